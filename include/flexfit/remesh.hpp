// Simulation remeshing: a surface whose triangles suit a mass-spring model, made from a mesh as
// a CAD exporter or a scanner wrote it.
//
// Why: a mass-spring part's springs are its mesh's edges. CAD exports carry long, thin
// triangles (slivers): a spring network over them is stiff in one direction and loose in the
// other, a graph-distance zone spans the part along one sliver, and the stable time step is set
// by the shortest edge. The thesis names "any polygon mesh, whatever the size of its triangles"
// as future work.
//
// How: CGAL's Polygon Mesh Processing (`libcgal-dev`), the maintained reference for it:
// `isotropic_remeshing` (Botsch and Kobbelt 2004: split edges longer than 4/3 L, collapse
// those shorter than 4/5 L, flip towards valence 6, tangential relaxation, projection back to
// the input surface), with the sharp edges (`detect_sharp_edges`, dihedral angle above
// `featureAngle`) and the borders held as constrained polylines: they are split and collapsed
// but stay where they were, so creases, corners and the rims of open parts keep their shape.
// The quality of both meshes is measured: the smallest angle, the share of triangles with an
// angle below 20 degrees, the edge lengths against the target, and the symmetric Hausdorff
// distance between them, as a share of the input's bounding-box diagonal: the farthest of
// samples a quarter of the target edge apart over each mesh (its vertices, points along its
// edges, rows across each face parallel to its longest edge) from the other mesh (CGAL's AABB
// tree, on every core; deterministic). Sampled, it can fall short of the true distance by
// about that spacing. The rows make about area / spacing^2 samples on any face: CGAL's grid
// sampling lays its grid along two edges of a face, (length / spacing)^2 / 2 points on a
// needle whatever its area (5.9 million on regr01's input at 1 % of its size, 8 times its
// area's share; the two samplings took 26 of its 31 s). (CGAL's bounded-error Hausdorff distance
// certifies its bound but took 7 s on a 2,000-face box of slivers, 24 s from regr01's input.)
//
// Thin features: two sharp polylines closer than half the target edge (a narrow chamfer, the
// rim of a plate thinner than the edge) cannot be meshed between without slivers. Rounding
// them: where a sliver (an angle below 20 degrees) has all three vertices on sharp polylines
// and is lower than half the target edge, the sharp edges at its vertices stop being kept and
// the surface is remeshed again, up to three rounds (counted in releasedEdges). That moves the
// surface: on regr01 (a CAD part) at 0.5 % of its size slivers go from 2.0 % to 0.2 % and the
// Hausdorff distance from 0.23 % to 0.44 % of the diagonal; on the spider (legs thinner than
// the edge, every edge of them sharp) from 0.2 % to 0.0 % and from 0.22 % to 1.2 %: its legs
// shrink. So `ThinFeatures::Auto` (the default) tries it only when 1 % or more of the
// triangles are slivers, and keeps the rounded surface only when it has fewer slivers, its
// Hausdorff distance is within the target edge (or no more than the other's) and it is closed
// if the other is (faces of zero area are dropped, which can open it); Keep and Round decide
// it outright.
//
// Each remeshing iteration is CGAL's split, collapse and flip followed by its tangential
// relaxation and a projection onto the input faces of the vertex's own patch (the faces
// between sharp edges), called one by one: CGAL 5.5.1's relaxation inside isotropic_remeshing
// reads past a property array for a vertex whose faces are all degenerate (a segfault seen on
// regr01 remeshed a second time); the same relaxation given a constraint map that answers an
// invalid edge is safe.
//
// Where sharp polylines meet, the remeshing can leave needles and caps: CGAL's
// remove_almost_degenerate_faces collapses or flips them (kept edges kept), and a face still of
// zero area by validateMesh's test (three nearly collinear vertices of one polyline) is dropped
// and counted (droppedFaces): measured, 2 of 4,777 faces of Wuson remeshed at 2 % of its size.
//
// Seams: an input with non-manifold edges or vertices is split into sheets by CGAL's
// polygon-soup orientation, a copy of the shared vertices on each. Those edges are cut at their
// midpoints to at most 4/3 of the target edge (the same points on every sheet), kept, and their
// vertices held in place, so the copies weld back and the junction stays joined (remeshed apart
// they drifted and opened cracks: regr01 at 1 % of its size had 142 boundary edges away from
// any border or junction of the input, and has none now).
//
// Known limits: the input must be a manifold surface (edges shared by at most two faces,
// consistently wound: repairMesh() makes it so where it can; CGAL's polygon-soup orientation
// splits the rest); features finer than the target edge are lost (the Hausdorff distance
// reports it); a part thinner than the target edge can close up.
#pragma once

