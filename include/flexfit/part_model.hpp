// The immutable part model: everything about a part that does not change while it simulates.
//
// Mesh, topology (CSR neighbourhoods), springs with rest lengths, stiffness and damping, and
// masses. Held through std::shared_ptr<const PartModel>, so several parts can share one model
// and no step can modify it. The mutable side is PartState (part_state.hpp).
//
// Springs are the unique mesh edges (Topology order). Arrays are struct-of-arrays: the step
// streams over springA/springB/restLength/stiffness/damping without touching cold data.
#pragma once

#include "flexfit/mesh.hpp"
#include "flexfit/topology.hpp"

#include <algorithm>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

namespace flexfit {

struct SpringBlocks;      // the full step's vector layout of the springs (internal)
struct SurfaceEmbedding;  // a drawn mesh carried by the simulation surface (surface_embedding.hpp)

// Spring constants: stiffness k (kg/s^2) and damping b (kg/s).
struct Material {
    double stiffness = 0.1;
    double damping = 0.01;

    // Thesis Table 4.1.
    static constexpr Material rigid() { return {1.0, 0.1}; }
    static constexpr Material elastic() { return {0.1, 0.01}; }
    static constexpr Material superelastic() { return {0.01, 0.001}; }
};

// "rigid" | "elastic" | "superelastic"; nullopt for anything else.
std::optional<Material> materialPreset(std::string_view name);

// A material as engineers state it, for a part simulated as a shell: its surface mesh is a
// membrane of the given thickness (SI units: the mesh's coordinates are metres).
//
// - Spring stiffness (van Gelder 1998): k_e = E t sum(area of the faces at e) / |e|^2. On a
//   near-equilateral mesh the network's in-plane Young's modulus is then E; its Poisson ratio is
//   the triangle lattice's own 1/3 whatever poissonRatio says (linear springs cannot give another:
//   van Gelder's result). poissonRatio enters the bending rigidity D = E t^3 / (12 (1 - nu^2)).
// - Lumped masses: density x thickness x a third of the area of the faces at each vertex.
// - Damping per spring from a damping ratio: b_e = 2 zeta sqrt(k_e mu_e), mu_e the reduced mass
//   of the spring's two masses (critically damped pair at zeta = 1).
// - Bending springs (optional): one across each interior edge, joining the two vertices opposite
//   it, k_b = 3 D |e|^2 / ((A1 + A2) d^2) with d their rest distance. Its hinge stiffness is the
//   discrete-shell one (Grinspun et al. 2003, 3 D |e|^2 / (A1 + A2)) times (h1 h2 sin(theta) / d^2)^2:
//   a quarter of it at a right-angle crease, and none on a flat region (a flat sheet gets no
//   linear bending stiffness from springs: a known limit). They keep creases and corners,
//   so a thin-walled section keeps its shape; in plane they add O((t / edge)^2) stiffness.
struct ShellMaterial {
    double youngsModulus = 0.0;  // E, Pa (> 0)
    double poissonRatio = 0.35;  // nu, in [0, 0.5)
    double thickness = 0.0;      // t, m (> 0)
    double density = 0.0;        // kg/m^3 (> 0)
    double dampingRatio = 0.1;   // zeta, >= 0
    bool bendingSprings = false;
};

// How a model numbers its masses.
enum class VertexOrder {
    AsGiven,   // mass i is the mesh's vertex i
    // The vertices renumbered for memory locality (src/model/vertex_order.hpp) when that puts more
    // springs in spring blocks than the given order does (the full step's fast layout): for
    // meshes from files, whose order is the exporter's. A mesh already in rows keeps its order.
    Locality,
};

struct PartModelSettings {
    Material material = Material::elastic();  // for every spring unless springMaterials is set
    double vertexMass = 1.0;                  // kg, for every vertex unless vertexMasses is set
    std::vector<double> vertexMasses;         // (V) optional per-vertex masses
    std::vector<Material> springMaterials;    // (E) optional per-spring constants, Topology order
    // Optional: a physical material; when set, it gives every spring's constants and every
    // vertex's mass in place of material and vertexMass (vertexMasses and springMaterials must
    // then be empty).
    std::optional<ShellMaterial> shell;
    // Optional: the mesh drawn and exported instead of the simulated one (the user's own, when the
    // part simulates on a remeshed surface), embedded in it (surface_embedding.hpp). Empty: the
    // simulation mesh is drawn.
    TriMesh drawnMesh;
    // The masses' order; per-vertex and per-spring arrays above are given in the mesh's own order
    // either way.
    VertexOrder vertexOrder = VertexOrder::AsGiven;
    // Optional: the vertices of the file the mesh was read from, when the read welded or removed
    // some (MeshReadResult::fileVertices). The model then takes and gives the file's vertex
    // indices (PartModel::massOf, vertexOf, inVertexOrder, drawnMesh()): a user's vertex 574 is
    // their file's vertex 574. Per-vertex arrays above stay in the mesh's order.
    FileVertices fileVertices = {};
};

// A model's file numbering (PartModelSettings::fileVertices).
struct FileNumbering {
    FileVertices vertices;  // file vertex -> given mesh vertex (kNoVertex: removed)
    VertexMap firstOf;      // (given V) given mesh vertex -> the first file vertex that became it
    TriMesh mesh;           // the simulation surface as the file numbers it (inFileOrder)
};

struct PartModel {
    std::string name;
    TriMesh mesh;  // rest shape in the part frame
    Topology topology;

