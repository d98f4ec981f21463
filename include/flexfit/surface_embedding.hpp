// Surface embedding: a mesh drawn on another one and carried along by its deformation.
//
// Why: a part may simulate on a remeshed surface (remesh.hpp) while the user's own mesh stays
// what is drawn and exported: their vertices, their faces, their order. Each vertex p of the
// drawn mesh is tied to its closest triangle (a, b, c) of the simulation surface at rest: the
// barycentric weights (wa, wb, wc) of the closest point and the offset d of p along the
// triangle's unit normal n. Its anchor on a simulation shape x is
//     anchor(x) = wa xa + wb xb + wc xc + d n(x),
// and the drawn vertex is p + (anchor(x) - anchor(x_rest)): it moves by its anchor's
// displacement. At rest the two anchors are the same computation on the same numbers, so an
// undeformed part draws exactly its original mesh, bit for bit, however far p lies from the
// simulation surface; deformed, a vertex follows its triangle's translation, stretch and (through
// the normal) rotation.
//
// Known limits: the closest triangle is chosen at rest, so a vertex of a wall thinner than the
// remeshing's Hausdorff distance may tie to the far side's triangle; the offset follows the flat
// triangle's normal, so over a sharply bent simulation triangle the drawn surface shows the
// triangle's facets; evaluating costs O(drawn vertices) (a whole-mesh pass, meant for frames and
// drawing, not for every step).
#pragma once

#include "flexfit/mesh.hpp"

#include <span>
#include <vector>

namespace flexfit {

struct SurfaceEmbedding {
    TriMesh mesh;                   // the drawn mesh at rest, in the simulation mesh's frame
    std::vector<Index> triangle;    // (N) the simulation face each drawn vertex is tied to
    std::vector<Vec3> weights;      // (N) barycentric weights of that face's corners
    std::vector<double> offset;     // (N) signed, along the face's unit normal
    std::vector<Vec3> restAnchor;   // (N) anchor(x_rest)
    std::vector<Index> nearestMass; // (N) the face's corner of largest weight (for per-mass data)
    double maxDistance = 0.0;       // farthest drawn vertex from the simulation surface at rest
    std::size_t simulationVertexCount = 0, simulationFaceCount = 0;  // of the simulation mesh embedded in

    std::size_t vertexCount() const { return mesh.vertices.size(); }
};

// Ties every vertex of `drawn` to the closest face of `simulation` (both validated meshes in one
// frame). Throws InputError (naming `source`) if either mesh has no faces.
SurfaceEmbedding embedSurface(TriMesh drawn, const TriMesh& simulation, const std::string& source);

// The drawn mesh's vertices for the simulation mesh's vertex positions x (faces of the
// simulation mesh, x in any frame in which the rest shape was given): `out` gets N positions.
// InputError unless x and simulationFaces have the simulation mesh's counts (embedSurface's).
void embeddedPositions(const SurfaceEmbedding& embedding, std::span<const Face> simulationFaces,
                       std::span<const Vec3> x, std::vector<Vec3>& out);

}  // namespace flexfit
