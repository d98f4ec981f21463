// Collision detection between parts (SPEC 6, thesis 4.3): face hierarchies, the narrow phase
// and contacts.
//
// PartCollider keeps one part's face hierarchy in the part's own frame: a rigid motion never
// touches it (queries carry the relative pose), and a deformation refits only the leaves of
// the faces around masses that moved and their ancestors. Leaf volumes: the face sphere
// (barycentre, radius to the farthest vertex, thesis 4.3) or the face's box.
//
// queryPair() traverses two hierarchies together (descending the larger volume first) and
// tests each overlapping leaf pair exactly:
//   SphereTriangle   (the thesis's test) the face sphere of part A against the triangle of
//                    part B, closest point on the triangle (Ericson 5.1.5);
//   TriangleTriangle the two triangles (separating axes; point, normal, depth), which does not
//                    report sphere-sized false contacts on large faces.
// A contact's normal is a world unit vector: moving part A by depth * normal (or part B by
// the opposite) separates the pair.
#pragma once

#include "flexfit/names.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <span>

#include "flexfit/bvh.hpp"
#include "flexfit/part.hpp"

#include <variant>

namespace flexfit {

enum class ExactTest { SphereTriangle, TriangleTriangle };
// Its names (names.hpp).
inline constexpr EnumName<ExactTest> kExactTestNames[] = {
    {ExactTest::SphereTriangle, "sphere", "face sphere against triangle"},
    {ExactTest::TriangleTriangle, "triangle", "triangle against triangle"},
};
template <> inline constexpr std::span<const EnumName<ExactTest>> kEnumNames<ExactTest> = kExactTestNames;

inline constexpr Index kNoMass = std::numeric_limits<Index>::max();

struct Contact {
    std::uint32_t partA = 0, partB = 0;
    Index faceA = 0, faceB = 0;
    Vec3 point = Vec3::Zero();   // world
    Vec3 normal = Vec3::UnitY(); // world, unit: pushes A out of B
    double depth = 0.0;
    // Point-shell contacts: the one mass of B inside A (faceB is a face around it; faceA is not
    // looked up and stays 0). kNoMass for face-face contacts.
    Index massB = kNoMass;
};

// The masses a contact presses on one side: the face's three, or `mass` alone when it is not
// kNoMass (a point-shell contact's massB). The span refers to `mass`, which must outlive it.
inline std::span<const Index> pressedMasses(const Face& face, const Index& mass) {
    return mass == kNoMass ? std::span<const Index>(face) : std::span<const Index>(&mass, 1);
}

struct QueryStats {
    std::size_t volumeTests = 0;     // bounding-volume overlap tests (nodes visited in pairs)
    std::size_t candidatePairs = 0;  // leaf pairs whose volumes overlap
    std::size_t exactTests = 0;
    std::size_t contacts = 0;
    QueryStats& operator+=(const QueryStats& o);
};

class PartCollider {
public:
    // `test` decides what the leaves bound: sphere leaves are face spheres either way; box
    // leaves bound the triangle for TriangleTriangle and the face sphere for SphereTriangle
    // (whose exact test uses the sphere, so a box of the triangle could cull true contacts).
    PartCollider(const Part& part, BoundingVolumeKind kind, ExactTest test = ExactTest::TriangleTriangle);

    BoundingVolumeKind kind() const { return kind_; }
    ExactTest exactTest() const { return test_; }
    // Whether the part's rest mesh bounds a solid (solidDefect: closed, consistently and outward
    // wound). Two such parts' triangle contacts push each face only out of the other's solid
    // (triangle_queries.hpp, FaceSides); an open or inside-out mesh is met two-sided.
    bool boundsSolid() const { return solid_; }
    // Rebuilds the hierarchy from the part's current (part-frame) positions.
    void rebuild(const Part& part);
    // Refits the faces around `changedMasses` from the part's positions, and their ancestors
    // (O(changed x valence x depth)). CollisionWorld refits in its queries, only the
    // hierarchies a face query needs, so a part met only by point-shell queries never pays.
    void refit(const Part& part, std::span<const Index> changedMasses);
    // The bounding sphere's growth: the largest displacement of a moving mass from rest
    // (O(moving)).
    void updateDisplacementBound(const Part& part);
    // Masses at their rest positions in a hierarchy of points, for point-shell queries: the
    // masses at rest never move, so this tree never needs a refit. Empty until built.
    void buildRestPointTree(const Part& part);
    const Bvh<Aabb>& restPointTree() const { return restPoints_; }

