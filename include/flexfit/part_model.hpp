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

#include <memory>
#include <optional>
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

struct PartModelSettings {
    Material material = Material::elastic();  // for every spring unless springMaterials is set
    double vertexMass = 1.0;                  // kg, for every vertex unless vertexMasses is set
    std::vector<double> vertexMasses;         // (V) optional per-vertex masses
    std::vector<Material> springMaterials;    // (E) optional per-spring constants, Topology order
    // Optional: the mesh drawn and exported instead of the simulated one (the user's own, when the
    // part simulates on a remeshed surface), embedded in it (surface_embedding.hpp). Empty: the
    // simulation mesh is drawn.
    TriMesh drawnMesh;
};

struct PartModel {
    std::string name;
    TriMesh mesh;  // rest shape in the part frame
    Topology topology;

    // Masses (V).
    std::vector<Vec3> restPositions;   // (V) part frame; same as mesh.vertices
    std::vector<double> mass;          // (V) kg, > 0
    std::vector<double> inverseMass;   // (V) 1/kg

    // Springs (E): one per unique edge.
    std::vector<Index> springA;        // (E) first mass (springA < springB; sorted by springA)
    std::vector<Index> springB;        // (E) second mass
    std::vector<double> restLength;    // (E) initial Euclidean distance
    std::vector<double> stiffness;     // (E) k
    std::vector<double> damping;       // (E) b
    // (V+1) springs whose first mass is a: [springAdr[a], springAdr[a+1]).
    std::vector<Index> springAdr;
    // The springs again, grouped for the vector full step (an internal layout); empty when the
    // mesh's vertex order gives too few blocks. It copies the spring constants: build models with
    // buildPartModel, and do not edit a model's springs afterwards.
    std::shared_ptr<const SpringBlocks> springBlocks;
    // Whether some springs fall in spring blocks (the others run by the listed-spring kernel).
    bool hasSpringBlocks() const;
    // The drawn mesh tied to the simulation surface; null when the simulation mesh is drawn.
    std::shared_ptr<const SurfaceEmbedding> drawn;
    // What the part looks like at rest: the drawn mesh, else the simulation mesh.
    const TriMesh& drawnMesh() const;

    std::size_t massCount() const { return mass.size(); }
    std::size_t springCount() const { return springA.size(); }
    std::size_t faceCount() const { return mesh.faces.size(); }
};

// Builds a model from a validated mesh. Throws InputError (source "part model settings") for
// non-positive or non-finite masses and constants, or per-vertex / per-spring arrays of the
// wrong size; a drawn mesh must pass validateMesh.
std::shared_ptr<const PartModel> buildPartModel(TriMesh mesh, const PartModelSettings& settings = {});

}  // namespace flexfit
