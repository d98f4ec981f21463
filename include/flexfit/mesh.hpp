// Triangle meshes: the input of every part, with validation and vertex welding.
//
// A TriMesh is plain data. validateMesh() is the single gate every reader and generator
// passes through: it rejects what would give a broken mass-spring model (empty mesh, index out
// of range, NaN/Inf coordinates, a scale outside 1e-20..1e20 units, degenerate or duplicate faces) and counts what is merely
// unusual (open boundaries, non-manifold edges) as warnings.
#pragma once

#include "flexfit/core.hpp"

#include <limits>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace flexfit {

struct TriMesh {
    std::string name;
    std::vector<Vec3> vertices;  // (V)
    std::vector<Face> faces;     // (F) 0-based vertex indices, counter-clockwise seen from outside
};

// What validation found that is legal but worth knowing.
struct MeshDiagnostics {
    std::size_t edgeCount = 0;          // unique undirected edges (= springs)
    std::size_t boundaryEdges = 0;      // edges used by exactly one face (open surface)
    std::size_t nonManifoldEdges = 0;   // edges used by three or more faces
    std::size_t unreferencedVertices = 0;
    std::vector<std::string> warnings;  // human-readable, one per class found

    bool closed() const { return boundaryEdges == 0 && nonManifoldEdges == 0; }
};

// Where each face and vertex came from in a text file, for error messages (0 = unknown).
struct MeshSourceLines {
    std::vector<std::size_t> vertexLine;  // (V) or empty
    std::vector<std::size_t> faceLine;    // (F) or empty
};

// The scales Flexfit computes with: a coordinate beyond kMaxMeshCoordinate in magnitude, or a
// mesh whose bounding-box diagonal is below kMinMeshSize, is refused (validateMesh). Collision
// and the spring model multiply up to five coordinates together; within these bounds no such
// product overflows or underflows to zero (1e20^5 = 1e100), and every unit in use (nm to km)
// fits many times over.
inline constexpr double kMaxMeshCoordinate = 1e20;
inline constexpr double kMinMeshSize = 1e-20;

// Throws InputError naming `source` (and the line, when `lines` knows it) for the first
// problem found. Faces are degenerate when two indices repeat or their area is below
// 1e-12 x (bounding-box diagonal)^2; duplicates are faces over the same three vertices.
MeshDiagnostics validateMesh(const TriMesh& mesh, const std::string& source,
                             const MeshSourceLines& lines = {});

// A vertex a change of the mesh removed (VertexMap).
inline constexpr Index kNoVertex = std::numeric_limits<Index>::max();

// Where each vertex of a mesh went when vertices were merged or removed: vertex i became
// vertex newIndex[i] of the changed mesh, or was removed (kNoVertex).
using VertexMap = std::vector<Index>;
// `map` followed by `then` (each entry of `map` sent on through `then`; removed stays removed).
void composeVertexMap(VertexMap& map, const VertexMap& then);

// Merges vertices closer than `tolerance` (0: bit-identical positions only), keeping the first
// of each cluster in input order, so the result is deterministic. Faces that collapse are
// removed; the count is returned. Used for formats that split vertices per face (STL).
// `moved`, when given, gets where each vertex went.
std::size_t weldVertices(TriMesh& mesh, double tolerance, VertexMap* moved = nullptr);
// The vertex each vertex would be welded into (itself when none): always an earlier one.
std::vector<Index> weldTargets(std::span<const Vec3> vertices, double tolerance);

// A file's own vertices, when reading it merged or removed some (the format's welding, an
// asked-for weld, the repair: mesh_io.hpp): file vertex i became mesh vertex meshVertex[i], or
// was removed (kNoVertex: no face used it). Empty when the mesh's vertices are the file's, one
// for one. A part built with it (PartModelSettings::fileVertices) takes and gives the file's
// vertex indices.
struct FileVertices {
    VertexMap meshVertex;         // (file V)
    std::vector<Vec3> positions;  // (file V) as read
    bool empty() const { return meshVertex.empty(); }
    std::size_t count() const { return meshVertex.size(); }
};

// The file's vertices (all of them: each at the position of the mesh vertex it became, a removed
// one at its file position) with `mesh`'s faces, each corner named by the first file vertex
// that became it: the mesh as the user's file numbers it.
TriMesh inFileOrder(const TriMesh& mesh, const FileVertices& file);
// For each mesh vertex, the first file vertex that became it (kNoVertex: none did).
VertexMap firstFileVertices(const FileVertices& file, std::size_t meshVertexCount);
// The first face corner naming a vertex beyond `vertexCount`, as (face, index), or nullopt.
std::optional<std::pair<std::size_t, Index>> firstIndexBeyond(std::span<const Face> faces, std::size_t vertexCount);
// InputError unless `file` fits a mesh of that many vertices: a position for each file vertex,
// each finite, each going to a vertex of the mesh or removed. inFileOrder and
// firstFileVertices check it.
void checkFileVertices(const FileVertices& file, std::size_t meshVertexCount);

// Axis-aligned bounds of the vertices.
Eigen::AlignedBox3d boundingBox(const TriMesh& mesh);

// The area of face f over the positions x (a mesh's vertices, or a part's masses).
inline double faceArea(const std::vector<Vec3>& x, const Face& f) {
    return 0.5 * (x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]).norm();
}

}  // namespace flexfit