    // The part's bounding sphere in its own frame: the thesis's sphere of the rest shape
    // (midpoint of the masses' box, radius to the farthest mass), grown by the largest
    // displacement of a mass from rest. world: transformed by the pose.
    Sphere localSphere() const { return {restSphere_.centre, restSphere_.radius + maxDisplacement_}; }
    Sphere worldSphere(const Part& part) const;

    const Bvh<Sphere>* spheres() const { return std::get_if<Bvh<Sphere>>(&bvh_); }
    const Bvh<Aabb>* boxes() const { return std::get_if<Bvh<Aabb>>(&bvh_); }
    std::size_t refitNodeCount() const;

    // Planes of a face of the rest shape, in the part frame: [0] its own (unit normal n,
    // offset n.a), [1..3] through each edge, perpendicular to it, normals pointing out. The
    // narrow phase's cheap rejection for faces whose masses are at rest: a triangle entirely
    // beyond one of them cannot touch the face.
    const std::array<Eigen::Vector4d, 4>& restPlanes(Index face) const { return restPlanes_[face]; }

    // How far the part's vertices may have moved (part frame) since the hierarchy was built:
    // each refit adds the largest move of a changed mass since the refit before.
    // generation() changes when rebuild() starts afresh.
    double vertexDrift() const { return vertexDrift_; }
    std::uint64_t generation() const { return generation_; }
    // How far a leaf can grow while the vertices move by `vertexMove` (box leaves: along each
    // axis of the part frame; sphere leaves: in radius): a triangle's box by at most that, a
    // face sphere (or its box) by three times it.
    double leafGrowth(double vertexMove) const { return leafDriftPerMove_ * vertexMove; }
    // Mean size of the leaf volumes (box diagonal, sphere diameter) when built: the scale of
    // the coherent query's margins.
    double leafScale() const { return leafScale_; }

private:
    std::vector<std::array<Eigen::Vector4d, 4>> restPlanes_;  // (F)
    BoundingVolumeKind kind_;
    ExactTest test_;
    bool solid_ = false;
    std::variant<Bvh<Sphere>, Bvh<Aabb>> bvh_;
    Sphere restSphere_;
    double maxDisplacement_ = 0.0;
    double leafDriftPerMove_ = 1.0;
    std::uint64_t generation_ = 0;
    double vertexDrift_ = 0.0;
    std::vector<Vec3> seenPositions_;  // (V) positions at the last refit that changed them
    double leafScale_ = 0.0;
    IndexSet changedFaces_;  // (F) scratch of refit()
    Bvh<Aabb> restPoints_;
};

// Leaf volumes of a face from part-frame positions.
Sphere faceSphere(std::span<const Vec3> positions, const Face& face);
Aabb faceBox(std::span<const Vec3> positions, const Face& face);
Aabb faceSphereBox(std::span<const Vec3> positions, const Face& face);  // box of the face sphere

// Contacts between parts a and b (ids are written into the contacts), in (faceA, faceB) order,
// whatever the traversal's. Appends to `contacts`;
// when `candidates` is given, also appends every leaf pair whose volumes overlap (otherwise
// subtrees that lie beyond the planes of an at-rest face of A are pruned, and the statistics
// count what was visited; the contacts are the same either way). Both
// colliders must have been built for `test` (std::invalid_argument otherwise).
void queryPair(std::uint32_t idA, const Part& a, const PartCollider& colliderA, std::uint32_t idB, const Part& b,
               const PartCollider& colliderB, ExactTest test, std::vector<Contact>& contacts, QueryStats& stats,
               std::vector<std::pair<Index, Index>>* candidates = nullptr);

// Point-shell contacts of a rigid part A with part B: every mass of B whose distance sampled
// from A's field (distance_field.hpp) is <= 0 is one contact (massB), with depth = minus that
// distance, point = the mass, normal = minus the field's normalised gradient (so it pushes A
// out of B, as for face contacts). B's moving masses are each sampled; its masses at rest are
// found through restPointsB (PartCollider::restPointTree, built), pruned with the field's Lipschitz
// bound, so the cost follows the masses near A's surface, not the pairs of faces, and needs no
// refit. Faces of A that poke between B's masses are not seen: meant for B finer than A (a
// deformable part against a rigid tool or ball). stats: volumeTests = tree nodes visited,
// candidatePairs = masses reached, exactTests = masses sampled.
// Temporal coherence for one pair (queryPairCoherent): the leaf pairs of a traversal made with
// A's volumes grown by a margin, and what that traversal assumed. Starts empty; the query
// keeps it. One per ordered pair (A, B), used with the same colliders.
struct PairCoherence {
    struct Candidate {
        Index faceA = 0, faceB = 0;
        // A lower bound on the gap between the two faces at the take: how far B's face lay
        // beyond a plane of A's face (A rigid; 0 otherwise), and once settled also how far A's
        // face lay beyond the plane of B's, or the two apart along a separating axis of the
        // triangles. Settled by the take itself when A deforms or the take is walked (those
        // gaps at the take's pose), else by the first scan whose reach attains the pair (the
        // gaps at that scan less its reach: the motion since the take).
        double separation = 0.0;
        bool settled = false;
    };
    // What a traversal took, and what it assumed: the relative pose it tested at, its margin,
    // and the colliders' vertex drifts and generations when it began. A traversal may be spread over
    // several queries (`stack` holds the node pairs left); it tests every node at `pose`.
    struct Take {
        std::vector<Candidate> candidates;  // in traversal order, by (faceA, faceB) once `sorted`
        bool sorted = false;                // set when complete, unless finished at once with pairs left to settle
        RelativePose pose;
        double margin = 0.0;
        double vertexDriftA = 0.0, vertexDriftB = 0.0;
        std::uint64_t generationA = 0, generationB = 0;
        std::vector<std::pair<std::int32_t, std::int32_t>> stack;
        std::size_t nodes = 0;              // node pairs visited
        std::size_t settledUpTo = 0;        // candidates a walked take has settled, in order
        std::uint64_t startQuery = 0;       // the query that began it (PairCoherence::queries)
    };
    Take list;                             // the candidates in use
    bool valid = false;
    Take next;                             // the next list, being taken
    bool walking = false;
    std::uint64_t queries = 0;             // coherent queries so far
    std::uint32_t queriesSince = 0;        // queries answered from the list
    std::size_t testedAfterTraversal = 0;  // candidates tested by the query that took the list
    std::size_t scanCost = 0;              // candidates tested since beyond that many, summed
    // Plain traversals answer while the motion would outrun any list; lastPlain holds the pose
    // and drifts the last of them saw (its candidates stay empty).
    bool plain = false;
    Take lastPlain;
    std::uint32_t plainQueries = 0;        // answered so since it began
    std::uint64_t traversals = 0;          // lists taken
    std::uint64_t plainTraversals = 0;     // queries answered by a whole traversal (queryPair)
    std::uint64_t scans = 0;               // queries answered from the list
};

// queryPair()'s contacts, in the same order, from the pair's last candidates while they still
// cover every leaf pair that can overlap: the relative motion of the parts (B's bounding sphere
// under the change of relative pose) plus the growth of both colliders' leaves since the candidates were taken
// stays within their margin. A's leaf volumes grown by the margin contain every position its
// leaves can reach meanwhile, so a leaf pair that overlaps now was a candidate; each candidate
// is tested as the full query tests a leaf pair (volume overlap now, then the exact test).
// A candidate whose faces were farther apart (beyond a plane of either face, or along a
// separating axis of the triangles) than their vertices have moved relative to each other since
// (relative motion plus both vertexDrifts) is skipped: the full query's exact test would find
// them apart. With A rigid the take measures only the cheap gap (A's face plane); the others
// are measured after its traversal by a walked take, or else by the first scan that reaches the
// candidate (Candidate::settled). So a body at rest on another costs O(its
// candidates' scan + the pairs near contact), not a traversal.
// The next list is taken by a traversal at a fixed pose, spread over the queries (1/8 of the
// last traversal's node pairs each) from when the motion reaches 0.25 of the margin: no query
// pays a whole traversal unless the motion outruns that walk (then it finishes it, or takes a
// list at once). Its margin: twice the last when the motion left it, twice the motion seen (at
// most half the margin) once the tests motion added have cost as much as a traversal (then it
// is taken at once); within [1e-4, 0.05] of the smaller mean leaf size. A pair at rest never
// traverses again. When the widest margin is outrun within 4 queries of a list's pose, plain
// queryPair() calls answer (at least the next 16) until the motion from one query to the next
// (relative pose and both colliders' vertex drifts) is slow enough that a list of the widest
// margin would last 8 queries: a tool sliding over a deforming part pays no lists it cannot
// use, a pair that comes to rest gets them back within a query of the 16.
// stats: volumeTests counts the traversal's nodes and the candidates tested; candidatePairs
// the candidates whose leaves overlap now.
void queryPairCoherent(std::uint32_t idA, const Part& a, const PartCollider& colliderA, std::uint32_t idB, const Part& b,
                       const PartCollider& colliderB, ExactTest test, PairCoherence& coherence, std::vector<Contact>& contacts,
                       QueryStats& stats);

class SignedDistanceField;
void queryPointShell(std::uint32_t idA, const Part& a, const SignedDistanceField& fieldA, std::uint32_t idB, const Part& b,
                     const Bvh<Aabb>& restPointsB, std::vector<Contact>& contacts, QueryStats& stats);

// Temporal coherence of a point-shell pair (queryPointShellCoherent). Starts empty.
struct PointShellCoherence {
    // A walk of B's rest-point tree at a fixed relative pose with the field's reach grown by a
    // margin: the leaves it reached, in its order, with the distance (or a lower bound of it)
    // each rest position samples there; only those in the grid whose distance does not stay
    // clear over the margin. Resumable: `stack` holds what is left.
    struct Walk {
        std::vector<std::int32_t> stack;
        std::vector<std::pair<Index, double>> masses;
        RelativePose pose;
        double margin = 0.0;
        std::size_t nodes = 0;
        bool active = false;
    };
    std::vector<std::pair<Index, double>> restMasses;  // the last complete walk's masses
    RelativePose pose;                                 // and its pose and margin
    double margin = 0.0;
    bool valid = false;
    std::size_t traversalCost = 0;                     // its nodes
    std::uint64_t traversals = 0;                      // walks completed
    // Walks the motion outran: finished after the old list ran out, or made whole in one query
    // that had no other to spread it over (a step-time spike either way).
    std::uint64_t walksAtOnce = 0;
    RelativePose lastQuery;                            // B in A at the last query: its speed
    Walk walk;                                         // the next list, under way
    // By mass of B, its last sample as a moving mass: the point (A's frame), and the square of
    // the motion from it over which the mass stays clear (SignedDistanceField::
    // squaredClearReach; -1: none; outside the grid, the squared distance to it; infinity: a
    // free vertex, which never touches). One record of 32 bytes.
    struct LastSample {
        Vec3 point = Vec3::Zero();
        double squaredReach = -1.0;
    };
    std::vector<LastSample> lastSamples;
};

// queryPointShell()'s contacts, in the same order, sampling only the masses that may touch.
// The field is fixed in A's frame and its interpolant's slope is at most sqrt(3), so a mass
// that sampled d > 0 cannot sample <= 0 within d / sqrt(3) of that point: a moving mass is
// skipped while it stays that close to its last sample, and a mass at rest while B's rest
// sphere (restSphereB, B's frame) has moved less than that in A's frame since the traversal
// that listed it. The rest masses come from a walk of the rest-point tree with the field's
// reach grown by a margin of 2 cells (subtrees of up to 8 masses listed whole, then each mass
// kept only where its sample can reach the surface within the margin); the next list's walk
// starts when B's rest sphere has moved 0.4 of the margin and is spread over the following
// queries, so a query pays a whole walk only when the motion outruns the margin. A haptic
// tool held still or sliding then samples only the masses near its surface, with no traversal
// spikes.
void queryPointShellCoherent(std::uint32_t idA, const Part& a, const SignedDistanceField& fieldA, std::uint32_t idB, const Part& b,
                             const Bvh<Aabb>& restPointsB, const Sphere& restSphereB, PointShellCoherence& coherence,
                             std::vector<Contact>& contacts, QueryStats& stats);

// --- The point shell's sharp features (sharp_features.cpp) ---
// The point shell sees only B's masses, so a rigid edge or corner narrower than the gaps
// between them can pass through B's surface unseen. The faces of the rigid part where its
// surface turns sharply at B's scale are therefore also tested as faces against B's faces
// (querySharpFeatures), which closes that hole; the point shell answers the rest.
//
// With B's rest resolution rho (every point of a B triangle lies within rho of one of its
// corners: rho = longest rest edge / sqrt(3)), a crossing of B's (locally flat) surface that
// covers a disc of radius rho of it holds a mass, which the point shell finds. A vertex v of
// the rigid part, with normal n, is smooth at scale rho when its faces lie within `angle`
// (theta) of n (the pressing direction, in v's normal cone, is then within theta of n), and the
// faces over the disc of radius R = rho cos(theta) / cos(2 theta) around v in n's plane
// (connected to v through such faces) turn less than 60 degrees from n (a height field) and lie
// at most rho tan(theta) behind v along n. Were v the deepest point of a crossing deeper than
// rho (tan(theta) + tan(2 theta) / 2), the crossing would cover a disc of radius rho of B's
// surface (sharp_features.cpp gives the steps): smooth surface hides at most that much past
// B's (0.78 rho, 0.45 of B's longest rest edge, at the default 20 degrees; a sphere of radius R
// hides about rho^2 / 2R; a true sphere is smooth from a radius of 2.25 rho, finely faceted
// ones from 2.5 rho, level-2 icospheres from 2.8 rho). Every other vertex is
// sharp, and the faces around sharp vertices are the sharp faces. Known limits: B's triangles
// stretched beyond their rest length widen the gaps by as much; a disc over more than 512
// vertices counts as sharp (a rigid part far finer than B), which keeps the bound at a
// cost; the bound assumes B locally flat over the disc.
inline constexpr double kSharpFeatureAngle = 0.3490658503988659;  // 20 degrees

// How deep smooth surface can cross B's unseen at B's rest resolution `radius`: the bound
// above, radius (tan(angle) + tan(2 angle) / 2).
inline double sharpFeatureBound(double radius, double angle = kSharpFeatureAngle) {
    return radius * (std::tan(angle) + 0.5 * std::tan(2.0 * angle));
}

struct SharpFeatures {
    std::vector<Index> faces;  // ascending faces of the rigid part
    Bvh<Aabb> tree;            // their leaf boxes (for `test`) in the part's frame; leaf k is faces[k]
    double radius = 0.0, angle = 0.0;
    ExactTest test = ExactTest::TriangleTriangle;
    bool empty() const { return faces.empty(); }
};

// The sharp faces of `rigid` (its rest mesh) at scale `radius` (>= 0, finite; `angle` in
// (0, pi/4)), with leaves for the exact test the queries will use.
SharpFeatures findSharpFeatures(const Part& rigid, double radius, ExactTest test = ExactTest::TriangleTriangle,
                                double angle = kSharpFeatureAngle);

// B's rest resolution: the largest distance from a point of one of its triangles to the
// nearest corner of that triangle is at most this (its longest rest edge / sqrt(3)).
double restResolution(const Part& part);

// The face contacts of A's sharp faces (A rigid, the part `features` were found for) against
// B's faces, in (faceA, faceB) order, appended after whatever `contacts` holds: queryPair()
// restricted to those faces of A. colliderB must be refitted to B's shape; the features must
// have been found for `test`.
void querySharpFeatures(std::uint32_t idA, const Part& a, const PartCollider& colliderA, const SharpFeatures& features,
                        std::uint32_t idB, const Part& b, const PartCollider& colliderB, ExactTest test,
                        std::vector<Contact>& contacts, QueryStats& stats);

}  // namespace flexfit