#include "flexfit/mesh.hpp"
#include "flexfit/names.hpp"

namespace flexfit {

// Sharp edges closer than half the target edge (see above): kept (slivers between them stay),
// rounded, or rounded where that leaves the surface within the target edge of the input.
enum class ThinFeatures { Auto, Keep, Round };
// Its names (names.hpp): the scene's `thin_features`, `--thin-features`, Python's thin_features=.
inline constexpr EnumName<ThinFeatures> kThinFeaturesNames[] = {
    {ThinFeatures::Auto, "auto", "rounded where that helps"},
    {ThinFeatures::Keep, "keep", "kept"},
    {ThinFeatures::Round, "round", "rounded"},
};
template <> inline constexpr std::span<const EnumName<ThinFeatures>> kEnumNames<ThinFeatures> = kThinFeaturesNames;

// A target edge beyond this share of the bounding-box diagonal is coarse: legal, but rarely meant
// (flexfit remesh warns of it), and the Hausdorff distance is then sampled at this share's scale.
inline constexpr double kCoarseRemeshEdgeShare = 0.1;

struct RemeshOptions {
    double targetEdge = 0.0;     // > 0, in the mesh's units
    int iterations = 5;          // split / collapse / flip / relax rounds
    double featureAngle = 40.0;  // degrees: edges with a dihedral angle above it are kept sharp
    ThinFeatures thinFeatures = ThinFeatures::Auto;
};

// The quality of a triangle mesh, as a simulation cares about it.
struct MeshQuality {
    std::size_t faces = 0;
    double minAngle = 0.0;         // degrees, over every triangle
    double slivers = 0.0;          // share of triangles with an angle below 20 degrees
    double minEdge = 0.0, meanEdge = 0.0, maxEdge = 0.0;
    double edgeSpread = 0.0;       // standard deviation of the edge lengths over their mean
};
MeshQuality measureQuality(const TriMesh& mesh);

struct RemeshResult {
    TriMesh mesh;
    MeshQuality before, after;
    std::size_t featureEdges = 0;  // input edges kept sharp (feature or border)
    std::size_t droppedFaces = 0;  // output faces still degenerate after CGAL's cap and needle removal
    std::size_t seamVertices = 0;  // vertices held at the input's non-manifold junctions (copies on each sheet counted)
    std::size_t releasedEdges = 0; // sharp edge pieces no longer kept on the rounded surface, when one was made
    double roundedHausdorff = 0.0; // the rounded surface's Hausdorff distance to the input, when one was made
    bool rounded = false;          // the output is the rounded surface
    double hausdorff = 0.0;        // symmetric Hausdorff distance between input and output
    double diagonal = 0.0;         // the input's bounding-box diagonal
    double hausdorffShare() const { return diagonal > 0.0 ? hausdorff / diagonal : 0.0; }
};

// Throws InputError (naming `source`) for a target edge that is not finite and > 0, an edge
// shorter than 1e-4 of the bounding-box diagonal (more than ~10^8 triangles), or a mesh CGAL
// cannot make a manifold surface of. The output passes validateMesh().
RemeshResult remeshForSimulation(const TriMesh& mesh, const RemeshOptions& options, const std::string& source);

}  // namespace flexfit