    // Masses (V).
    Vec3Array restPositions;           // (V) part frame; same as mesh.vertices
    DoubleArray mass;                  // (V) kg, > 0
    DoubleArray inverseMass;           // (V) 1/kg

    // Springs (E): one per unique edge, and with a shell material's bending springs one across
    // each interior edge; sorted by (springA, springB), so a bending spring's index is not an edge's.
    std::vector<Index> springA;        // (E) first mass (springA < springB; sorted by springA)
    std::vector<Index> springB;        // (E) second mass
    std::vector<double> restLength;    // (E) initial Euclidean distance
    std::vector<double> stiffness;     // (E) k
    std::vector<double> damping;       // (E) b
    // (V+1) springs whose first mass is a: [springAdr[a], springAdr[a+1]).
    std::vector<Index> springAdr;
    // mass -> every spring at it (either end): massSprings[massSpringAdr[v] .. adr[v+1]).
    std::vector<Index> massSpringAdr;  // (V+1)
    std::vector<Index> massSprings;    // (2E)
    std::size_t bendingSpringCount = 0;
    // A mass farther than this from mass 0 along an axis has diverged, even if finite: 1e6 times
    // the rest shape's bounding-box diagonal, as the divergence checks test it, within a factor 2
    // (a power of two). Explicit Euler far above its stability bound can stay finite for a
    // while, at 1e39 units. Relative to mass 0, not to the part's origin: a fully deformable part
    // in free fall moves its masses, not its frame, and may fall any distance together.
    // buildPartModel sets it; infinite (finite positions only) otherwise.
    double positionBound = std::numeric_limits<double>::infinity();
    std::span<const Index> springsAt(Index v) const {
        return {massSprings.data() + massSpringAdr[v], massSprings.data() + massSpringAdr[v + 1]};
    }
    // The springs again, grouped for the vector full step (an internal layout); empty when the
    // mesh's vertex order gives too few blocks. It copies the spring constants: build models with
    // buildPartModel, and do not edit a model's springs afterwards.
    std::shared_ptr<const SpringBlocks> springBlocks;
    // Whether some springs fall in spring blocks (the others run by the listed-spring kernel).
    bool hasSpringBlocks() const;
    // The drawn mesh tied to the simulation surface; null when the simulation mesh is drawn.
    std::shared_ptr<const SurfaceEmbedding> drawn;
    // What the part looks like at rest: the drawn mesh, else the simulation mesh as the user
    // numbers it (userMesh()).
    const TriMesh& drawnMesh() const;

    // The masses' order (VertexOrder::Locality). When the build renumbered the given mesh's
    // vertices, mass massOfVertex[v] is its vertex v and vertexOfMass[m] is mass m's vertex;
    // `mesh`, restPositions, topology and every per-mass and per-spring array are in mass order
    // (faces keep their order and indices), and givenMesh is the mesh as given, which userMesh()
    // and drawnMesh() return when there is neither a file numbering nor a drawn mesh: frames and
    // the viewer show the user's vertices in their order. Empty (and givenMesh null): mass i is
    // vertex i.
    std::vector<Index> massOfVertex;  // (V or 0)
    std::vector<Index> vertexOfMass;  // (V or 0)
    std::shared_ptr<const TriMesh> givenMesh;
    bool renumbered() const { return !massOfVertex.empty(); }

