// TOML scene parsing (scene_file.hpp). Every table is read through a Table that remembers
// which keys were used, so unknown keys (typos) are reported instead of silently ignored.
#include "flexfit/scene_file.hpp"
#include "flexfit/remesh.hpp"
#include "flexfit/remesh_cache.hpp"

#include "flexfit/generators.hpp"
#include "flexfit/mesh_io.hpp"

#include "io/scene_document.hpp"
#include "io/text_lines.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <optional>
#include <cmath>
#include <set>
#include <unordered_map>

namespace flexfit {
namespace {

using detail::lineOf;

// One TOML table with its name for messages ("part 'ball'") and the keys read from it.
class Table {
public:
    Table(const toml::table& table, std::string what, const std::string& file, std::vector<SceneWarning>& warnings)
        : table_(table), what_(std::move(what)), file_(file), warnings_(warnings) {}

    [[noreturn]] void fail(const toml::node& at, const std::string& key, const std::string& problem) const {
        throw InputError(file_, lineOf(at), what_ + ", key '" + shown(key) + "': " + problem);
    }
    // A key as an error names it: at most 80 characters (an unknown key of 5 MB was echoed whole).
    static std::string shown(const std::string& key) { return key.size() <= 80 ? key : key.substr(0, 77) + "..."; }
    [[noreturn]] void fail(const std::string& problem) const { throw InputError(file_, lineOf(table_), what_ + ": " + problem); }

    bool has(const std::string& key) const { return table_.contains(key); }
    const toml::node* node(const std::string& key) {
        used_.insert(key);
        return table_.get(key);
    }
    std::size_t line(const std::string& key) const {
        const toml::node* n = table_.get(key);
        return n ? lineOf(*n) : lineOf(table_);
    }
    std::size_t line() const { return lineOf(table_); }

