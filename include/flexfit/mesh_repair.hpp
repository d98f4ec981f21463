// Repairing meshes as files deliver them: CAD exports and scans carry zero-area and duplicate
// faces, cracks where an exporter wrote one position twice, vertices no face uses, and faces
// wound against their neighbours. A user cannot fix these by hand in a 50,000-face file, and
// each one breaks a mass-spring model (a zero-area face has no normal, a crack splits the
// spring network, a flipped face points its normal inside).
//
// repairMesh() repairs them, in this order, and counts each kind:
//  1. near-duplicate vertices welded: closer than the weld tolerance (by default
//     nearDuplicateTolerance(), 1e-6 of the bounding-box diagonal: an edge that short already
//     makes a face of zero area by validateMesh's test, so nothing the mesh resolves is merged);
//     the first vertex of a cluster, in file order, stands for it;
//  2. degenerate faces dropped: a repeated vertex (also one left by welding) or zero area (the
//     test of validateMesh);
//  3. duplicate faces dropped: the same three vertices as an earlier face, in any order;
//  4. windings made consistent: across every edge two faces share, one uses it in each
//     direction. Per connected piece (through such edges), the faces fewer in number are
//     flipped (ties: those wound against the piece's first face); a piece that no flipping can
//     make consistent (non-orientable, a Moebius strip) is left as it is and counted;
//  5. unreferenced vertices removed (also those only dropped faces used).
// Vertices and faces keep their file order otherwise. The result passes validateMesh().
// Corrupt input is not repaired: an empty mesh, a NaN or infinite coordinate or an index out
// of range throws InputError naming the source and line, as validateMesh does.
//
// requireNoDefects() is the strict reading: it throws InputError for the first defect
// repairMesh would repair (validateMesh's errors first, then near-duplicate vertices,
// unreferenced vertices, inconsistent windings), naming the line when `lines` knows it.
//
// Known limits: welding is by distance alone (two sheets closer than the tolerance weld);
// orientation is made consistent, not outward (a closed piece wound inside out stays so, and
// the signed distance field refuses it); faces that cross each other are not detected.
#pragma once

#include "flexfit/mesh.hpp"

#include <string>
#include <vector>

namespace flexfit {

// Vertices closer than this share one position: 1e-6 of the bounding-box diagonal.
constexpr double kNearDuplicateShare = 1e-6;
double nearDuplicateTolerance(const TriMesh& mesh);

// What repairMesh() changed, by kind.
struct MeshRepairs {
    double weldTolerance = 0.0;               // the tolerance used
    std::size_t weldedVertices = 0;           // merged into an earlier vertex
    std::size_t degenerateFaces = 0;          // repeated vertex or zero area: dropped
    std::size_t duplicateFaces = 0;           // same vertices as an earlier face: dropped
    std::size_t flippedFaces = 0;             // turned to agree with their neighbours
    std::size_t nonOrientablePieces = 0;      // left as they are
    std::size_t unreferencedVertices = 0;     // used by no face: removed
    // Where each input vertex went (welded into an earlier one, removed, or renumbered past the
    // removed ones); empty when no vertex was welded or removed.
    VertexMap vertexMap;

    bool any() const;
    // One line per kind found, with its count ("2 zero-area or repeated-vertex faces dropped").
    std::vector<std::string> warnings() const;
};

// `weldTolerance` < 0: nearDuplicateTolerance(mesh).
MeshRepairs repairMesh(TriMesh& mesh, double weldTolerance, const std::string& source, const MeshSourceLines& lines = {});
void requireNoDefects(const TriMesh& mesh, double weldTolerance, const std::string& source, const MeshSourceLines& lines = {});

}  // namespace flexfit
