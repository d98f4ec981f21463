#include "flexfit/part_model.hpp"

#include "flexfit/surface_embedding.hpp"
#include "model/spring_blocks.hpp"

#include <cmath>

namespace flexfit {
namespace {

const std::string kSettingsSource = "part model settings";

bool positiveFinite(double x) { return std::isfinite(x) && x > 0.0; }
bool nonNegativeFinite(double x) { return std::isfinite(x) && x >= 0.0; }

void checkMaterial(const Material& m, const std::string& what) {
    if (!nonNegativeFinite(m.stiffness)) throw InputError(kSettingsSource, 0, what + " stiffness must be finite and >= 0");
    if (!nonNegativeFinite(m.damping)) throw InputError(kSettingsSource, 0, what + " damping must be finite and >= 0");
}

void checkSettings(const PartModelSettings& s, std::size_t vertices, std::size_t springs) {
    checkMaterial(s.material, "material");
    if (!positiveFinite(s.vertexMass)) throw InputError(kSettingsSource, 0, "vertex mass must be finite and > 0");
    if (!s.vertexMasses.empty() && s.vertexMasses.size() != vertices)
        throw InputError(kSettingsSource, 0, "per-vertex masses: " + std::to_string(s.vertexMasses.size()) +
                                                 " values for " + std::to_string(vertices) + " vertices");
    for (std::size_t v = 0; v < s.vertexMasses.size(); ++v)
        if (!positiveFinite(s.vertexMasses[v]))
            throw InputError(kSettingsSource, 0, "mass of vertex " + std::to_string(v) + " must be finite and > 0");
    if (!s.springMaterials.empty() && s.springMaterials.size() != springs)
        throw InputError(kSettingsSource, 0, "per-spring materials: " + std::to_string(s.springMaterials.size()) +
                                                 " values for " + std::to_string(springs) + " springs");
    for (std::size_t e = 0; e < s.springMaterials.size(); ++e) checkMaterial(s.springMaterials[e], "spring " + std::to_string(e));
}

}  // namespace

std::optional<Material> materialPreset(std::string_view name) {
    if (name == "rigid") return Material::rigid();
    if (name == "elastic") return Material::elastic();
    if (name == "superelastic") return Material::superelastic();
    return std::nullopt;
}

std::shared_ptr<const PartModel> buildPartModel(TriMesh mesh, const PartModelSettings& settings) {
    auto model = std::make_shared<PartModel>();
    model->topology = buildTopology(mesh.faces, mesh.vertices.size());
    const std::size_t vertices = mesh.vertices.size(), springs = model->topology.edgeCount();
    checkSettings(settings, vertices, springs);

    model->name = mesh.name;
    model->restPositions = mesh.vertices;
    model->mass = settings.vertexMasses.empty() ? std::vector<double>(vertices, settings.vertexMass) : settings.vertexMasses;
    model->inverseMass.resize(vertices);
    for (std::size_t v = 0; v < vertices; ++v) model->inverseMass[v] = 1.0 / model->mass[v];

    model->springA = model->topology.edgeA;
    model->springB = model->topology.edgeB;
    model->restLength.resize(springs);
    model->stiffness.resize(springs);
    model->damping.resize(springs);
    for (std::size_t e = 0; e < springs; ++e) {
        model->restLength[e] = (mesh.vertices[model->springA[e]] - mesh.vertices[model->springB[e]]).norm();
        const Material& m = settings.springMaterials.empty() ? settings.material : settings.springMaterials[e];
        model->stiffness[e] = m.stiffness;
        model->damping[e] = m.damping;
    }
    model->springAdr.assign(vertices + 1, 0);
    for (Index a : model->springA) ++model->springAdr[a + 1];
    for (std::size_t v = 0; v < vertices; ++v) model->springAdr[v + 1] += model->springAdr[v];
    model->springBlocks = std::make_shared<const SpringBlocks>(
        buildSpringBlocks(model->springA, model->springB, model->restLength, model->stiffness, model->damping));
    if (!settings.drawnMesh.faces.empty()) {
        validateMesh(settings.drawnMesh, kSettingsSource + ", drawn mesh");
        model->drawn = std::make_shared<const SurfaceEmbedding>(embedSurface(settings.drawnMesh, mesh, kSettingsSource));
    }
    model->mesh = std::move(mesh);
    return model;
}

bool PartModel::hasSpringBlocks() const { return springBlocks != nullptr && !springBlocks->empty(); }

const TriMesh& PartModel::drawnMesh() const { return drawn ? drawn->mesh : mesh; }

}  // namespace flexfit
