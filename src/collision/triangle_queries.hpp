// Exact geometric queries on triangles: the narrow phase's building blocks.
//
// closestPointOnTriangle follows Ericson, Real-Time Collision Detection, 5.1.5: it classifies
// the point against the triangle's Voronoi regions (3 vertices, 3 edges, the face) with dot
// products only, and handles degenerate (zero-area, needle) triangles by falling back to the
// closest point on their edges.
//
// intersectTriangles is a separating-axis test on the 11 axes of two triangles (both normals
// and the 9 edge-edge cross products; in-plane edge normals when they are coplanar). When no
// axis separates them it reports the minimum-overlap axis as the contact normal, the overlap
// as the depth, and the centroid of the intersection points (edges of each through the other)
// as the contact point; for faces of solids, not a push that only slides a face off the
// other's edge or through it (see intersectTriangles).
#pragma once

#include "flexfit/bvh.hpp"
#include "flexfit/core.hpp"

#include <cstdint>
#include <limits>
#include <optional>

namespace flexfit {

struct Triangle {
    Vec3 a, b, c;
};

// The Voronoi region of a triangle that holds a closest point: a corner, an edge (EdgeAB joins
// a and b, EdgeBC b and c, EdgeCA c and a) or the interior of the face.
enum class TriangleFeature : std::uint8_t { CornerA, CornerB, CornerC, EdgeAB, EdgeBC, EdgeCA, Interior };

// Closest point of the (closed) triangle to p; `feature`, when given, receives its region.
Vec3 closestPointOnTriangle(const Vec3& p, const Triangle& t, TriangleFeature* feature = nullptr);

// The closest point to p on a mesh whose faces (by index) a box hierarchy holds: depth-first,
// nearer child first, subtrees pruned by their box's distance. Ties keep the first face found.
struct ClosestFace {
    Index face = 0;
    Vec3 point = Vec3::Zero();
    TriangleFeature feature = TriangleFeature::Interior;
    double squaredDistance = 0.0;
};
ClosestFace closestFace(const Bvh<Aabb>& faceTree, std::span<const Vec3> vertices, std::span<const Face> faces, const Vec3& p);

struct TriangleContact {
    Vec3 point;   // on the intersection
    Vec3 normal;  // unit; moving the first triangle by depth * normal separates them
    double depth = 0.0;
};

// Contact of a sphere (centre, radius) with a triangle: the point is the closest point on the
// triangle, the normal points from it to the centre (the triangle's normal when the centre lies
// on the triangle), depth = radius - distance. nullopt when they do not touch.
std::optional<TriangleContact> sphereTriangleContact(const Vec3& centre, double radius, const Triangle& t);

// Contact of two triangles; nullopt when they do not intersect (touching counts as
// intersecting). Normal: pushing `first` by depth * normal separates it from `second`.
//
// How intersectTriangles reads the two faces (FaceSides::TwoSided: as surfaces).
//
// Solids: both are faces of solids (closed, outward-wound meshes: solidDefect), whose insides
// lie behind them. A push of `first` clearly out along its own normal or into `second` against
// its normal (more than 30 degrees out of the face planes) parts the two triangles only by
// sliding one off the other's edge or through the other, and the solids stay as deep in each
// other. When the smallest push is such a one and the faces meet more than 30 degrees from
// parallel, the smallest push that is not replaces it, if that is short (a tenth of the
// triangles' size: triangle_queries.cpp, solidPush). Equal boxes stacked flush need it: every
// crossing lies on a coincident edge, and the two-sided test reported depth 0 sideways while
// the boxes sank into each other.
// RigidSolids: as Solids, and besides, opposing faces within 30 degrees of parallel (a box face
// tilted on the one below, a peg's side on the hole's wall, a ball pressed on a face) whose
// smallest push goes through the other face get the push back along one face's normal, by the
// depth of one triangle's deepest point behind the other within its prism, put at the middle of
// that depth (opposingFacesPush). Two-sided, such pairs pointed through the other face about as
// often as not, which the contact solver read as separating. For rigid pairs only: a
// deformable part's contact response moves a face's three masses by the contact's depth, and
// with the deepest point's depth a tool pressed into a face pushed its masses 0.1 mm beyond
// the tool's surface (stiff_clip.toml, where the two-sided contacts left them on it).
// Whether there is a contact does not depend on it. Known limits: a push that does separate
// the solids at a convex edge turned by more than 60 degrees leaves one face's cone too, and
// is replaced when a short push is left; overlaps deeper than a tenth of the faces keep the
// two-sided push between faces meeting at a steep angle.
enum class FaceSides : std::uint8_t { TwoSided, Solids, RigidSolids };
std::optional<TriangleContact> intersectTriangles(const Triangle& first, const Triangle& second, FaceSides sides = FaceSides::TwoSided);

// How far apart two triangles are along the best of intersectTriangles' axes (both normals and
// the nine edge-edge cross products, unit): a lower bound on their distance. While no vertex
// of either side's vertices moves by more than the gap in total (along a fixed axis, the gap
// shrinks by at most the two sides' largest moves), they stay apart. 0 when no axis separates
// them. Stops at the first axis whose gap exceeds `enough` (then a lower bound on the gap).
double triangleGap(const Triangle& first, const Triangle& second, double enough = std::numeric_limits<double>::infinity());

}  // namespace flexfit