    // The file's numbering, when the model was built with the file's vertices (a read that
    // welded or removed some); null otherwise. A removed vertex (no face used it) has no mass: it
    // is carried rigidly with the part at its file position, with no displacement or velocity
    // of its own.
    std::shared_ptr<const FileNumbering> file;

    // The user's vertices: the file's when `file` is set, else the given mesh's.
    std::size_t vertexCount() const { return file ? file->vertices.count() : massCount(); }
    // Whether mass i is the user's vertex i (no renumbering, no file numbering).
    bool massesAreVertices() const { return !renumbered() && !file; }
    // The mass of the user's vertex. Without a file numbering an index out of range passes
    // through unchanged, for the call it goes to to refuse; with one, an index past the file's
    // vertices or a removed file vertex throws InputError naming the part.
    Index massOf(Index vertex) const;
    // The user's vertex of mass m (with a file numbering, the first file vertex that became it).
    Index vertexOf(Index m) const;
    // The mass of the given mesh's vertex (no file numbering).
    Index massOfGivenVertex(Index v) const { return renumbered() ? massOfVertex[v] : v; }
    // The simulation surface as the user numbers it: the file's vertices and the faces over
    // them, else the given mesh.
    const TriMesh& userMesh() const { return file ? file->mesh : givenMesh ? *givenMesh : mesh; }

    std::size_t massCount() const { return mass.size(); }
    std::size_t springCount() const { return springA.size(); }
    std::size_t faceCount() const { return mesh.faces.size(); }
};

// Builds a model from a mesh. The mesh passes validateMesh here too (source: its name, else
// "part model mesh"), as a mesh built in code reaches this without a reader: whatever a reader
// refuses (a NaN, a coordinate beyond kMaxMeshCoordinate, an index out of range, a degenerate
// or duplicate face, no faces, a mesh below kMinMeshSize) is refused, not simulated. A mesh
// from a reader is checked twice (the duplicate-face sort: O(F log F)). Throws InputError (source
// "part model settings") for
// non-positive or non-finite masses and constants, or per-vertex / per-spring arrays of the
// wrong size, a shell material out of range (or set beside per-vertex masses or per-spring
// materials), or one that leaves a vertex without mass (in no face of positive area); a drawn
// mesh must pass validateMesh.
std::shared_ptr<const PartModel> buildPartModel(TriMesh mesh, const PartModelSettings& settings = {});

// Per-mass values in the given mesh's vertex order (a copy when the model is not renumbered).
template <class T>
void inGivenVertexOrder(const PartModel& model, std::span<const T> perMass, std::vector<T>& out) {
    out.resize(perMass.size());
    if (!model.renumbered()) {
        std::copy(perMass.begin(), perMass.end(), out.begin());
        return;
    }
    for (std::size_t v = 0; v < out.size(); ++v) out[v] = perMass[model.massOfVertex[v]];
}

// Per-mass values in the user's vertex order (PartModel::vertexCount() of them): a file
// vertex welded into another repeats its value; a removed one gets removed(vertex), by default
// zero (no displacement, no velocity; Eigen's T{} would be uninitialised).
template <class T, class Removed>
void inVertexOrder(const PartModel& model, std::span<const T> perMass, std::vector<T>& out, Removed removed) {
    if (!model.file) return inGivenVertexOrder(model, perMass, out);
    const VertexMap& given = model.file->vertices.meshVertex;
    out.resize(given.size());
    for (std::size_t u = 0; u < out.size(); ++u)
        out[u] = given[u] == kNoVertex ? removed(Index(u)) : perMass[model.massOfGivenVertex(given[u])];
}
template <class T>
void inVertexOrder(const PartModel& model, std::span<const T> perMass, std::vector<T>& out) {
    inVertexOrder(model, perMass, out, [](Index) {
        if constexpr (requires { T::Zero(); })
            return T(T::Zero());
        else
            return T{};
    });
}

}  // namespace flexfit