    double number(const std::string& key, double fallback) {
        const toml::node* n = node(key);
        if (!n) return fallback;
        if (!n->is_number()) fail(*n, key, "expected a number");
        const double v = n->value<double>().value();
        if (!std::isfinite(v)) fail(*n, key, "must be finite");
        return v;
    }
    double positive(const std::string& key, double fallback) {
        const double v = number(key, fallback);
        if (!(v > 0.0)) fail(*table_.get(key), key, "must be > 0");
        return v;
    }
    double nonNegative(const std::string& key, double fallback) {
        const double v = number(key, fallback);
        if (!(v >= 0.0)) fail(*table_.get(key), key, "must be >= 0");
        return v;
    }
    bool flag(const std::string& key, bool fallback) {
        const toml::node* n = node(key);
        if (!n) return fallback;
        if (!n->is_boolean()) fail(*n, key, "expected true or false");
        return n->value<bool>().value();
    }
    int integer(const std::string& key, int fallback, int lo, int hi) {
        const toml::node* n = node(key);
        if (!n) return fallback;
        if (!n->is_integer()) fail(*n, key, "expected an integer");
        const std::int64_t v = n->value<std::int64_t>().value();
        if (v < lo || v > hi) fail(*n, key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
        return int(v);
    }
    std::string text(const std::string& key, const std::string& fallback) {
        const toml::node* n = node(key);
        if (!n) return fallback;
        if (!n->is_string()) fail(*n, key, "expected a string");
        return std::string(n->value<std::string>().value());
    }
    std::string requiredText(const std::string& key) {
        if (!has(key)) fail("missing key '" + key + "'");
        return text(key, "");
    }
    // A name that heads columns of metrics.csv and labels frames: non-empty, on one line, with
    // no comma or double quote (which would split or break a CSV header).
    std::string name(const std::string& key, const std::optional<std::string>& fallback = std::nullopt) {
        if (!fallback && !has(key)) fail("missing key '" + key + "'");
        const std::string value = text(key, fallback.value_or(""));
        const bool plain = !value.empty() && std::none_of(value.begin(), value.end(), [](char c) {
            return c == ',' || c == '"' || static_cast<unsigned char>(c) < 0x20 || c == 0x7f;
        });
        if (!plain && has(key)) fail(*node(key), key, "a name must be non-empty, on one line, with no comma or double quote (names head the columns of metrics.csv)");
        return value;
    }
    Vec3 vec3(const std::string& key, const Vec3& fallback) {
        const toml::node* n = node(key);
        if (!n) return fallback;
        const toml::array* a = n->as_array();
        if (!a || a->size() != 3) fail(*n, key, "expected an array of 3 numbers");
        Vec3 v;
        for (int i = 0; i < 3; ++i) {
            const toml::node& e = *a->get(std::size_t(i));
            if (!e.is_number()) fail(e, key, "expected an array of 3 numbers");
            v[i] = e.value<double>().value();
        }
        if (!v.allFinite()) fail(*n, key, "must be finite");
        return v;
    }
    // Rotation as degrees about x, then y, then z (world axes).
    Eigen::Quaterniond rotation(const std::string& key) {
        const Vec3 deg = vec3(key, Vec3::Zero()) * (M_PI / 180.0);
        return Eigen::Quaterniond(Eigen::AngleAxisd(deg.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(deg.y(), Vec3::UnitY()) *
                                  Eigen::AngleAxisd(deg.x(), Vec3::UnitX()));
    }
    Pose pose(const std::string& positionKey, const std::string& rotationKey) {
        Pose p;
        p.translation = vec3(positionKey, Vec3::Zero());
        // As far as a mesh's coordinates may go (mesh.hpp): a ball placed at y = 1e300 stayed there,
        // every step's fall lost to rounding, and collision's products would overflow.
        if (!(p.translation.cwiseAbs().maxCoeff() <= kMaxMeshCoordinate))
            fail(*node(positionKey), positionKey, "a coordinate beyond 1e+20 units, farther than a mesh's may go (mesh.hpp)");
        p.rotation = rotation(rotationKey);
        return p;
    }
    std::vector<Index> indices(const std::string& key) {
        const toml::node* n = node(key);
        std::vector<Index> out;
        if (!n) return out;
        const toml::array* a = n->as_array();
        if (!a) fail(*n, key, "expected an array of indices");
        for (const toml::node& e : *a) {
            if (!e.is_integer() || e.value<std::int64_t>().value() < 0 || e.value<std::int64_t>().value() > 0x7fffffff)
                fail(e, key, "expected non-negative integer indices");
            out.push_back(Index(e.value<std::int64_t>().value()));
        }
        return out;
    }
    Table sub(const std::string& key) {
        const toml::node* n = node(key);
        if (!n || !n->is_table()) fail(n ? *n : static_cast<const toml::node&>(table_), key, "expected a table");
        return Table(*n->as_table(), what_ + "." + key, file_, warnings_);
    }
    // One of the enum's names (names.hpp); an old spelling is read with a warning.
    template <class Enum>
    Enum choice(const std::string& key, Enum fallback) {
        if (!has(key)) {
            used_.insert(key);
            return fallback;
        }
        const std::string value = text(key, "");
        std::string replacement;
        const std::optional<Enum> e = parseName<Enum>(value, &replacement);
        if (!e) fail(*table_.get(key), key, "unknown value '" + value + "' (expected one of " + nameList<Enum>() + ")");
        if (!replacement.empty()) warnings_.push_back({line(key), what_ + ", key '" + key + "': " + deprecationWarning(value, replacement)});
        return *e;
    }
    // Every key must have been read.
    void finish() const {
        for (const auto& [key, value] : table_)
            if (!used_.count(std::string(key.str()))) fail(value, std::string(key.str()), "unknown key");
    }
    const std::string& what() const { return what_; }
    const std::string& file() const { return file_; }

private:
    const toml::table& table_;
    std::string what_;
    const std::string& file_;
    std::vector<SceneWarning>& warnings_;
    std::set<std::string> used_;
};

// The array of tables under `key` ([[part]] etc.); empty when absent.
std::vector<const toml::table*> tables(Table& root, const std::string& key) {
    std::vector<const toml::table*> out;
    const toml::node* n = root.node(key);
    if (!n) return out;
    const toml::array* a = n->as_array();
    if (!a) root.fail(*n, key, "expected [[" + key + "]] tables");
    for (const toml::node& e : *a) {
        if (!e.is_table()) root.fail(e, key, "expected [[" + key + "]] tables");
        out.push_back(e.as_table());
    }
    return out;
}

struct PartRemesh {
    RemeshOptions options;
    bool cache = true;  // through SceneReadOptions::remeshCache
};

// `remesh = L` (the target edge) or `remesh = { edge = L, iterations = N, feature_angle = DEG,
// thin_features = "auto" | "keep" | "round", cache = true | false }`.
std::optional<PartRemesh> readRemesh(Table& t) {
    if (!t.has("remesh")) return std::nullopt;
    const toml::node* n = t.node("remesh");
    PartRemesh part;
    RemeshOptions& r = part.options;
    if (n->is_number()) {
        r.targetEdge = t.positive("remesh", 1.0);
        return part;
    }
    if (!n->is_table())
        t.fail(*n, "remesh", "expected a target edge length or {edge, iterations, feature_angle, thin_features, cache}");
    Table options = t.sub("remesh");
    if (!options.has("edge")) options.fail("needs 'edge' (the target edge length)");
    r.targetEdge = options.positive("edge", 0.0);
    part.cache = options.flag("cache", true);
    r.iterations = options.integer("iterations", r.iterations, 1, 100);
    r.featureAngle = options.positive("feature_angle", r.featureAngle);
    if (!(r.featureAngle < 180.0)) options.fail(*options.node("feature_angle"), "feature_angle", "must be below 180 degrees");
    const std::string thin = options.text("thin_features", nameOf(ThinFeatures::Auto));
    const std::optional<ThinFeatures> chosen = parseName<ThinFeatures>(thin);
    if (!chosen) options.fail(*options.node("thin_features"), "thin_features", "unknown value '" + thin + "' (expected 'auto', 'keep' or 'round')");
    r.thinFeatures = *chosen;
    options.finish();
    return part;
}

// The part's simulation surface, through the remesh cache unless the scene or the part turns
// it off; a cache that cannot be written becomes a warning at the remesh key's line.
TriMesh remeshPart(Table& t, const TriMesh& mesh, const PartRemesh& remesh, const std::string& source,
                   const SceneReadOptions& options, std::vector<SceneWarning>& warnings) {
    const std::filesystem::path directory =
        remesh.cache ? options.remeshCache.value_or(defaultRemeshCacheDirectory()) : std::filesystem::path();
    CachedRemesh cached = remeshCached(mesh, remesh.options, source, directory);
    if (!cached.problem.empty())
        warnings.push_back({t.line("remesh"), t.what() + ", key 'remesh': " + cached.problem +
                                                  (cached.hit || cached.stored ? "" : "; the part is remeshed at every load")});
    return std::move(cached.result.mesh);
}

// Mesh input errors stay as they are (they name the mesh file and its line); the scene's
// line is added so the user knows which part asked for the file. What the repair changed
// becomes the scene's warnings, at the mesh key's line: nothing is changed silently.
// A remeshed part simulates on the new surface; the file's mesh (repaired) is what it draws
// (`draw = "original"`, the default) unless `draw = "simulation"`.
struct PartMeshes {
    TriMesh simulated;
    TriMesh drawn;      // empty: the simulated mesh is drawn
    FileVertices file;  // the file's vertices when the read welded or removed some (not remeshed)
};

PartMeshes readPartMesh(Table& t, const std::filesystem::path& base, const SceneReadOptions& options, std::vector<SceneWarning>& warnings) {
    const std::string file = t.text("mesh", "");
    if (file.empty()) t.fail(*t.node("mesh"), "mesh", "an empty path: name the part's mesh file");
    const std::filesystem::path path = std::filesystem::path(file).is_absolute() ? std::filesystem::path(file) : base / file;
    const std::size_t line = t.line("mesh");
    MeshReadOptions read;
    read.repair = t.flag("repair", true) && !options.strictMeshes;
    const std::optional<PartRemesh> remesh = readRemesh(t);
    MeshReadResult result;
    try {
        result = readMesh(path, read);
    } catch (const InputError& e) {
        throw InputError(t.file(), line, t.what() + ", key 'mesh': " + e.what());
    }
    for (const std::string& repair : result.repairs.warnings())
        warnings.push_back({line, t.what() + ", key 'mesh': " + path.string() + ": " + repair});
    const std::string draw = t.text("draw", "original");
    if (draw != "original" && draw != "simulation")
        t.fail(*t.node("draw"), "draw", "unknown value '" + draw + "' (expected 'original' or 'simulation')");
    const bool drawOriginal = draw == "original";
    if (!remesh && t.has("draw"))
        warnings.push_back({t.line("draw"), t.what() + ", key 'draw': has no effect without 'remesh' (the file's mesh is simulated and drawn)"});
    if (!remesh) return {std::move(result.mesh), {}, std::move(result.fileVertices)};
    try {
        TriMesh simulated = remeshPart(t, result.mesh, *remesh, path.string(), options, warnings);
        // Drawn: the file's own vertices, in its order, over the repaired faces.
        return {std::move(simulated), drawOriginal ? inFileOrder(result.mesh, result.fileVertices) : TriMesh{}, {}};
    } catch (const InputError& e) {
        throw InputError(t.file(), t.line("remesh"), t.what() + ", key 'remesh': " + e.problem());
    }
}

// A box's divisions: one number for every axis, or [x, y, z] (e.g. a strip of near-square cells).
std::array<int, 3> boxDivisions(Table& g) {
    const toml::node* n = g.node("divisions");
    if (n == nullptr || !n->is_array()) {
        const int d = g.integer("divisions", 1, 1, 256);
        return {d, d, d};
    }
    const std::vector<Index> d = g.indices("divisions");
    if (d.size() != 3) g.fail(*n, "divisions", "expected one integer or three [x, y, z]");
    for (Index v : d)
        if (v < 1 || v > 256) g.fail(*n, "divisions", "each must be in [1, 256]");
    return {int(d[0]), int(d[1]), int(d[2])};
}

TriMesh generatePartMesh(Table& t) {
    const toml::node* n = t.node("generator");
    if (n->is_string()) {
        const std::string name(n->value<std::string>().value());
        if (name == "torus1") return makeTorus1();
        if (name == "torus2") return makeTorus2();
        if (name == "heart") return makeHeart();
        if (name == "container-mouth") return makeContainerMouth();
        t.fail(*n, "generator", "unknown generator '" + name + "' (expected 'torus1', 'torus2', 'heart', 'container-mouth' or a table)");
    }
    if (!n->is_table()) t.fail(*n, "generator", "expected a name or a table");
    Table g = t.sub("generator");
    const std::string type = g.text("type", "torus");
    if (type != "torus" && type != "sphere" && type != "box" && type != "plate")
        g.fail(*g.node("type"), "type", "unknown value '" + type + "' (expected one of 'torus', 'sphere', 'box', 'plate')");
    TriMesh mesh;
    if (type == "torus") {
        const double major = g.positive("major", 10.0), minor = g.positive("minor", 2.5);
        if (!(minor < major)) g.fail("minor radius must be smaller than the major radius");
        const int u = g.integer("u", 24, 3, 4096), v = g.integer("v", 24, 3, 4096);
        if (const std::optional<std::string> problem = generatedVertexCountProblem(static_cast<long long>(u) * v))
            g.fail(*g.node("u"), "u", "u x v = " + *problem);
        mesh = makeTorus(major, minor, u, v);
    } else if (type == "sphere") {
        mesh = makeIcoSphere(g.positive("radius", 1.0), g.integer("level", 3, 0, 7));
    } else if (type == "box") {
        const Vec3 half = g.vec3("half_extents", Vec3::Ones());
        if (!(half.minCoeff() > 0.0)) g.fail(*g.node("half_extents"), "half_extents", "must be > 0");
        mesh = makeBox(half, boxDivisions(g));
    } else {
        const Vec3 half = g.vec3("half_extents", Vec3(2.0, 0.5, 2.0));
        if (!(half.minCoeff() > 0.0)) g.fail(*g.node("half_extents"), "half_extents", "must be > 0");
        // A hole key left out is half the plate's, so only a given one can be too wide.
        const double hx = g.positive("hole_x", 0.5 * half.x()), hz = g.positive("hole_z", 0.5 * half.z());
        if (!(hx < half.x())) g.fail(*g.node("hole_x"), "hole_x", "must be smaller than the plate's half extent along x (half_extents[0])");
        if (!(hz < half.z())) g.fail(*g.node("hole_z"), "hole_z", "must be smaller than the plate's half extent along z (half_extents[2])");
        mesh = makePlateWithHole(half, hx, hz);
    }
    g.finish();
    // What the generators take but Flexfit cannot compute with (a radius of 1e30: validateMesh's
    // scale bounds) is refused here, at the generator's line, as a file's mesh would be.
    try {
        validateMesh(mesh, "generator");
    } catch (const InputError& e) {
        g.fail(e.problem());
    }
    return mesh;
}

// A physical material: {youngs_modulus, thickness, density, poisson_ratio, damping_ratio,
// bending_springs} (part_model.hpp's ShellMaterial).
ShellMaterial readShellMaterial(Table& m) {
    for (const char* key : {"thickness", "density"})
        if (!m.has(key)) m.fail(std::string("needs '") + key + "' beside 'youngs_modulus' (a physical material)");
    if (m.has("stiffness") || m.has("damping"))
        m.fail(*m.node(m.has("stiffness") ? "stiffness" : "damping"), m.has("stiffness") ? "stiffness" : "damping",
               "give either spring constants {stiffness, damping} or a physical material {youngs_modulus, ...}, not both");
    ShellMaterial shell;
    shell.youngsModulus = m.positive("youngs_modulus", 0.0);
    shell.thickness = m.positive("thickness", 0.0);
    shell.density = m.positive("density", 0.0);
    shell.poissonRatio = m.nonNegative("poisson_ratio", shell.poissonRatio);
    if (!(shell.poissonRatio < 0.5)) m.fail(*m.node("poisson_ratio"), "poisson_ratio", "must be in [0, 0.5)");
    shell.dampingRatio = m.nonNegative("damping_ratio", shell.dampingRatio);
    shell.bendingSprings = m.flag("bending_springs", false);
    return shell;
}

// `material`: a preset name, spring constants {stiffness, damping}, or a physical material.
void readMaterial(Table& t, PartModelSettings& model) {
    const toml::node* n = t.node("material");
    if (!n) return;
    if (n->is_string()) {
        const std::string name(n->value<std::string>().value());
        if (auto preset = materialPreset(name)) {
            model.material = *preset;
            return;
        }
        t.fail(*n, "material", "unknown preset '" + name + "' (expected 'rigid', 'elastic', 'superelastic', {stiffness, damping} or {youngs_modulus, thickness, density, ...})");
    }
    if (!n->is_table()) t.fail(*n, "material", "expected a preset name, {stiffness, damping} or {youngs_modulus, thickness, density, ...}");
    Table m = t.sub("material");
    if (m.has("youngs_modulus")) {
        model.shell = readShellMaterial(m);
        if (t.has("vertex_mass"))
            t.fail(*t.node("vertex_mass"), "vertex_mass", "a physical material gives the masses (density x thickness x area): leave vertex_mass out");
    } else {
        for (const char* key : {"thickness", "density", "poisson_ratio", "damping_ratio", "bending_springs"})
            if (m.has(key)) m.fail(*m.node(key), key, "belongs to a physical material: needs 'youngs_modulus'");
        model.material = Material{m.positive("stiffness", 0.1), m.nonNegative("damping", 0.01)};
    }
    m.finish();
}

ScenePart readPart(Table& t, const std::filesystem::path& base, const SceneReadOptions& options, std::vector<SceneWarning>& warnings) {
    ScenePart p;
    p.name = t.name("name");
    p.line = t.line();
    if (t.has("mesh") == t.has("generator")) t.fail("needs exactly one of 'mesh' and 'generator'");
    for (const char* key : {"repair", "remesh", "draw", "vertex_order"})
        if (t.has(key) && !t.has("mesh")) t.fail(*t.node(key), key, "applies only to a part read from a 'mesh' file");
    PartMeshes meshes = t.has("mesh") ? readPartMesh(t, base, options, warnings) : PartMeshes{generatePartMesh(t), {}, {}};
    TriMesh mesh = std::move(meshes.simulated);
    mesh.name = p.name;
    PartModelSettings model;
    model.drawnMesh = std::move(meshes.drawn);
    model.fileVertices = std::move(meshes.file);
    // A file's vertices come in its exporter's order: renumbered for locality unless asked not
    // to (the scene's mass indices, frames and outputs stay in the file's order either way).
    if (t.has("mesh")) {
        const std::string order = t.text("vertex_order", "locality");
        if (order != "locality" && order != "as_given")
            t.fail(*t.node("vertex_order"), "vertex_order", "unknown value '" + order + "' (expected 'locality' or 'as_given')");
        model.vertexOrder = order == "locality" ? VertexOrder::Locality : VertexOrder::AsGiven;
    }
    readMaterial(t, model);
    model.vertexMass = t.positive("vertex_mass", 1.0);

    p.part.mode = t.choice("mode", PartMode::RigidDeformable);
    SimulationSettings& sim = p.part.simulation;
    sim.integrator = t.choice("integrator", Integrator::SemiImplicitEuler);
    sim.implicit.maxIterations = t.integer("implicit_iterations", sim.implicit.maxIterations, 1, 100000);
    sim.implicit.tolerance = t.nonNegative("implicit_tolerance", sim.implicit.tolerance);
    if (sim.implicit.tolerance >= 1.0) t.fail(*t.node("implicit_tolerance"), "implicit_tolerance", "must be in [0, 1)");
    sim.globalDamping = t.nonNegative("global_damping", 0.0);
    sim.restoration.method = t.choice("restoration", RestorationMethod::Constraint);
    sim.restoration.constraintFraction = t.positive("constraint_fraction", sim.restoration.constraintFraction);
    if (sim.restoration.constraintFraction > 1.0) t.fail(*t.node("constraint_fraction"), "constraint_fraction", "must be in (0, 1]");
    if (t.has("constraint_rate") && t.has("constraint_fraction"))
        t.fail(*t.node("constraint_rate"), "constraint_rate", "give either constraint_rate or constraint_fraction, not both");
    if (t.has("constraint_rate")) sim.restoration.constraintRate = t.positive("constraint_rate", 1.0);
    sim.restoration.anchorStiffness = t.nonNegative("anchor_stiffness", sim.restoration.anchorStiffness);
    sim.restoration.anchorDamping = t.nonNegative("anchor_damping", sim.restoration.anchorDamping);
    ZoneSettings& z = p.part.zones;
    z.defaultLevel = t.integer("default_level", z.defaultLevel, 0, 255);
    z.contactLevel = t.integer("contact_level", z.contactLevel, 0, 255);
    z.activityThreshold = t.positive("activity_threshold", z.activityThreshold);
    z.restSpeed = t.positive("rest_speed", z.restSpeed);
    z.reservedZones = t.integer("reserved_zones", z.reservedZones, 0, 65535);

    p.body.motion = t.choice("motion", MotionType::Static);
    p.body.density = t.positive("density", 1.0);
    p.body.linearVelocity = t.vec3("velocity", Vec3::Zero());
    p.body.angularVelocity = t.vec3("angular_velocity", Vec3::Zero());
    p.body.thickness = t.nonNegative("thickness", 0.0);
    p.body.boundingVolume = t.choice("bounding_volume", BoundingVolumeKind::Aabb);
    p.body.staticFriction = t.nonNegative("static_friction", 0.0);
    // Kinetic friction defaults to the static one (a single coefficient, as most users give).
    p.body.kineticFriction = t.nonNegative("kinetic_friction", p.body.staticFriction);
    if (p.body.kineticFriction > p.body.staticFriction)
        t.fail(*t.node("kinetic_friction"), "kinetic_friction", "must not exceed static_friction");
    p.body.restitution = t.nonNegative("restitution", 0.0);
    if (p.body.restitution > 1.0) t.fail(*t.node("restitution"), "restitution", "must be in [0, 1]");
    p.pose = t.pose("position", "rotation");
    t.finish();
    try {
        p.model = buildPartModel(std::move(mesh), model);
    } catch (const InputError& e) {
        t.fail("invalid part: " + std::string(e.what()));
    }
    if (p.body.motion == MotionType::Dynamic && t.has("density")) {  // the body the world will make of it
        try {
            makeRigidBody(*p.model, p.body);
        } catch (const InputError& e) {
            t.fail(*t.node("density"), "density", e.problem());
        }
    }
    return p;
}

// The scene's parts by name, as read so far (Scene::find scans: a scene of n parts read in O(n)).
using PartIds = std::unordered_map<std::string, BodyId>;

BodyId partId(Table& t, const std::string& key, const PartIds& parts) {
    const std::string name = t.requiredText(key);
    if (const auto found = parts.find(name); found != parts.end()) return found->second;
    t.fail(*t.node(key), key, "no part named '" + name + "'");
}

AssemblyVector readVector(Table& t, const std::string& key) {
    AssemblyVector v;
    if (!t.has(key)) return v;
    Table s = t.sub(key);
    v.origin = s.vec3("origin", v.origin);
    v.end = s.vec3("end", v.end);
    if (v.origin == v.end) s.fail(*s.node(s.has("end") ? "end" : "origin"), s.has("end") ? "end" : "origin", "the vector's origin and end coincide: a vector of zero length has no direction");
    s.finish();
    return v;
}

AssemblyArea readArea(Table& t) {
    AssemblyArea a;
    if (!t.has("area")) return a;
    Table s = t.sub("area");
    a.shape = s.choice("shape", AssemblyArea::Shape::Box);
    a.frame = s.pose("position", "rotation");
    a.halfExtents = s.vec3("half_extents", a.halfExtents);
    if (!(a.halfExtents.minCoeff() > 0.0)) s.fail(*s.node("half_extents"), "half_extents", "must be > 0");
    a.radius = s.positive("radius", a.radius);
    a.halfHeight = s.positive("half_height", a.halfHeight);
    s.finish();
    return a;
}

AssemblyRule readAssembly(Table& t, const Scene& scene, const PartIds& parts) {
    AssemblyRule r;
    r.name = t.name("name", "assembly " + std::to_string(scene.assemblies.size()));
    for (const AssemblyRule& other : scene.assemblies)
        if (other.name == r.name) {
            const std::string problem = "duplicate assembly name '" + r.name + "'";
            if (t.has("name")) t.fail(*t.node("name"), "name", problem);
            t.fail(problem + " (the default name of the assembly at this place)");
        }
    r.primary = partId(t, "primary", parts);
    r.secondary = partId(t, "secondary", parts);
    if (r.primary == r.secondary) t.fail(*t.node("secondary"), "secondary", "must differ from the primary");
    r.technique = t.choice("technique", SnapTechnique::ZoneSnap);
    r.finalRelativePose = t.pose("final_position", "final_rotation");
    r.snapDuration = t.nonNegative("snap_duration", r.snapDuration);
    r.distanceTolerance = t.positive("distance_tolerance", r.distanceTolerance);
    r.angleTolerance = t.positive("angle_tolerance", r.angleTolerance * 180.0 / M_PI) * M_PI / 180.0;
    r.primaryVector = readVector(t, "primary_vector");
    r.secondaryVector = readVector(t, "secondary_vector");
    r.vectorTolerance = t.positive("vector_tolerance", r.vectorTolerance);
    r.area = readArea(t);
    t.finish();
    return r;
}

void checkIndices(Table& t, const std::string& key, const std::vector<Index>& indices, std::size_t count) {
    for (Index i : indices)
        if (i >= count) t.fail(*t.node(key), key, "index " + std::to_string(i) + " out of range (the part has " + std::to_string(count) + ")");
}

// Masses are named by the user's vertices (the file's: PartModel::vertexCount()); one the
// repair removed has no mass.
void checkMasses(Table& t, const std::vector<Index>& masses, const PartModel& model) {
    checkIndices(t, "masses", masses, model.vertexCount());
    for (Index v : masses)
        if (model.file && model.file->vertices.meshVertex[v] == kNoVertex)
            t.fail(*t.node("masses"), "masses", "vertex " + std::to_string(v) + " of the part's mesh file was removed by the repair (no face uses it): it has no mass");
}

std::string formatSeconds(double seconds) {
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", seconds);
    return text;
}

SceneAction readAction(Table& t, Scene& scene, const PartIds& parts) {
    using Kind = SceneAction::Kind;
    SceneAction a;
    a.line = t.line();
    if (!t.has("time")) t.fail("missing key 'time'");
    a.time = t.nonNegative("time", 0.0);
    if (!t.has("type")) t.fail("missing key 'type'");
    a.kind = t.choice("type", Kind::Push);
    a.body = partId(t, "part", parts);
    const ScenePart& part = scene.parts[a.body];
    switch (a.kind) {
        case Kind::Grab:
            a.grab.frequency = t.positive("frequency", a.grab.frequency);
            a.grab.stiffness = t.nonNegative("stiffness", 0.0);
            // Left out: critical damping (GrabSettings' -1); given, it must be >= 0.
            a.grab.damping = t.has("damping") ? t.nonNegative("damping", 0.0) : -1.0;
            a.grab.angularStiffness = t.nonNegative("angular_stiffness", 0.0);
            a.grab.angularDamping = t.has("angular_damping") ? t.nonNegative("angular_damping", 0.0) : -1.0;
            if (part.body.motion == MotionType::Static) t.fail(*t.node("part"), "part", "a static part cannot be grabbed");
            break;
        case Kind::Move:
            if (!t.has("position")) t.fail("missing key 'position'");
            a.target = t.pose("position", "rotation");
            a.duration = t.nonNegative("duration", 0.0);
            break;
        case Kind::Release: break;
        case Kind::Push:
            if (!t.has("force")) t.fail("missing key 'force'");
            a.force = t.vec3("force", Vec3::Zero());
            a.duration = t.nonNegative("duration", 0.0);
            break;
        case Kind::Force:
            if (!t.has("force")) t.fail("missing key 'force'");
            a.force = t.vec3("force", Vec3::Zero());
            a.duration = t.nonNegative("duration", 0.0);
            a.masses = t.indices("masses");
            a.faces = t.indices("faces");
            if (a.masses.empty() && a.faces.empty()) t.fail("a force needs 'masses' or 'faces'");
            checkMasses(t, a.masses, *part.model);
            checkIndices(t, "faces", a.faces, part.model->faceCount());
            break;
        case Kind::Velocity:
            a.linear = t.vec3("linear", Vec3::Zero());
            a.angular = t.vec3("angular", Vec3::Zero());
            break;
        case Kind::Kick:
            if (!t.has("velocity")) t.fail("missing key 'velocity' (the masses' velocity change)");
            a.linear = t.vec3("velocity", Vec3::Zero());
            a.masses = t.indices("masses");
            if (a.masses.empty()) t.fail("a kick needs 'masses'");
            checkMasses(t, a.masses, *part.model);
            break;
    }
    t.finish();
    // Said, not refused: a sweep may make the part static in some runs (a grab there cannot be).
    if ((a.kind == Kind::Push || a.kind == Kind::Velocity) && part.body.motion == MotionType::Static)
        scene.warnings.push_back({t.line("part"), t.what() + ", key 'part': a static part does not move: the " + toString(a.kind) +
                                                      " has no effect on it"});
    if (a.time >= scene.duration)
        scene.warnings.push_back({t.line("time"), t.what() + ", key 'time': at or after the scene's duration (" + formatSeconds(scene.duration) +
                                                      " s): the action runs only in a longer run"});
    return a;
}

// Moves and releases need the part to be held at that time.
void checkOperatorScript(const Scene& scene) {
    std::optional<BodyId> held;
    for (const SceneAction& a : scene.actions) {
        using Kind = SceneAction::Kind;
        if (a.kind == Kind::Grab) held = a.body;
        if ((a.kind == Kind::Move || a.kind == Kind::Release) && held != a.body)
            throw InputError(scene.source, a.line, std::string("action '") + toString(a.kind) + "': part '" + scene.parts[a.body].name +
                                                       "' is not grabbed at that time");
        if (a.kind == Kind::Release) held.reset();
    }
}

void readWorld(Table& root, Scene& scene) {
    if (!root.has("world")) return;
    Table w = root.sub("world");
    WorldSettings& s = scene.world;
    s.timeStep = w.positive("time_step", s.timeStep);
    s.gravity = w.vec3("gravity", s.gravity);
    scene.duration = w.positive("duration", scene.duration);
    s.maxTravelFraction = w.positive("max_travel_fraction", s.maxTravelFraction);
    if (s.maxTravelFraction > 1.0) w.fail(*w.node("max_travel_fraction"), "max_travel_fraction", "must be in (0, 1]");
    s.maxSubsteps = w.integer("max_substeps", s.maxSubsteps, 1, kMostSubsteps);
    s.contactIterations = w.integer("contact_iterations", s.contactIterations, 1, kMostContactIterations);
    s.contactSlop = w.positive("contact_slop", s.contactSlop);
    if (s.contactSlop > 1.0) w.fail(*w.node("contact_slop"), "contact_slop", "must be in (0, 1]");
    s.contactDamping = w.nonNegative("contact_damping", s.contactDamping);
    s.collision.exactTest = w.choice("exact_test", ExactTest::TriangleTriangle);
    s.collision.rigidDeformable = w.choice("rigid_deformable_query", RigidDeformableQuery::Auto);
    s.collision.coherent = w.flag("coherent_collision", s.collision.coherent);
    w.finish();
    try {
        validateSettings(s);
    } catch (const InputError& e) {
        w.fail(e.problem());
    }
}

// The [world] key a run of no step or of too many is reported at: the time step when it lies
// outside what simulations use (1 us to 1 s) or the table states no duration, else the
// duration (a duration of 1e300 had been reported at the time step's line).
const char* stepCountKey(const toml::table* world, double timeStep) {
    const bool usualStep = timeStep >= 1e-6 && timeStep <= 1.0;
    const bool hasDuration = world != nullptr && world->contains("duration"), hasStep = world != nullptr && world->contains("time_step");
    return hasStep && (!usualStep || !hasDuration) ? "time_step" : "duration";
}

}  // namespace

Scene parseScene(std::string_view text, const std::string& source, const std::filesystem::path& baseDirectory,
                 const SceneReadOptions& options) {
    toml::table document;
    try {
        document = toml::parse(text, source);
    } catch (const toml::parse_error& e) {
        throw InputError(source, e.source().begin.line, "TOML syntax: " + std::string(e.description()));
    }
    Scene scene = detail::readSceneDocument(document, source, baseDirectory, options);
    // Checked here, not in readWorld: a sweep's run sets its own duration after reading.
    if (const std::optional<std::string> problem = stepCountProblem(scene.duration, scene.world.timeStep)) {
        const toml::node* world = document.get("world");
        const toml::table* w = world != nullptr ? world->as_table() : nullptr;
        const char* key = stepCountKey(w, scene.world.timeStep);
        const toml::node* at = w != nullptr ? w->get(key) : nullptr;
        throw InputError(source, at != nullptr ? lineOf(*at) : 0, std::string("scene.world, key '") + key + "': " + *problem);
    }
    return scene;
}

AssemblyRule detail::readAssemblyTable(const toml::table& table, const std::string& source, const std::vector<std::string>& partNames,
                                       std::vector<SceneWarning>& warnings) {
    Scene scene;  // no other rules; readAssembly looks the rule's bodies up by name
    scene.source = source;
    PartIds parts;
    for (BodyId id = 0; id < partNames.size(); ++id) parts.emplace(partNames[id], id);  // the first of a name, as Scene::find
    Table t(table, "assembly", scene.source, warnings);
    return readAssembly(t, scene, parts);
}

namespace {

// The restoration constraint's default fraction is per step and was chosen for the default
// 1 ms step: at another step h a deforming part restores (1 ms / h) times as fast and resists
// loads about (1 ms / h)^2 times as stiffly (k ~ c m / h^2, simulation.hpp), which a user
// moving a scene to a haptic rate does not expect. Said where the fraction is the default; a
// fraction or a rate the scene gives is its choice.
void warnOfPerStepRestoration(const Table& t, const ScenePart& p, Scene& scene) {
    if (t.has("constraint_fraction") || t.has("constraint_rate")) return;
    if (const std::optional<DefaultFractionElsewhere> d = defaultFractionAt(p.part, scene.world.timeStep))
        scene.warnings.push_back({t.line("restoration"),
                                  t.what() + ": " + describe(*d, {"time_step = ", "constraint_rate = ", " (1/s)", "restoration = \"anchors\""})});
}

}  // namespace

Scene detail::readSceneDocument(const toml::table& document, const std::string& source, const std::filesystem::path& baseDirectory,
                                const SceneReadOptions& options) {
    Scene scene;
    scene.source = source;
    Table root(document, "scene", scene.source, scene.warnings);
    readWorld(root, scene);
    PartIds ids;
    for (const toml::table* t : tables(root, "part")) {
        Table part(*t, "part " + std::to_string(scene.parts.size() + 1), scene.source, scene.warnings);
        ScenePart p = readPart(part, baseDirectory, options, scene.warnings);
        if (ids.contains(p.name)) part.fail(*t->get("name"), "name", "duplicate part name '" + p.name + "'");
        warnOfPerStepRestoration(part, p, scene);
        ids.emplace(p.name, BodyId(scene.parts.size()));
        scene.parts.push_back(std::move(p));
    }
    if (scene.parts.empty()) root.fail("no [[part]]: a scene needs at least one part");
    for (const toml::table* t : tables(root, "assembly")) {
        Table a(*t, "assembly " + std::to_string(scene.assemblies.size() + 1), scene.source, scene.warnings);
        scene.assemblies.push_back(readAssembly(a, scene, ids));
    }
    for (const toml::table* t : tables(root, "action")) {
        Table a(*t, "action " + std::to_string(scene.actions.size() + 1), scene.source, scene.warnings);
        scene.actions.push_back(readAction(a, scene, ids));
    }
    std::stable_sort(scene.actions.begin(), scene.actions.end(), [](const SceneAction& a, const SceneAction& b) { return a.time < b.time; });
    checkOperatorScript(scene);
    if (root.has("output")) {
        Table o = root.sub("output");
        scene.objEvery = o.nonNegative("obj_every", 0.0);
        scene.vtkEvery = o.nonNegative("vtk_every", 0.0);
        scene.glbEvery = o.nonNegative("glb_every", 0.0);
        o.finish();
    }
    root.finish();
    return scene;
}

Scene loadScene(const std::filesystem::path& file, const SceneReadOptions& options) {
    return parseScene(detail::readTextDocument(file, "scene file"), file.string(), file.parent_path(), options);
}

}  // namespace flexfit
