// flexfit._flexfit: the C++ API for Python (pybind11). The package's __init__.py re-exports it
// and adds flexfit.sweep (Dask).
//
// Lifetimes: a Part or RigidBody obtained from a World (World.part(id)) is a view into it and
// keeps the World alive; state arrays (positions, velocities, rest positions, moving masses)
// are NumPy views without copies that keep their owner alive, read-only (the state changes
// through the API: forces, zones, steps). Arrays computed on request (zone depths, world
// positions) are fresh copies. Enum values are the scene file's names ("rigid-deformable").
// World.step() and SceneRun.step() release the GIL. InputError and DivergenceError become
// flexfit.InputError (a ValueError with .source, .line, .problem) and flexfit.DivergenceError
// (a RuntimeError with .body, .time, .problem), carrying the C++ message.
#include "flexfit/flexfit.hpp"
#include "io/scene_document.hpp"
#include "scene_runner.hpp"
#include "sweep_runner.hpp"

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

namespace py = pybind11;
using namespace flexfit;

namespace {

// A read-only NumPy view of n rows of `width` doubles at `data`, keeping `owner` alive.
py::array rowsView(const double* data, std::size_t n, std::size_t width, py::handle owner) {
    py::array a(py::dtype::of<double>(), {n, width}, {width * sizeof(double), sizeof(double)}, data, owner);
    a.attr("flags").attr("writeable") = false;
    return a;
}

py::array vec3View(std::span<const Vec3> v, py::handle owner) {
    static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is three packed doubles");
    return rowsView(v.empty() ? nullptr : v.front().data(), v.size(), 3, owner);
}

py::array_t<double> vec3Copy(const std::vector<Vec3>& v) {
    py::array_t<double> a({v.size(), std::size_t(3)});
    auto m = a.mutable_unchecked<2>();
    for (std::size_t i = 0; i < v.size(); ++i)
        for (int k = 0; k < 3; ++k) m(py::ssize_t(i), k) = v[i][k];
    return a;
}

// Python speaks the user's vertex indices (the file's, for a scene part whose file lost vertices
// to welding or repair): a model renumbered for locality translates them to masses here
// (PartModel::massOf, which refuses an index past a file's vertices; without a file numbering one
// out of range passes through for the C++ call to refuse).
// Per-mass rows in the user's vertex order: a read-only view of the state when the masses are
// the vertices, else a read-only copy. A file vertex the repair removed reads its file position
// (part frame, `positions`) or zero.
py::array vertexRows(const PartModel& model, std::span<const Vec3> perMass, py::handle owner, bool positions) {
    if (model.massesAreVertices()) return vec3View(perMass, owner);
    std::vector<Vec3> rows;
    inVertexOrder<Vec3>(model, perMass, rows, [&](Index v) { return positions ? model.file->vertices.positions[v] : Vec3(Vec3::Zero()); });
    py::array a = vec3Copy(rows);
    a.attr("flags").attr("writeable") = false;
    return a;
}

template <class Enum>
Enum enumFrom(const std::string& text, const char* what) {
    const std::optional<Enum> value = parseName<Enum>(text);
    if (!value) throw InputError(what, 0, "unknown value '" + text + "' (expected one of " + nameList<Enum>() + ")");
    return *value;
}

// Pose from Python: position (3) and rotation as a quaternion (w, x, y, z).
Pose makePose(const Vec3& position, const Eigen::Vector4d& wxyz) {
    Pose p;
    p.translation = position;
    p.rotation = Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
    if (!(p.rotation.norm() > 0.0) || !position.allFinite() || !wxyz.allFinite()) throw InputError("pose", 0, "position and rotation must be finite, the rotation non-zero");
    p.rotation.normalize();
    return p;
}

py::dict poseDict(const Pose& p) {
    py::dict d;
    d["position"] = p.translation;
    d["rotation_wxyz"] = Eigen::Vector4d(p.rotation.w(), p.rotation.x(), p.rotation.y(), p.rotation.z());
    return d;
}

py::dict contactDict(const World& w, const Contact& c) {
    py::dict d;
    d["part_a"] = c.partA;
    d["part_b"] = c.partB;
    d["face_a"] = c.faceA;
    d["face_b"] = c.faceB;
    d["point"] = c.point;
    d["normal"] = c.normal;
    d["depth"] = c.depth;
    d["mass_b"] = c.massB == kNoMass ? py::object(py::none()) : py::object(py::int_(w.part(c.partB).model().vertexOf(c.massB)));
    return d;
}

py::dict profileDict(const Profile& p) {
    py::dict last, total;
    for (std::size_t i = 0; i < kStageCount; ++i) {
        last[toString(Stage(i))] = p.lastSeconds[i];
        total[toString(Stage(i))] = p.totalSeconds[i];
    }
    py::dict d;
    d["last_seconds"] = last;
    d["total_seconds"] = total;
    d["last_step_seconds"] = p.lastStepSeconds;
    d["total_step_seconds"] = p.totalStepSeconds;
    d["steps"] = p.steps;
    d["substeps"] = p.substeps;
    d["cut_moves"] = p.cutMoves;
    d["rigid_queries"] = p.rigidQueries;
    d["face_queries"] = p.faceQueries;
    d["face_traversals"] = p.faceTraversals;
    return d;
}

py::dict eventDict(const AssemblyEvent& e) {
    py::dict d;
    d["rule"] = e.rule;
    d["technique"] = toString(e.technique);
    d["time"] = e.time;
    d["from"] = poseDict(e.primaryPoseBefore);
    d["to"] = poseDict(e.primaryPoseAfter);
    return d;
}

std::vector<FramePart> frameParts(const World& world, const std::vector<std::string>& names) {
    if (!names.empty() && names.size() != world.bodyCount())
        throw InputError("names", 0, "one name per body (" + std::to_string(world.bodyCount()) + "), or none");
    std::vector<FramePart> parts;
    for (BodyId id = 0; id < world.bodyCount(); ++id) parts.push_back({names.empty() ? "part" + std::to_string(id) : names[id], &world.part(id)});
    return parts;
}

TriMesh meshFromArrays(py::array_t<double, py::array::c_style | py::array::forcecast> vertices,
                       py::array_t<std::int64_t, py::array::c_style | py::array::forcecast> faces, const std::string& name) {
    if (vertices.ndim() != 2 || vertices.shape(1) != 3) throw InputError("vertices", 0, "expected an (n, 3) array");
    if (faces.ndim() != 2 || faces.shape(1) != 3) throw InputError("faces", 0, "expected an (m, 3) array of vertex indices");
    TriMesh mesh;
    mesh.name = name;
    auto v = vertices.unchecked<2>();
    for (py::ssize_t i = 0; i < v.shape(0); ++i) mesh.vertices.emplace_back(v(i, 0), v(i, 1), v(i, 2));
    auto f = faces.unchecked<2>();
    for (py::ssize_t i = 0; i < f.shape(0); ++i) {
        Face face;
        for (int k = 0; k < 3; ++k) {
            if (f(i, k) < 0 || f(i, k) >= v.shape(0))
                throw InputError("faces", 0, "face " + std::to_string(i) + " has vertex " + std::to_string(f(i, k)) + ", out of range");
            face[std::size_t(k)] = Index(f(i, k));
        }
        mesh.faces.push_back(face);
    }
    return mesh;
}

// Scene warnings as Python sees them: their messages (a scene's file and lines are its own).
std::vector<std::string> messagesOf(const std::vector<SceneWarning>& warnings) {
    std::vector<std::string> out;
    for (const SceneWarning& w : warnings) out.push_back(w.message);
    return out;
}

// load_scene's and run_scene's keywords: remesh_cache None is the default directory, "" none.
SceneReadOptions sceneReadOptions(bool strict, std::optional<std::filesystem::path> remeshCache) {
    SceneReadOptions options;
    options.strictMeshes = strict;
    options.remeshCache = std::move(remeshCache);
    return options;
}

py::object summaryObject(const Scene& scene, const cli::RunSummary& s) {
    return py::module_::import("json").attr("loads")(cli::summaryJson(scene, s));
}


// A part's and body's settings from keyword arguments named as the scene file's [[part]] keys
// (scene.hpp); `body` is null for a part alone (it takes `time_step` instead). An unknown key is
// an InputError naming it; the values are checked where the C++ API checks them.
void applyPartKeywords(const py::kwargs& keywords, PartSettings& part, BodySettings* body) {
    SimulationSettings& sim = part.simulation;
    ZoneSettings& zones = part.zones;
    std::optional<double> kinetic;
    for (const auto& [key, value] : keywords) {
        const std::string k = py::str(key);
        try {
        auto number = [&] { return value.cast<double>(); };
        auto integer = [&] { return value.cast<int>(); };
        if (k == "mode") part.mode = enumFrom<PartMode>(value.cast<std::string>(), "mode");
        else if (k == "integrator") sim.integrator = enumFrom<Integrator>(value.cast<std::string>(), "integrator");
        else if (k == "implicit_iterations") sim.implicit.maxIterations = integer();
        else if (k == "implicit_tolerance") sim.implicit.tolerance = number();
        else if (k == "global_damping") sim.globalDamping = number();
        else if (k == "restoration") sim.restoration.method = enumFrom<RestorationMethod>(value.cast<std::string>(), "restoration");
        else if (k == "constraint_fraction") sim.restoration.constraintFraction = number();
        else if (k == "constraint_rate") sim.restoration.constraintRate = number();
        else if (k == "anchor_stiffness") sim.restoration.anchorStiffness = number();
        else if (k == "anchor_damping") sim.restoration.anchorDamping = number();
        else if (k == "default_level") zones.defaultLevel = integer();
        else if (k == "contact_level") zones.contactLevel = integer();
        else if (k == "activity_threshold") zones.activityThreshold = number();
        else if (k == "rest_speed") zones.restSpeed = number();
        else if (k == "reserved_zones") zones.reservedZones = integer();
        else if (!body && k == "time_step") sim.timeStep = number();
        else if (body && k == "motion") body->motion = enumFrom<MotionType>(value.cast<std::string>(), "motion");
        else if (body && k == "density") body->density = number();
        else if (body && k == "velocity") body->linearVelocity = value.cast<Vec3>();
        else if (body && k == "angular_velocity") body->angularVelocity = value.cast<Vec3>();
        else if (body && k == "thickness") body->thickness = number();
        else if (body && k == "static_friction") body->staticFriction = number();
        else if (body && k == "kinetic_friction") kinetic = number();
        else if (body && k == "restitution") body->restitution = number();
        else throw InputError(k, 0, "unknown keyword (the scene file's [[part]] keys: mode, motion, density, restoration, anchor_stiffness, ...)");
        } catch (const py::cast_error&) {
            throw InputError(k, 0, "a value of the wrong type: " + std::string(py::str(py::repr(value))));
        }
    }
    if (body) body->kineticFriction = kinetic.value_or(body->staticFriction);  // as in scene files
}

// A Python UserWarning when a deforming part takes the restoration constraint's default fraction
// (per step, chosen for 1 ms) at another time step, as scene files warn (defaultFractionAt).
void warnOfDefaultFraction(const py::kwargs& keywords, const PartSettings& part, double timeStep) {
    if (keywords.contains("constraint_fraction") || keywords.contains("constraint_rate")) return;
    if (const std::optional<DefaultFractionElsewhere> d = defaultFractionAt(part, timeStep)) {
        const std::string message = describe(*d, {"time_step ", "constraint_rate=", "", "restoration='anchors'"});
        if (PyErr_WarnEx(PyExc_UserWarning, message.c_str(), 1) != 0) throw py::error_already_set();
    }
}

// A Python value as a TOML node: bool, int, float, str, a dict (table), a sequence (array),
// nested, and NumPy scalars and arrays (by their tolist()); anything else is an InputError of
// `source` naming the key.
std::unique_ptr<toml::node> tomlValue(const py::handle& value, const std::string& key, const std::string& source) {
    if (py::isinstance<py::bool_>(value)) return std::make_unique<toml::value<bool>>(value.cast<bool>());
    if (py::isinstance<py::int_>(value)) {
        try {
            return std::make_unique<toml::value<std::int64_t>>(value.cast<std::int64_t>());
        } catch (const py::cast_error&) {
            throw InputError(source, 0, "key '" + key + "': an integer out of range: " + std::string(py::str(value)));
        }
    }
    if (py::isinstance<py::float_>(value)) return std::make_unique<toml::value<double>>(value.cast<double>());
    if (py::isinstance<py::str>(value)) return std::make_unique<toml::value<std::string>>(value.cast<std::string>());
    if (py::isinstance<py::dict>(value)) {
        auto table = std::make_unique<toml::table>();
        for (const auto& [k, v] : value.cast<py::dict>()) {
            const std::string name = py::str(k);
            table->insert(name, std::move(*tomlValue(v, key + "." + name, source)));
        }
        return table;
    }
    if (py::hasattr(value, "tolist")) return tomlValue(value.attr("tolist")(), key, source);  // NumPy: Python values
    if (py::isinstance<py::sequence>(value)) {
        auto array = std::make_unique<toml::array>();
        for (const py::handle item : value) array->push_back(std::move(*tomlValue(item, key, source)));
        return array;
    }
    throw InputError(source, 0, "key '" + key + "': a value of a type a scene file cannot hold: " + std::string(py::str(py::repr(value))));
}

// An assembly rule from keywords named as the scene file's [[assembly]] keys, read by the
// scene reader itself (so the same keys, defaults and checks); bodies by id.
AssemblyRule assemblyRule(const World& w, BodyId primary, BodyId secondary, const py::kwargs& keywords, std::size_t ruleCount) {
    for (const auto& [role, id] : {std::pair{"primary", primary}, std::pair{"secondary", secondary}})
        if (id >= w.bodyCount())
            throw InputError("add_assembly", 0, std::string(role) + ": no body " + std::to_string(id) + " (the world has " +
                                                    std::to_string(w.bodyCount()) + ")");
    toml::table table;
    for (const auto& [key, value] : keywords) {
        const std::string k = py::str(key);
        if (k == "primary" || k == "secondary") throw InputError("add_assembly", 0, "key '" + k + "': give the body id as the argument");
        table.insert(k, std::move(*tomlValue(value, k, "add_assembly")));
    }
    std::vector<std::string> names;
    for (BodyId id = 0; id < w.bodyCount(); ++id) names.push_back("body " + std::to_string(id));
    table.insert("primary", names[primary]);
    table.insert("secondary", names[secondary]);
    if (!table.contains("name")) table.insert("name", "assembly " + std::to_string(ruleCount));
    std::vector<SceneWarning> warnings;
    AssemblyRule rule = detail::readAssemblyTable(table, "add_assembly", names, warnings);
    for (const SceneWarning& warning : warnings)  // old spellings: Python warnings, as scene files print them
        if (PyErr_WarnEx(PyExc_DeprecationWarning, warning.message.c_str(), 1) != 0) throw py::error_already_set();
    return rule;
}

PartModelSettings modelSettings(std::optional<std::string> material, std::optional<std::pair<double, double>> springs, double vertexMass,
                                std::optional<double> youngsModulus, std::optional<double> thickness, std::optional<double> density,
                                double poissonRatio, double dampingRatio, bool bendingSprings) {
    PartModelSettings s;
    if (int(bool(material)) + int(bool(springs)) + int(bool(youngsModulus)) > 1)
        throw InputError("material", 0, "give one of material (a preset), springs (stiffness, damping) or youngs_modulus (a physical material)");
    if (material) {
        const auto preset = materialPreset(*material);
        if (!preset) throw InputError("material", 0, "unknown material preset '" + *material + "' (rigid, elastic, superelastic)");
        s.material = *preset;
    }
    if (springs) s.material = Material{springs->first, springs->second};
    s.vertexMass = vertexMass;
    if (youngsModulus) {
        if (!thickness || !density) throw InputError("youngs_modulus", 0, "a physical material needs thickness and density too");
        s.shell = ShellMaterial{*youngsModulus, poissonRatio, *thickness, *density, dampingRatio, bendingSprings};
    } else if (thickness || density) {
        throw InputError(thickness ? "thickness" : "density", 0, "belongs to a physical material: give youngs_modulus too");
    }
    return s;
}

// A world's part, read-only in Python: its state changes only through the World.
struct PartView {
    const Part* part = nullptr;
};

// What Part and PartView both read. `get` gives the part of a Python object; arrays that are
// views keep that object (and so the part's owner) alive.
template <class Class, class Get>
void addPartReaders(Class& c, Get get) {
    c.def_property_readonly("mode", [get](py::object self) { return std::string(toString(get(self).mode())); }, "rigid, rigid-deformable or full-deformable.")
        .def_property_readonly("model", [get](py::object self) { return std::const_pointer_cast<PartModel>(get(self).sharedModel()); },
                               "The part's model (shared, immutable).")
        .def_property_readonly("positions", [get](py::object self) { return vertexRows(get(self).model(), get(self).state().positions, self, true); },
                               "Mass positions in the part frame (the mesh's vertex order), a read-only (n, 3) view of the state, or a read-only copy when "
                               "the masses are not the vertices (renumbered, or a file whose vertices were welded or removed: then vertex_count rows; "
                               "non-moving masses at rest).")
        .def_property_readonly("velocities", [get](py::object self) { return vertexRows(get(self).model(), get(self).state().velocities, self, false); },
                               "Mass velocities (part frame, the mesh's vertex order), a read-only (n, 3) view, or a copy when the masses are not the vertices.")
        .def_property_readonly("moving_masses", [get](py::object self) {
            const Part& part = get(self);
            std::vector<Index> vertices;
            for (Index m : part.movingMasses()) vertices.push_back(part.model().vertexOf(m));
            return py::array_t<Index>(py::ssize_t(vertices.size()), vertices.data());
        }, "Indices of the masses the zones move, a new array (the list changes with every zone).")
        .def_property_readonly("zone_depths", [get](py::object self) {
            std::vector<int> perMass, depths;
            get(self).zoneDepths(perMass);
            inVertexOrder<int>(get(self).model(), perMass, depths, [](Index) { return -1; });
            return py::array_t<int>(py::ssize_t(depths.size()), depths.data());
        }, "Each mass's depth in the zones covering it (0 = seed, -1 = at rest), a new int array.")
        .def("world_positions", [get](py::object self) {
            std::vector<Vec3> rows;
            get(self).vertexWorldPositions(rows);
            return vec3Copy(rows);
        }, "Mass positions in the world, a new (n, 3) array.")
        .def_property_readonly("zone_count", [get](py::object self) { return get(self).zoneCount(); }, "Zones open on the part.")
        .def_property_readonly("time", [get](py::object self) { return get(self).time(); }, "The part's simulated time (s).")
        .def_property_readonly("pose", [get](py::object self) { return poseDict(get(self).pose()); },
                               "The part's pose: {'position', 'rotation_wxyz'} (part frame to world).")
        .def("state_hash", [get](py::object self) { return stateHash(get(self).state()); }, "64-bit hash of the state, bit for bit.");
}
}  // namespace

