#include "flexfit/part_model.hpp"

#include "flexfit/bounding_volume.hpp"
#include "flexfit/surface_embedding.hpp"
#include "model/spring_blocks.hpp"
#include "model/vertex_order.hpp"

#include <algorithm>
#include <cmath>

namespace flexfit {
namespace {

const std::string kSettingsSource = "part model settings";

bool positiveFinite(double x) { return std::isfinite(x) && x > 0.0; }
bool nonNegativeFinite(double x) { return std::isfinite(x) && x >= 0.0; }
// A mass the step can divide by: positive, finite, with a finite inverse (not subnormal).
bool invertibleMass(double x) { return positiveFinite(x) && std::isfinite(1.0 / x); }

void checkMaterial(const Material& m, const std::string& what) {
    if (!nonNegativeFinite(m.stiffness)) throw InputError(kSettingsSource, 0, what + " stiffness must be finite and >= 0");
    if (!nonNegativeFinite(m.damping)) throw InputError(kSettingsSource, 0, what + " damping must be finite and >= 0");
}

void checkSettings(const PartModelSettings& s, std::size_t vertices, std::size_t springs) {
    checkMaterial(s.material, "material");
    if (!invertibleMass(s.vertexMass))
        throw InputError(kSettingsSource, 0, "vertex mass must be finite and > 0, with a finite inverse (not subnormal)");
    if (!s.vertexMasses.empty() && s.vertexMasses.size() != vertices)
        throw InputError(kSettingsSource, 0, "per-vertex masses: " + std::to_string(s.vertexMasses.size()) +
                                                 " values for " + std::to_string(vertices) + " vertices");
    for (std::size_t v = 0; v < s.vertexMasses.size(); ++v)
        if (!invertibleMass(s.vertexMasses[v]))
            throw InputError(kSettingsSource, 0, "mass of vertex " + std::to_string(v) + " must be finite and > 0, with a finite inverse (not subnormal)");
    if (!s.springMaterials.empty() && s.springMaterials.size() != springs)
        throw InputError(kSettingsSource, 0, "per-spring materials: " + std::to_string(s.springMaterials.size()) +
                                                 " values for " + std::to_string(springs) + " springs");
    for (std::size_t e = 0; e < s.springMaterials.size(); ++e) checkMaterial(s.springMaterials[e], "spring " + std::to_string(e));
}

void checkShell(const ShellMaterial& m, const PartModelSettings& s) {
    auto fail = [](const std::string& problem) { throw InputError(kSettingsSource, 0, "shell material: " + problem); };
    if (!positiveFinite(m.youngsModulus)) fail("Young's modulus must be finite and > 0");
    if (!(std::isfinite(m.poissonRatio) && m.poissonRatio >= 0.0 && m.poissonRatio < 0.5)) fail("Poisson's ratio must be in [0, 0.5)");
    if (!positiveFinite(m.thickness)) fail("thickness must be finite and > 0");
    if (!positiveFinite(m.density)) fail("density must be finite and > 0");
    if (!nonNegativeFinite(m.dampingRatio)) fail("damping ratio must be finite and >= 0");
    if (!s.vertexMasses.empty() || !s.springMaterials.empty())
        fail("gives the masses and the spring constants: per-vertex masses or per-spring materials cannot be set beside it");
}

// A spring's two ends and, for the shell's rules, the area of the faces it spans (its edge's
// faces, or the two faces a bending spring crosses) and the edge it crosses (bending only).
struct SpringSpec {
    Index a = 0, b = 0;
    double faceArea = 0.0;
    double crossedEdgeLength = 0.0;  // 0: an edge spring
    bool operator<(const SpringSpec& o) const { return a != o.a ? a < o.a : b < o.b; }
};

// One spec per unique edge (Topology order) and, with bending springs, one per interior edge
// joining its two opposite vertices (skipped where those are already joined by an edge or by
// another bending spring).
std::vector<SpringSpec> springSpecs(const TriMesh& mesh, const Topology& topo, bool bending) {
    struct HalfEdge {
        Index a, b, opposite;
        double area;
    };
    std::vector<HalfEdge> halves;
    halves.reserve(3 * mesh.faces.size());
    for (const Face& f : mesh.faces) {
        const double area = faceArea(mesh.vertices, f);
        for (int i = 0; i < 3; ++i) {
            const Index u = f[std::size_t(i)], w = f[std::size_t((i + 1) % 3)], o = f[std::size_t((i + 2) % 3)];
            halves.push_back({std::min(u, w), std::max(u, w), o, area});
        }
    }
    std::sort(halves.begin(), halves.end(), [](const HalfEdge& l, const HalfEdge& r) {
        return l.a != r.a ? l.a < r.a : l.b != r.b ? l.b < r.b : l.opposite < r.opposite;
    });
    std::vector<SpringSpec> specs;
    specs.reserve(topo.edgeCount());
    std::vector<SpringSpec> crossing;
    for (std::size_t i = 0; i < halves.size();) {  // the runs of halves follow Topology's edge order
        std::size_t j = i;
        double area = 0.0;
        for (; j < halves.size() && halves[j].a == halves[i].a && halves[j].b == halves[i].b; ++j) area += halves[j].area;
        specs.push_back({halves[i].a, halves[i].b, area, 0.0});
        if (bending && j - i == 2 && halves[i].opposite != halves[i + 1].opposite) {
            const Index c = halves[i].opposite, d = halves[i + 1].opposite;
            const double edge = (mesh.vertices[halves[i].a] - mesh.vertices[halves[i].b]).norm();
            crossing.push_back({std::min(c, d), std::max(c, d), area, edge});
        }
        i = j;
    }
    if (crossing.empty()) return specs;
    std::stable_sort(crossing.begin(), crossing.end());
    std::vector<SpringSpec> merged;
    merged.reserve(specs.size() + crossing.size());
    std::merge(specs.begin(), specs.end(), crossing.begin(), crossing.end(), std::back_inserter(merged));
    // An edge comes first among equal ends (merge keeps the first range's first): drop the rest.
    merged.erase(std::unique(merged.begin(), merged.end(), [](const SpringSpec& l, const SpringSpec& r) { return l.a == r.a && l.b == r.b; }),
                 merged.end());
    return merged;
}

std::vector<double> lumpedMasses(const TriMesh& mesh, const ShellMaterial& m) {
    std::vector<double> mass(mesh.vertices.size(), 0.0);
    for (const Face& f : mesh.faces) {
        const double share = m.density * m.thickness * faceArea(mesh.vertices, f) / 3.0;
        for (Index v : f) mass[v] += share;
    }
    for (std::size_t v = 0; v < mass.size(); ++v)
        if (!(mass[v] > 0.0))
            throw InputError(kSettingsSource, 0,
                             "shell material: vertex " + std::to_string(v) + " gets no mass (it is in no face of positive area)");
    return mass;
}

// van Gelder's membrane stiffness for an edge, the bending rule for a crossing spring
// (ShellMaterial's comment).
double shellStiffness(const ShellMaterial& m, const SpringSpec& s, double restLength) {
    if (s.crossedEdgeLength == 0.0) return m.youngsModulus * m.thickness * s.faceArea / (restLength * restLength);
    const double t = m.thickness, nu = m.poissonRatio;
    const double rigidity = m.youngsModulus * t * t * t / (12.0 * (1.0 - nu * nu));
    const double e = s.crossedEdgeLength;
    return 3.0 * rigidity * e * e / (s.faceArea * restLength * restLength);
}

void buildMassSprings(PartModel& model) {
    const std::size_t vertices = model.massCount();
    model.massSpringAdr.assign(vertices + 1, 0);
    for (std::size_t e = 0; e < model.springCount(); ++e) {
        ++model.massSpringAdr[model.springA[e] + 1];
        ++model.massSpringAdr[model.springB[e] + 1];
    }
    for (std::size_t v = 0; v < vertices; ++v) model.massSpringAdr[v + 1] += model.massSpringAdr[v];
    model.massSprings.resize(2 * model.springCount());
    std::vector<Index> next(model.massSpringAdr.begin(), model.massSpringAdr.end() - 1);
    for (std::size_t e = 0; e < model.springCount(); ++e) {  // ascending spring order per mass
        model.massSprings[next[model.springA[e]]++] = Index(e);
        model.massSprings[next[model.springB[e]]++] = Index(e);
    }
}

}  // namespace

std::optional<Material> materialPreset(std::string_view name) {
    if (name == "rigid") return Material::rigid();
    if (name == "elastic") return Material::elastic();
    if (name == "superelastic") return Material::superelastic();
    return std::nullopt;
}

namespace {

// The model with mass i = vertex i, without its drawn mesh.
std::shared_ptr<PartModel> buildInGivenOrder(TriMesh mesh, const PartModelSettings& settings) {
    auto model = std::make_shared<PartModel>();
    model->topology = buildTopology(mesh.faces, mesh.vertices.size());
    const std::size_t vertices = mesh.vertices.size();
    checkSettings(settings, vertices, model->topology.edgeCount());
    const ShellMaterial* shell = settings.shell ? &*settings.shell : nullptr;
    if (shell) checkShell(*shell, settings);

    model->name = mesh.name;
    model->restPositions.assign(mesh.vertices.begin(), mesh.vertices.end());
    if (shell) {
        const std::vector<double> lumped = lumpedMasses(mesh, *shell);
        model->mass.assign(lumped.begin(), lumped.end());
    } else if (settings.vertexMasses.empty()) {
        model->mass.assign(vertices, settings.vertexMass);
    } else {
        model->mass.assign(settings.vertexMasses.begin(), settings.vertexMasses.end());
    }
    model->inverseMass.resize(vertices);
    for (std::size_t v = 0; v < vertices; ++v) model->inverseMass[v] = 1.0 / model->mass[v];

    const std::vector<SpringSpec> specs = springSpecs(mesh, model->topology, shell && shell->bendingSprings);
    const std::size_t springs = specs.size();
    model->bendingSpringCount = springs - model->topology.edgeCount();
    model->springA.resize(springs);
    model->springB.resize(springs);
    model->restLength.resize(springs);
    model->stiffness.resize(springs);
    model->damping.resize(springs);
    for (std::size_t e = 0; e < springs; ++e) {
        const Index a = specs[e].a, b = specs[e].b;
        model->springA[e] = a;
        model->springB[e] = b;
        model->restLength[e] = (mesh.vertices[a] - mesh.vertices[b]).norm();
        if (shell) {
            const double k = shellStiffness(*shell, specs[e], model->restLength[e]);
            const double reducedMass = model->mass[a] * model->mass[b] / (model->mass[a] + model->mass[b]);
            model->stiffness[e] = k;
            model->damping[e] = 2.0 * shell->dampingRatio * std::sqrt(k * reducedMass);
            continue;
        }
        const Material& m = settings.springMaterials.empty() ? settings.material : settings.springMaterials[e];
        model->stiffness[e] = m.stiffness;
        model->damping[e] = m.damping;
    }
    for (std::size_t e = 0; e < springs; ++e)
        if (!std::isfinite(model->stiffness[e]))
            throw InputError(kSettingsSource, 0, "shell material: spring " + std::to_string(e) + " gets no finite stiffness (a zero-length edge)");
    buildMassSprings(*model);
    model->springAdr.assign(vertices + 1, 0);
    for (Index a : model->springA) ++model->springAdr[a + 1];
    for (std::size_t v = 0; v < vertices; ++v) model->springAdr[v + 1] += model->springAdr[v];
    model->springBlocks = std::make_shared<const SpringBlocks>(
        buildSpringBlocks(model->springA, model->springB, model->restLength, model->stiffness, model->damping, vertices));
    model->mesh = std::move(mesh);
    return model;
}

// Topology edge e of the given order is edge edgeOf[e] of the renumbered one.
std::vector<Index> renumberedEdges(const Topology& given, const Topology& renumbered, std::span<const Index> newIndex) {
    std::vector<Index> edgeOf(given.edgeCount());
    for (std::size_t e = 0; e < edgeOf.size(); ++e) {
        const Index a = std::min(newIndex[given.edgeA[e]], newIndex[given.edgeB[e]]);
        const Index b = std::max(newIndex[given.edgeA[e]], newIndex[given.edgeB[e]]);
        const auto neighbours = renumbered.neighborsOf(a);
        const auto at = std::lower_bound(neighbours.begin(), neighbours.end(), b) - neighbours.begin();
        edgeOf[e] = renumbered.edgesOf(a)[std::size_t(at)];
    }
    return edgeOf;
}

// The given model's mesh renumbered for locality, when that puts more springs in blocks; null
// otherwise. Settings were checked by the given order's build (their errors name the user's
// vertices and springs).
std::shared_ptr<PartModel> renumberedForLocality(const PartModel& given, const PartModelSettings& settings) {
    const std::vector<Index> newIndex = detail::localityOrder(given.topology, given.mesh.faces);
    PartModelSettings renumbered = settings;
    for (std::size_t v = 0; v < settings.vertexMasses.size(); ++v) renumbered.vertexMasses[newIndex[v]] = settings.vertexMasses[v];
    auto model = buildInGivenOrder(detail::renumberVertices(given.mesh, newIndex), [&] {
        PartModelSettings s = renumbered;
        s.springMaterials.clear();  // per-spring constants go in below, by edge
        return s;
    }());
    if (model->springBlocks->blockedSprings() <= given.springBlocks->blockedSprings()) return nullptr;
    if (!settings.springMaterials.empty()) {
        const std::vector<Index> edgeOf = renumberedEdges(given.topology, model->topology, newIndex);
        for (std::size_t e = 0; e < edgeOf.size(); ++e) renumbered.springMaterials[edgeOf[e]] = settings.springMaterials[e];
        model = buildInGivenOrder(std::move(model->mesh), renumbered);
    }
    model->massOfVertex = newIndex;
    model->vertexOfMass.resize(newIndex.size());
    for (std::size_t v = 0; v < newIndex.size(); ++v) model->vertexOfMass[newIndex[v]] = Index(v);
    return model;
}

// The file numbering of a model whose given mesh is `given`, checked: every file vertex goes to
// a vertex of the mesh or is removed, and every mesh vertex comes from one.
std::shared_ptr<const FileNumbering> fileNumbering(const FileVertices& file, const TriMesh& given) {
    const auto fail = [](const std::string& problem) { throw InputError(kSettingsSource, 0, "file vertices: " + problem); };
    try {
        checkFileVertices(file, given.vertices.size());
    } catch (const InputError& e) {
        fail(e.problem());
    }
    auto numbering = std::make_shared<FileNumbering>();
    numbering->vertices = file;
    numbering->firstOf = firstFileVertices(file, given.vertices.size());
    for (std::size_t v = 0; v < given.vertices.size(); ++v)
        if (numbering->firstOf[v] == kNoVertex) fail("no file vertex goes to mesh vertex " + std::to_string(v));
    numbering->mesh = inFileOrder(given, file);
    return numbering;
}

// PartModel::positionBound: 1e6 times the rest shape's diagonal (infinite for a shape of no extent).
double divergenceBound(std::span<const Vec3> rest) {
    const double extent = rest.empty() ? 0.0 : Aabb::around(rest).size();
    const double bound = 1e6 * extent;
    return extent > 0.0 && std::isfinite(bound) ? bound : std::numeric_limits<double>::infinity();
}

}  // namespace

std::shared_ptr<const PartModel> buildPartModel(TriMesh mesh, const PartModelSettings& settings) {
    validateMesh(mesh, mesh.name.empty() ? std::string("part model mesh") : mesh.name);
    std::shared_ptr<PartModel> model = buildInGivenOrder(std::move(mesh), settings);
    if (settings.vertexOrder == VertexOrder::Locality)
        if (auto renumbered = renumberedForLocality(*model, settings)) {
            renumbered->givenMesh = std::make_shared<const TriMesh>(std::move(model->mesh));
            model = std::move(renumbered);
        }
    if (!settings.drawnMesh.faces.empty()) {
        validateMesh(settings.drawnMesh, kSettingsSource + ", drawn mesh");
        model->drawn = std::make_shared<const SurfaceEmbedding>(embedSurface(settings.drawnMesh, model->mesh, kSettingsSource));
    }
    if (!settings.fileVertices.empty()) model->file = fileNumbering(settings.fileVertices, model->userMesh());
    model->positionBound = divergenceBound(model->restPositions);
    return model;
}

Index PartModel::massOf(Index vertex) const {
    if (!file) return vertex < massCount() ? massOfGivenVertex(vertex) : vertex;
    if (vertex >= file->vertices.count())  // the step's own check would give the mass count as the bound
        throw InputError("part '" + name + "'", 0,
                         "vertex " + std::to_string(vertex) + " does not exist (its file has " + std::to_string(file->vertices.count()) +
                             " vertices)");
    const Index given = file->vertices.meshVertex[vertex];
    if (given == kNoVertex)
        throw InputError("part '" + name + "'", 0,
                         "vertex " + std::to_string(vertex) + " of its file was removed by the repair (no face uses it): it has no mass");
    return massOfGivenVertex(given);
}

Index PartModel::vertexOf(Index m) const {
    const Index given = renumbered() ? vertexOfMass[m] : m;
    return file ? file->firstOf[given] : given;
}

bool PartModel::hasSpringBlocks() const { return springBlocks != nullptr && !springBlocks->empty(); }

const TriMesh& PartModel::drawnMesh() const { return drawn ? drawn->mesh : userMesh(); }

}  // namespace flexfit