PYBIND11_MODULE(_flexfit, m) {
    m.doc() = "Flexfit: rigid-deformable parts for virtual assembly (C++ library bindings)";

    // --- Errors ---
    static py::exception<InputError> inputError(m, "InputError", PyExc_ValueError);
    static py::exception<DivergenceError> divergenceError(m, "DivergenceError", PyExc_RuntimeError);
    inputError.doc() = "Bad input: a file, a scene, a parameter. Attributes: source, line, problem.";
    divergenceError.doc() = "A run diverged (non-finite state). Attributes: body (or None), time, problem.";
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InputError& e) {
            py::object error = py::handle(inputError)(e.what());
            error.attr("source") = e.source();
            error.attr("line") = e.line();
            error.attr("problem") = e.problem();
            PyErr_SetObject(inputError.ptr(), error.ptr());
        } catch (const DivergenceError& e) {
            py::object error = py::handle(divergenceError)(e.what());
            error.attr("body") = e.body() ? py::object(py::int_(*e.body())) : py::object(py::none());
            error.attr("time") = e.time();
            error.attr("problem") = e.problem();
            PyErr_SetObject(divergenceError.ptr(), error.ptr());
        }
    });

    // --- Meshes ---
    py::class_<TriMesh>(m, "Mesh", "A triangle mesh: vertices (n, 3) and faces (m, 3), counter-clockwise seen from outside.")
        .def(py::init(&meshFromArrays), py::arg("vertices"), py::arg("faces"), py::arg("name") = "mesh",
             "A mesh from arrays (copied); faces index the vertices from 0.")
        .def_readwrite("name", &TriMesh::name, "The mesh's name (from its file, or given).")
        .def_property_readonly("vertices", [](py::object self) { return vec3View(self.cast<const TriMesh&>().vertices, self); },
                               "Vertex positions, a read-only (n, 3) view.")
        .def_property_readonly("faces", [](py::object self) {
            const auto& f = self.cast<const TriMesh&>().faces;
            py::array a(py::dtype::of<Index>(), {f.size(), std::size_t(3)}, {3 * sizeof(Index), sizeof(Index)}, f.empty() ? nullptr : f.front().data(), self);
            a.attr("flags").attr("writeable") = false;
            return a;
        }, "Vertex indices of each face, a read-only (m, 3) view.")
        .def("__repr__", [](const TriMesh& mesh) { return "<flexfit.Mesh '" + mesh.name + "': " + std::to_string(mesh.vertices.size()) + " vertices, " + std::to_string(mesh.faces.size()) + " faces>"; });

    py::class_<FileVertices>(m, "FileVertices", "Where each vertex of a mesh file went when the read welded or removed some "
                                                "(read_mesh(..., file_vertices=True)); give it to PartModel to keep the file's vertex numbering.")
        .def_property_readonly("count", &FileVertices::count, "The file's vertex count.")
        .def_property_readonly("mesh_vertex", [](const FileVertices& f) {
            std::vector<std::int64_t> v(f.count());
            for (std::size_t u = 0; u < v.size(); ++u) v[u] = f.meshVertex[u] == kNoVertex ? -1 : std::int64_t(f.meshVertex[u]);
            return py::array_t<std::int64_t>(py::ssize_t(v.size()), v.data());
        }, "The mesh vertex each file vertex became (-1: removed, no face used it), a new array.")
        .def_property_readonly("positions", [](const FileVertices& f) { return vec3Copy(f.positions); }, "The file's vertex positions, a new (n, 3) array.");

    m.def("read_mesh", [](const std::filesystem::path& path, bool strict, std::optional<double> weld, bool fileVertices) {
        MeshReadOptions options;
        options.repair = !strict;
        options.weldTolerance = weld;
        MeshReadResult r;
        {
            py::gil_scoped_release release;
            r = readMesh(path, options);
        }
        if (!fileVertices) return py::make_tuple(std::move(r.mesh), r.diagnostics.warnings);
        py::object numbering = r.fileVertices.empty() ? py::object(py::none()) : py::cast(std::move(r.fileVertices));
        return py::make_tuple(std::move(r.mesh), r.diagnostics.warnings, numbering);
    }, py::arg("path"), py::arg("strict") = false, py::arg("weld") = py::none(), py::kw_only(), py::arg("file_vertices") = false,
          "Reads a mesh (.tri, OBJ, STL, PLY, OFF, glTF, ...). Returns (mesh, warnings): geometric defects are repaired and listed, "
          "or refused with strict=True. With file_vertices=True, (mesh, warnings, numbering): a FileVertices when the read welded or "
          "removed vertices (None otherwise), for PartModel(..., file_vertices=numbering) to keep the file's vertex indices. Raises "
          "InputError naming the file and line.");
    m.def("write_mesh", &writeMesh, py::arg("mesh"), py::arg("path"), "Writes a mesh; the format follows the extension (.tri, .obj, ...).");
    m.def("torus", &makeTorus, py::arg("major"), py::arg("minor"), py::arg("u"), py::arg("v"), "A torus of u x v vertices about the y axis.");
    m.def("sphere", &makeIcoSphere, py::arg("radius"), py::arg("level"), "An icosphere subdivided `level` times.");
    m.def("box", [](const Vec3& half, int divisions) { return makeBox(half, divisions); }, py::arg("half_extents"), py::arg("divisions") = 1,
          "A box with each face divided into divisions x divisions squares.");
    m.def("heart", &makeHeart, py::arg("size") = 20.0, py::arg("segments") = 93, py::arg("rings") = 80, "The thesis's heart.");
    m.def("container_mouth", &makeContainerMouth, "The thesis's container mouth (a torus R = 10, r = 2.5, 64 x 24).");
    m.def("remesh", [](const TriMesh& mesh, double edge, const std::string& thinFeatures) {
        RemeshOptions options;
        options.targetEdge = edge;
        const std::optional<ThinFeatures> chosen = parseName<ThinFeatures>(thinFeatures);
        if (!chosen) throw InputError("thin_features", 0, "unknown value '" + thinFeatures + "' (expected 'auto', 'keep' or 'round')");
        options.thinFeatures = *chosen;
        RemeshResult r;
        {
            const TriMesh input = mesh;  // a copy: other Python threads may change `mesh` meanwhile
            py::gil_scoped_release release;
            r = remeshForSimulation(input, options, input.name);
        }
        py::dict q;
        q["min_angle_degrees"] = r.after.minAngle;
        q["slivers"] = r.after.slivers;
        q["edge_spread"] = r.after.edgeSpread;
        q["hausdorff_share"] = r.hausdorffShare();
        q["thin_features_rounded"] = r.rounded;
        return py::make_tuple(std::move(r.mesh), q);
    }, py::arg("mesh"), py::arg("edge"), py::arg("thin_features") = "auto",
          "Simulation remeshing (CGAL): near-uniform edges of length `edge`, sharp features kept; sharp edges closer than half "
          "the edge kept ('keep'), rounded ('round') or rounded where that leaves fewer slivers within `edge` of the input "
          "('auto'). Returns (mesh, quality); the GIL is released meanwhile.");

    // --- Models and parts ---
    py::class_<PartModel, std::shared_ptr<PartModel>>(m, "PartModel", "A part's immutable model: its mesh, masses and springs.")
        .def(py::init([](TriMesh mesh, std::optional<std::string> material, std::optional<std::pair<double, double>> springs, double vertexMass,
                         std::optional<double> youngsModulus, std::optional<double> thickness, std::optional<double> density, double poissonRatio,
                         double dampingRatio, bool bendingSprings, const std::string& vertexOrder, std::optional<FileVertices> fileVertices) {
                 PartModelSettings settings = modelSettings(material, springs, vertexMass, youngsModulus, thickness, density, poissonRatio, dampingRatio, bendingSprings);
                 if (fileVertices) settings.fileVertices = std::move(*fileVertices);
                 if (vertexOrder != "as_given" && vertexOrder != "locality")
                     throw InputError("vertex_order", 0, "unknown value '" + vertexOrder + "' (expected 'as_given' or 'locality')");
                 settings.vertexOrder = vertexOrder == "locality" ? VertexOrder::Locality : VertexOrder::AsGiven;
                 py::gil_scoped_release release;  // a large mesh's topology, order and spring blocks
                 return std::const_pointer_cast<PartModel>(buildPartModel(std::move(mesh), settings));
             }),
             py::arg("mesh"), py::arg("material") = py::none(), py::arg("springs") = py::none(), py::arg("vertex_mass") = 1.0, py::kw_only(),
             py::arg("youngs_modulus") = py::none(), py::arg("thickness") = py::none(), py::arg("density") = py::none(), py::arg("poisson_ratio") = 0.35,
             py::arg("damping_ratio") = 0.1, py::arg("bending_springs") = false, py::arg("vertex_order") = "as_given",
             py::arg("file_vertices") = py::none(),
             "Builds a model from a mesh: material a preset name ('elastic'), or springs=(stiffness, damping) with vertex_mass in kg, or a "
             "physical material (SI units): youngs_modulus, thickness, density, poisson_ratio, damping_ratio, bending_springs. "
             "vertex_order='locality' renumbers the masses for memory locality when that makes the step faster (a mesh from a file); "
             "every index and per-mass array in Python stays in the mesh's own vertex order either way. file_vertices (from "
             "read_mesh(..., file_vertices=True)) makes them the file's vertices, through the read's welds and removals.")
        .def_property_readonly("mass_count", &PartModel::massCount, "Number of masses (the mesh's vertices).")
        .def_property_readonly("vertex_count", &PartModel::vertexCount,
                               "Number of the user's vertices: the rows of per-vertex arrays (mass_count, or the file's vertex count for a model "
                               "built with file_vertices or a scene part whose file lost vertices to welding or repair).")
        .def_property_readonly("spring_count", [](const PartModel& model) { return model.springCount(); }, "Number of springs (edges, and bending springs of a physical material).")
        .def_property_readonly("mesh", [](py::object self) {
            const PartModel& model = self.cast<const PartModel&>();
            return py::cast(&model.userMesh(), py::return_value_policy::reference_internal, self);
        }, "The simulation mesh as given (rest shape, part frame; for a scene part whose file lost vertices to welding or repair, "
           "the file's vertices with the repaired faces over them).")
        .def_property_readonly("rest_positions", [](py::object self) { return vertexRows(self.cast<const PartModel&>(), self.cast<const PartModel&>().restPositions, self, true); },
                               "Rest positions, a read-only (n, 3) array (a view unless the masses are not the vertices).")
        .def_property_readonly("renumbered", &PartModel::renumbered, "Whether the masses are the mesh's vertices renumbered (vertex_order='locality').")
        .def_property_readonly("mass_of_vertex", [](const PartModel& model) {
            std::vector<std::int64_t> masses(model.vertexCount());
            for (Index v = 0; v < masses.size(); ++v) {
                const bool removed = model.file && model.file->vertices.meshVertex[v] == kNoVertex;
                masses[v] = removed ? -1 : std::int64_t(model.massOf(v));
            }
            return py::array_t<std::int64_t>(py::ssize_t(masses.size()), masses.data());
        }, "The internal mass of each vertex (for C++ code and the state hash; Python's indices are the vertices); -1 for a file vertex "
           "the repair removed.");

    py::class_<Part> partClass(m, "Part", "A part: a rigid body until pressed, then mass-spring-damper zones around the contacts.");
    partClass.def(py::init([](std::shared_ptr<PartModel> model, const py::kwargs& settings) {
                 PartSettings s;
                 applyPartKeywords(settings, s, nullptr);
                 warnOfDefaultFraction(settings, s, s.simulation.timeStep);
                 return Part(model, s);
             }),
             py::arg("model"),
             "A part stepped on its own (without a world). Settings as keywords named as the scene file's [[part]] keys "
             "(mode='rigid-deformable', restoration, anchor_stiffness, global_damping, integrator, contact_level, ...) and time_step.")
        .def("open_zone", [](Part& p, Index mass, int level) { return p.openZone(ZoneSeed::mass(p.model().massOf(mass)), level); }, py::arg("mass"), py::arg("level"),
             "Opens a zone of `level` rings around a mass; returns its id.")
        .def("apply_force", [](Part& p, Index mass, const Vec3& force) { p.applyForce(p.model().massOf(mass), force); }, py::arg("mass"), py::arg("force"),
             "A world-frame force on one mass for the next step.")
        .def("kick_mass", [](Part& p, Index mass, const Vec3& change) { p.kickMass(p.model().massOf(mass), change); }, py::arg("mass"),
             py::arg("velocity_change"), "A velocity change on one mass, now.")
        .def("step", [](Part& p) {
            py::gil_scoped_release release;
            p.step();
        }, "One step of the part alone (its own time step).");
    addPartReaders(partClass, [](py::handle self) -> const Part& { return self.cast<const Part&>(); });

    // A world's part, read-only: the world changes it (forces, zones and steps go through World).
    py::class_<PartView> view(m, "PartView", "A world's part, read-only (World.part): forces, zones and steps go through the World. Keeps the world alive.");
    addPartReaders(view, [](py::handle self) -> const Part& { return *self.cast<const PartView&>().part; });

    // --- World ---
    py::class_<World>(m, "World", "Parts with rigid-body motion, collisions, deformation and snapping; one step of named stages.")
        .def(py::init([](double timeStep, const Vec3& gravity) {
                 WorldSettings s;
                 s.timeStep = timeStep;
                 s.gravity = gravity;
                 return std::make_unique<World>(s);
             }),
             py::arg("time_step") = 1e-3, py::arg("gravity") = Vec3(0.0, -9.81, 0.0))
        .def("add", [](World& w, std::shared_ptr<PartModel> model, const Vec3& position, const Eigen::Vector4d& rotation, const py::kwargs& settings) {
            PartSettings part;
            BodySettings body;
            applyPartKeywords(settings, part, &body);
            warnOfDefaultFraction(settings, part, w.settings().timeStep);
            py::gil_scoped_release release;  // the part's hierarchies, and a distance field for the point shell
            return w.add(model, part, body, makePose(position, rotation));
        }, py::arg("model"), py::arg("position") = Vec3::Zero(), py::arg("rotation") = Eigen::Vector4d(1, 0, 0, 0),
             "Adds a part at a pose (rotation as a quaternion w, x, y, z); returns its body id. Settings as keywords named as the scene "
             "file's [[part]] keys, with the same defaults: mode ('rigid-deformable'; 'rigid', 'full-deformable'), motion ('static'; "
             "'kinematic', 'dynamic'), density, velocity, static_friction, kinetic_friction, restitution, restoration, anchor_stiffness, "
             "anchor_damping, constraint_rate, global_damping, integrator, contact_level, default_level, ...")
        .def_property_readonly("body_count", &World::bodyCount, "Bodies in the world (ids 0 .. body_count - 1).")
        .def("part", [](const World& w, BodyId id) { return PartView{&w.part(id)}; }, py::arg("id"), py::keep_alive<0, 1>(),
             "The body's part, read-only (a PartView that keeps the world alive).")
        .def("step", [](World& w, int steps) {
            py::gil_scoped_release release;
            for (int i = 0; i < steps; ++i) w.step();
        }, py::arg("steps") = 1, "Steps the world (the GIL is released meanwhile).")
        .def_property_readonly("time", &World::time, "Simulated time (s).")
        .def_property_readonly("step_count", &World::stepCount, "Steps taken.")
        .def("contacts", [](const World& w) {
            py::list out;
            for (const Contact& c : w.contacts()) out.append(contactDict(w, c));
            return out;
        }, "The last step's contacts, as dicts (part_a, part_b, point, normal, depth, ...).")
        .def("prepare", &World::prepare, py::call_guard<py::gil_scoped_release>(),
             "Before a real-time loop: does now what the first step would do once (each touching pair's first collision "
             "traversal, the contact scratch), so the first step costs what the next ones do. Changes no result.")
        .def("profile", [](const World& w) { return profileDict(w.profile()); }, "Per-stage times of the last step and in total (s).")
        .def("state_hash", &World::stateHash, "64-bit FNV-1a of the whole state, bit for bit (equal hashes: the same run).")
        .def("centre_of_mass", &World::centreOfMass, py::arg("id"), "World position of a body's centre of mass.")
        .def("pose", [](const World& w, BodyId id) { return poseDict(w.part(id).pose()); }, py::arg("id"), "A body's pose: {'position', 'rotation_wxyz'}.")
        .def("apply_force", &World::applyForce, py::arg("id"), py::arg("force"), "A force at the centre of mass for the next step.")
        .def("apply_mass_force", &World::applyMassForce,
             py::arg("id"), py::arg("mass"), py::arg("force"), "A world-frame force on one mass.")
        .def("kick_mass", &World::kickMass,
             py::arg("id"), py::arg("mass"), py::arg("velocity_change"),
             "A velocity change on one mass of a deforming part; on a rigid dynamic body, the same momentum as an impulse.")
        .def("set_velocity", &World::setVelocity, py::arg("id"), py::arg("linear"), py::arg("angular") = Vec3::Zero(),
             "Sets a dynamic body's velocity (world frame; rad/s for the angular one).")
        .def("open_zone", [](World& w, BodyId id, Index mass, int level) { return w.openZone(id, ZoneSeed::mass(mass), level); }, py::arg("id"),
             py::arg("mass"), py::arg("level"), "Opens a zone on a body's part around a mass (ahead of a contact); returns its id.")
        .def("grab", [](World& w, BodyId id, double frequency, double stiffness, double damping, double angularStiffness, double angularDamping) {
            GrabSettings g;
            g.frequency = frequency;
            g.stiffness = stiffness;
            g.damping = damping;
            g.angularStiffness = angularStiffness;
            g.angularDamping = angularDamping;
            w.grab(id, g);
        }, py::arg("id"), py::arg("frequency") = 10.0, py::arg("stiffness") = 0.0, py::arg("damping") = -1.0,
             py::arg("angular_stiffness") = 0.0, py::arg("angular_damping") = -1.0,
             "The operator grabs a body: a spring-damper coupling of that frequency, or of the stiffnesses given (N/m, N m/rad; "
             "0: from the frequency) and dampings (N s/m, N m s/rad; negative: critical), as the scene file's grab action.")
        .def("set_grab_target", [](World& w, const Vec3& position, const Eigen::Vector4d& rotation) { w.setGrabTarget(makePose(position, rotation)); },
             py::arg("position"), py::arg("rotation") = Eigen::Vector4d(1, 0, 0, 0), "Moves the pose the operator wants the grabbed body at.")
        .def("release", &World::release, "The operator lets go of the grabbed body.")
        .def("coupling", [](const World& w) {
            py::dict d;
            d["active"] = w.coupling().active;
            d["body"] = w.coupling().body;
            d["force"] = w.coupling().force;
            d["torque"] = w.coupling().torque;
            return d;
        }, "The operator coupling's force and torque on the grabbed body in the last step (the device feels their opposite).")
        .def("add_assembly", [](World& w, BodyId primary, BodyId secondary, const py::kwargs& keys) {
            return w.addAssembly(assemblyRule(w, primary, secondary, keys, w.assemblyCount()));
        }, py::arg("primary"), py::arg("secondary"),
             "Adds a snapping rule between two bodies; returns its index. Keywords as the scene file's [[assembly]] keys, with the "
             "same defaults and checks: name, technique ('zone'; 'collision', 'proximity', 'vector'), final_position, "
             "final_rotation (as in scene files: Euler angles in degrees, about x, then y, then z; not a quaternion), "
             "snap_duration, distance_tolerance, angle_tolerance (degrees), primary_vector / secondary_vector "
             "({'origin': ..., 'end': ...}), vector_tolerance, area ({'shape': 'box' | 'sphere' | 'cylinder', 'position', "
             "'rotation', 'half_extents', 'radius', 'half_height'}).")
        .def("assembled", &World::assembled, py::arg("rule"), "Whether the rule has snapped its primary into place.")
        .def_property_readonly("assembly_count", &World::assemblyCount, "Assembly rules added (indices 0 .. assembly_count - 1).")
        .def("apply_force_at", &World::applyForceAt, py::arg("id"), py::arg("force"), py::arg("point"),
             "A world-frame force at a world point for the next step: the force and its torque (dynamic bodies; others ignore it).")
        .def("apply_face_force", &World::applyFaceForce, py::arg("id"), py::arg("face"), py::arg("force"),
             "A world-frame force for the next step spread over a face's three masses (on a part that does not deform, a third of "
             "it at each of those points of its rigid body).")
        .def("set_kinematic_target", [](World& w, BodyId id, const Vec3& position, const Eigen::Vector4d& rotation) {
            w.setKinematicTarget(id, makePose(position, rotation));
        }, py::arg("id"), py::arg("position"), py::arg("rotation") = Eigen::Vector4d(1, 0, 0, 0),
             "A kinematic body's pose to reach by the end of the next step (its velocity follows; other bodies ignore it).")
        .def("assembly_events", [](const World& w) {
            py::list out;
            for (const AssemblyEvent& e : w.assemblyEvents()) out.append(eventDict(e));
            return out;
        }, "The snaps so far, as dicts (rule, technique, time, from and to poses).")
        .def("write_vtk", [](const World& w, const std::filesystem::path& path, const std::vector<std::string>& names) { writeVtkFrame(path, frameParts(w, names)); },
             py::arg("path"), py::arg("names") = std::vector<std::string>{}, "One VTK PolyData frame (.vtp) with zone_depth, displacement, velocity.")
        .def("write_glb", [](const World& w, const std::filesystem::path& path, const std::vector<std::string>& names) { writeGlbFrame(path, frameParts(w, names)); },
             py::arg("path"), py::arg("names") = std::vector<std::string>{}, "One glTF 2 binary frame (.glb).");

    py::class_<VtkSeries>(m, "VtkSeries", "VTK frames and their .pvd collection (ParaView opens the .pvd as a time series).")
        .def(py::init<std::filesystem::path, std::string>(), py::arg("directory"), py::arg("stem") = "frames")
        .def("write", [](VtkSeries& s, const World& w, const std::vector<std::string>& names) { return s.write(w.time(), frameParts(w, names)); },
             py::arg("world"), py::arg("names") = std::vector<std::string>{}, "Writes the world's frame at its time; returns the .vtp path.")
        .def_property_readonly("collection", &VtkSeries::collection, "Path of the .pvd collection.");

    // --- Scenes ---
    py::class_<Scene>(m, "Scene", "A scene file's world, parts, assembly rules and actions.")
        .def_readonly("source", &Scene::source, "The scene file (for messages).")
        .def_readwrite("duration", &Scene::duration, "Seconds a run lasts (the scene's [world] duration).")
        .def_property_readonly("part_names", [](const Scene& s) {
            std::vector<std::string> names;
            for (const ScenePart& p : s.parts) names.push_back(p.name);
            return names;
        }, "Part names in body-id order.")
        .def_property_readonly("time_step", [](const Scene& s) { return s.world.timeStep; }, "The world's time step (s).")
        .def_property_readonly("warnings", [](const Scene& s) { return messagesOf(s.warnings); }, "The scene's warnings (old spellings, mesh repairs).");
    m.def("load_scene", [](const std::filesystem::path& path, bool strict, std::optional<std::filesystem::path> remeshCache) {
        py::gil_scoped_release release;  // a scene's meshes may be remeshed and their fields built: seconds
        return loadScene(path, sceneReadOptions(strict, std::move(remeshCache)));
    }, py::arg("path"), py::arg("strict") = false, py::arg("remesh_cache") = py::none(),
          "Reads a scene file (TOML), the GIL released meanwhile. Raises InputError naming the file, line and key. "
          "remesh_cache: the directory keeping remeshed parts' surfaces between loads (None: the default, "
          "$FLEXFIT_CACHE_DIR/remesh or ~/.cache/flexfit/remesh; \"\": none).");

    py::class_<SceneRun>(m, "SceneRun", "A scene's world driven by its scripted actions (what `flexfit run` steps).")
        .def(py::init([](const Scene& scene) {
                 py::gil_scoped_release release;  // the world: every part's hierarchies and distance fields
                 return std::make_unique<SceneRun>(scene);
             }),
             py::arg("scene"))
        .def("step", [](SceneRun& r, int steps) {
            py::gil_scoped_release release;
            for (int i = 0; i < steps; ++i) r.step();
        }, py::arg("steps") = 1, "The actions due, then a world step (the GIL is released meanwhile).")
        .def_property_readonly("world", [](SceneRun& r) { return &r.world(); }, py::return_value_policy::reference_internal, "The run's world (a view that keeps the run alive).")
        .def("finished", &SceneRun::finished, "True once every scripted action has run.")
        .def("body", [](const SceneRun& r, const std::string& name) {
            const auto id = r.scene().find(name);
            if (!id) throw InputError(r.scene().source, 0, "no part named '" + name + "'");
            return *id;
        }, py::arg("name"), "The body id of a part by its scene name.");

    m.def("run_scene", [](const std::filesystem::path& path, std::optional<std::filesystem::path> out, std::optional<double> duration, std::optional<double> vtkEvery,
                          std::optional<double> glbEvery, std::optional<std::filesystem::path> remeshCache) {
        std::optional<Scene> loaded;
        {
            py::gil_scoped_release release;
            loaded.emplace(loadScene(path, sceneReadOptions(false, std::move(remeshCache))));
        }
        const Scene& scene = *loaded;
        cli::RunOptions options;
        options.duration = duration;
        options.out = out.value_or(std::filesystem::path());
        options.progress = false;
        options.vtkEvery = vtkEvery;
        options.glbEvery = glbEvery;
        cli::RunSummary s;
        {
            py::gil_scoped_release release;
            s = cli::runScene(scene, options);
        }
        return summaryObject(scene, s);
    }, py::arg("path"), py::arg("out") = py::none(), py::arg("duration") = py::none(), py::arg("vtk_every") = py::none(), py::arg("glb_every") = py::none(),
          py::arg("remesh_cache") = py::none(),
          "Runs a scene file as `flexfit run` does; returns its summary (a dict, as summary.json), and with `out` writes the same files. "
          "remesh_cache as load_scene's.");

    // --- Sweeps ---
    py::class_<Sweep>(m, "Sweep", "A sweep file: a base scene, the parameters to vary, every combination a run.")
        .def_property_readonly("file", [](const Sweep& s) { return s.file; }, "The sweep file.")
        .def_property_readonly("scene", [](const Sweep& s) { return s.scene; }, "The base scene file.")
        .def_property_readonly("parameter_names", [](const Sweep& s) {
            std::vector<std::string> names;
            for (const SweepParameter& p : s.parameters) names.push_back(p.name);
            return names;
        }, "The parameters' names (the table's columns).")
        .def_property_readonly("run_ids", [](const Sweep& s) {
            std::vector<std::string> ids;
            for (const SweepRun& r : s.runs) ids.push_back(r.id);
            return ids;
        }, "Every run's id, in the sweep's order.")
        .def("labels", &Sweep::labels, py::arg("run"), "The run's value label for each parameter.")
        .def_property_readonly("warnings", [](const Sweep& s) { return messagesOf(s.warnings); }, "The runs' scene warnings (mesh repairs, old spellings), each once; empty when loaded with check_runs=False.")
        .def("scene_of", [](const Sweep& s, std::size_t run) { return sweepScene(s, run); }, py::arg("run"), py::call_guard<py::gil_scoped_release>(),
             "The scene of one run (the base with its values; the GIL released while it is built).")
        .def("__len__", [](const Sweep& s) { return s.runs.size(); }, "Number of runs.");
    m.def("load_sweep", [](const std::filesystem::path& path, bool checkRuns, bool strict, std::optional<std::filesystem::path> remeshCache) {
        return loadSweep(path, checkRuns, sceneReadOptions(strict, std::move(remeshCache)));
    }, py::arg("path"), py::arg("check_runs") = true, py::arg("strict") = false, py::arg("remesh_cache") = py::none(),
          py::call_guard<py::gil_scoped_release>(),
          "Reads a sweep file; with check_runs, builds and checks every run's scene first (the GIL released meanwhile). "
          "strict and remesh_cache as load_scene's, for every run's scene.");
    m.def("missing_sweep_runs", &cli::missingSweepRuns, py::arg("sweep"), py::arg("out"), "Indices of the runs without results under `out`.");
    m.def("run_sweep_run", [](const Sweep& s, std::size_t run, const std::filesystem::path& out) {
        py::gil_scoped_release release;
        return cli::runSweepRun(s, run, out);
    }, py::arg("sweep"), py::arg("run"), py::arg("out"), "Runs one run into out/runs/<id>/ (False: it was already done).");
    m.def("write_sweep_table", &cli::writeSweepTable, py::arg("sweep"), py::arg("out"), "Writes out/results.csv from every run's row.");
    m.def("run_sweep_threads", [](const Sweep& s, const std::filesystem::path& out, int jobs) {
        py::gil_scoped_release release;
        return cli::runSweep(s, out, jobs, false);
    }, py::arg("sweep"), py::arg("out"), py::arg("jobs"), "What `flexfit sweep` does: the missing runs on threads, then the table.");
}
