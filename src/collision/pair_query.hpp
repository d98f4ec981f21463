// Internal to src/collision: the pieces the full and the coherent pair queries share
// (collision.hpp): the simultaneous traversal of two hierarchies, the cheap rejection by an
// at-rest face's planes, and the exact test of one leaf pair.
#pragma once

#include "collision/triangle_queries.hpp"
#include "flexfit/collision.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace flexfit::detail {

inline Triangle triangleOf(std::span<const Vec3> positions, const Face& f) { return {positions[f[0]], positions[f[1]], positions[f[2]]}; }

inline double volumeSize(const Sphere& s) { return 2.0 * s.radius; }
inline double volumeSize(const Aabb& b) { return b.size(); }
// Which side of a node pair descends: the larger volume, compared by squared size (the box's
// diagonal without its square root, which was the traversal's costliest instruction). Sizes
// within rounding of each other may now descend the other side: that changes the order of
// the traversal and its counts, never the contacts (sorted) or the candidates (a set).
inline double squaredVolumeSize(const Sphere& s) { return 4.0 * s.radius * s.radius; }
inline double squaredVolumeSize(const Aabb& b) { return (b.max - b.min).squaredNorm(); }

inline Sphere grown(const Sphere& s, double margin) { return {s.centre, s.radius + margin}; }
inline Aabb grown(const Aabb& b, double margin) { return {b.min.array() - margin, b.max.array() + margin}; }

// Simultaneous depth-first traversal; leafPair(faceA, faceB) for every overlapping leaf pair.
// prune(faceA, volumeB) may cut a subtree of B that cannot touch A's leaf face, and
// pruneA(faceB, volumeA) a subtree of A that cannot touch B's leaf face. A margin > 0
// grows A's volumes by it (for the coherent query's candidates); which side descends depends
// on the volumes alone, not on the margin. traverseFrom() goes on from the node pairs left in
// `stack` for about `budget` volume tests, and can be resumed (the coherent query spreads a traversal
// over several queries); traverse() is one whole traversal.
using NodePairStack = std::vector<std::pair<std::int32_t, std::int32_t>>;

// Leaf groups: a node pair whose subtrees hold at most leafGroup() items each is not descended
// node by node; each of its leaf pairs is tested directly (the same leaf-volume test, then
// leafPair), in a tight loop over the subtrees' node ranges, without the internal node pairs'
// tests and stack traffic. The contacts are the same: a pair of leaves that overlap has
// overlapping ancestors (every node encloses its children), and a leaf pair a prune would have
// cut below is handed to leafPair, whose exact test rejects it (RestPlaneFilter: a subtree is
// pruned only when each of its triangles would be). Asking the prune of each leaf pair instead
// was measured slower (the exact test's own plane test repeats it). The group size was chosen
// by measurement (BM_ToolIntoPart and BM_FlexfitQuery in bench/results/collision.csv).
inline constexpr std::size_t kDefaultLeafGroup = 4;
std::size_t leafGroup();  // kDefaultLeafGroup unless a ScopedLeafGroup chose another
// Benchmarks and tests: every traversal in this scope groups `items` (>= 1; 1 descends every
// node pair). Not thread-safe; scopes must not overlap.
class ScopedLeafGroup {
public:
    explicit ScopedLeafGroup(std::size_t items);
    ~ScopedLeafGroup();
    ScopedLeafGroup(const ScopedLeafGroup&) = delete;
    ScopedLeafGroup& operator=(const ScopedLeafGroup&) = delete;
};

// A's volume (grown by the margin when kGrown) against B's.
template <bool kGrown, class VA, class VB>
bool volumesOverlap(const VA& a, const VB& b, const RelativePose& bInA, double margin) {
    if constexpr (kGrown) return overlap(grown(a, margin), b, bInA);
    return overlap(a, b, bInA);
}

// Every leaf pair of the subtrees of nodes i (of A) and j (of B), by the leaves' volumes.
// Returns the volume tests made.
template <bool kGrown, class BA, class BB, class LeafPair>
std::size_t testLeafGroup(std::int32_t i, std::int32_t j, const Bvh<BA>& a, const Bvh<BB>& b, const RelativePose& bInA, QueryStats& stats,
                          LeafPair& leafPair, double margin) {
    const auto& na = a.nodes();
    const auto& nb = b.nodes();
    const std::size_t before = stats.volumeTests;
    for (std::int32_t p = i; p < a.subtreeEnd(i); ++p) {
        const auto& x = na[std::size_t(p)];
        if (!x.isLeaf()) continue;
        for (std::int32_t q = j; q < b.subtreeEnd(j); ++q) {
            const auto& y = nb[std::size_t(q)];
            if (!y.isLeaf()) continue;
            ++stats.volumeTests;
            if (!volumesOverlap<kGrown>(x.volume, y.volume, bInA, margin)) continue;
            ++stats.candidatePairs;
            leafPair(x.item, y.item);
        }
    }
    return stats.volumeTests - before;
}

template <bool kGrown, class BA, class BB, class LeafPair, class Prune, class PruneA>
void traverseFromImpl(NodePairStack& stack, std::size_t budget, const Bvh<BA>& a, const Bvh<BB>& b, const RelativePose& bInA,
                      QueryStats& stats, LeafPair& leafPair, Prune& prune, PruneA& pruneA, double margin) {
    const auto& na = a.nodes();
    const auto& nb = b.nodes();
    const std::size_t group = leafGroup();
    // `budget` counts volume tests: a leaf group's tests count each.
    for (std::size_t visited = 0; !stack.empty() && visited < budget; ++visited) {
        const auto [i, j] = stack.back();
        stack.pop_back();
        const auto& x = na[std::size_t(i)];
        const auto& y = nb[std::size_t(j)];
        ++stats.volumeTests;
        if (!volumesOverlap<kGrown>(x.volume, y.volume, bInA, margin)) continue;
        if (x.isLeaf() && !y.isLeaf() && prune(x.item, y.volume)) continue;
        if (y.isLeaf() && !x.isLeaf() && pruneA(y.item, x.volume)) continue;
        if (!(x.isLeaf() && y.isLeaf()) && a.itemCount(i) <= group && b.itemCount(j) <= group) {
            visited += testLeafGroup<kGrown>(i, j, a, b, bInA, stats, leafPair, margin);
            continue;
        }
        if (x.isLeaf() && y.isLeaf()) {
            ++stats.candidatePairs;
            leafPair(x.item, y.item);
        } else if (x.isLeaf() || (!y.isLeaf() && squaredVolumeSize(y.volume) > squaredVolumeSize(x.volume))) {
            stack.emplace_back(i, y.right);
            stack.emplace_back(i, y.left);
        } else {
            stack.emplace_back(x.right, j);
            stack.emplace_back(x.left, j);
        }
    }
}

// No subtree of A pruned by B's leaf faces.
struct NoPrune {
    template <class Volume>
    bool operator()(Index, const Volume&) const { return false; }
};

template <class BA, class BB, class LeafPair, class Prune, class PruneA = NoPrune>
void traverseFrom(NodePairStack& stack, std::size_t budget, const Bvh<BA>& a, const Bvh<BB>& b, const RelativePose& bInA,
                  QueryStats& stats, LeafPair leafPair, Prune prune, double margin, PruneA pruneA = {}) {
    if (margin > 0.0)
        traverseFromImpl<true>(stack, budget, a, b, bInA, stats, leafPair, prune, pruneA, margin);
    else
        traverseFromImpl<false>(stack, budget, a, b, bInA, stats, leafPair, prune, pruneA, margin);
}

template <class BA, class BB, class LeafPair, class Prune, class PruneA = NoPrune>
void traverse(const Bvh<BA>& a, const Bvh<BB>& b, const RelativePose& bInA, QueryStats& stats, LeafPair leafPair, Prune prune,
              double margin, PruneA pruneA = {}) {
    if (a.empty() || b.empty()) return;
    thread_local NodePairStack stack;
    stack.assign(1, {0, 0});
    traverseFrom(stack, std::numeric_limits<std::size_t>::max(), a, b, bInA, stats, leafPair, prune, margin, pruneA);
}

template <class Visit>
void dispatch(const PartCollider& a, const PartCollider& b, Visit visit) {
    if (a.spheres() && b.spheres()) return visit(*a.spheres(), *b.spheres());
    if (a.spheres() && b.boxes()) return visit(*a.spheres(), *b.boxes());
    if (a.boxes() && b.spheres()) return visit(*a.boxes(), *b.spheres());
    return visit(*a.boxes(), *b.boxes());
}

// One part's at-rest face planes moved to the other part's frame: each face's plane and edge
// planes (PartCollider::restPlanes, cached in the part's own frame), moved once per face and
// query. A face is at rest when its part is rigid or none of its masses moves: its vertices are
// then where the rest planes were computed.
class MovedFacePlanes {
public:
    // A face's planes in the other frame, and the rounding margin of each plane's tests (far
    // wider than the triangle test's tolerance).
    struct Planes {
        std::array<Eigen::Vector4d, 4> planes;
        std::array<double, 4> margins;
    };
    // Kept between queries so a query allocates nothing: one per thread and side, handed to each
    // filter once. Packed in the order the faces were first met (by their slot in `moved`): a
    // query touches a few faces of a large part, and writing each one's 128 bytes into an array
    // by face index missed the cache on every face (the filter's costliest instructions in a
    // tool pressed into a 3,732-face part).
    struct Scratch {
        std::vector<Planes> planes;  // by slot of `moved`
        IndexSet moved;              // faces whose planes are in `planes` for this query
    };
    // The planes of `part` moved to the other part's frame: A's to B's when `ofA`, else B's to A's.
    MovedFacePlanes(const Part& part, const PartCollider& collider, const RelativePose& bInA, bool ofA, Scratch& scratch)
        : part_(part), collider_(collider), bInA_(bInA), ofA_(ofA), planes_(scratch.planes), moved_(scratch.moved) {
        moved_.clear();
        moved_.growTo(part.model().faceCount());
        planes_.clear();
    }
    bool rigid() const { return part_.mode() == PartMode::Rigid; }
    bool atRest(Index face) const {
        const Face& f = part_.model().mesh.faces[face];
        return rigid() || !(part_.region().moves(f[0]) || part_.region().moves(f[1]) || part_.region().moves(f[2]));
    }
    // The face's planes in the other frame; the reference holds until the next call.
    const Planes& of(Index face) {
        if (!moved_.insert(face)) return planes_[moved_.slotOf(face)];
        const auto& planes = collider_.restPlanes(face);
        Planes& out = planes_.emplace_back();
        auto& moved = out.planes;
        for (std::size_t k = 0; k < planes.size(); ++k) {
            out.margins[k] = 1e-9 * (1.0 + std::abs(planes[k][3]));
            const Vec3 n = planes[k].head<3>();
            // A's: n.(R x + t) = d  <=>  (R^T n).x = d - n.t. B's: n.x_B = d, x_B = R^T (x_A - t)
            // <=>  (R n).x_A = d + (R n).t. R n is n itself when R is exactly the identity (the
            // same values up to the sign of a zero, which no comparison here sees).
            if (ofA_) {
                const Vec3 turned = bInA_.pureTranslation ? n : Vec3(bInA_.rotation.transpose() * n);
                moved[k] << turned, planes[k][3] - n.dot(bInA_.translation);
            } else {
                const Vec3 turned = bInA_.pureTranslation ? n : Vec3(bInA_.rotation * n);
                moved[k] << turned, planes[k][3] + turned.dot(bInA_.translation);
            }
        }
        return out;
    }
    // The other part's triangle (its positions, in its own frame) entirely beyond one of the
    // face's planes by more than the margin (or behind its own plane).
    bool triangleBeyond(Index face, std::span<const Vec3> positions, const Face& other) {
        const auto& [planes, margins] = of(face);
        for (std::size_t k = 0; k < planes.size(); ++k) {
            const double m = margins[k];
            const auto [d0, d1, d2] = distances(planes[k], positions, other);
            if (d0 > m && d1 > m && d2 > m) return true;
            if (k == 0 && d0 < -m && d1 < -m && d2 < -m) return true;
        }
        return false;
    }
    // How far the other part's triangle lies beyond one of the face's planes, less the margin
    // triangleBeyond() keeps (0 when none separates them); stops once it exceeds `enough`.
    double gap(Index face, std::span<const Vec3> positions, const Face& other, double enough) {
        const auto& [planes, margins] = of(face);
        double gap = 0.0;
        for (std::size_t k = 0; k < planes.size(); ++k) {
            const auto [d0, d1, d2] = distances(planes[k], positions, other);
            gap = std::max(gap, std::min({d0, d1, d2}) - margins[k]);
            if (k == 0) gap = std::max(gap, -std::max({d0, d1, d2}) - margins[k]);
            if (gap > enough) break;
        }
        return gap * (1.0 - 1e-12);
    }
    // A volume of the other part entirely beyond one of the face's planes by more than the
    // margin and `extra` (or behind its own plane).
    template <class Volume>
    bool volumeBeyond(Index face, const Volume& volume, double extra) {
        const auto& [planes, margins] = of(face);
        for (std::size_t k = 0; k < planes.size(); ++k) {
            const Vec3 n = planes[k].head<3>();
            const double m = margins[k] + extra;
            const auto [lowest, highest] = extent(volume, n);
            if (lowest - planes[k][3] > m) return true;
            if (k == 0 && highest - planes[k][3] < -m) return true;
        }
        return false;
    }

private:
    // How far each vertex of the other triangle lies beyond the plane (n.x - d).
    static std::array<double, 3> distances(const Eigen::Vector4d& plane, std::span<const Vec3> positions, const Face& other) {
        const Vec3 n = plane.head<3>();
        return {n.dot(positions[other[0]]) - plane[3], n.dot(positions[other[1]]) - plane[3], n.dot(positions[other[2]]) - plane[3]};
    }
    // Range of n.x over the volume.
    [[gnu::always_inline]] static std::pair<double, double> extent(const Aabb& box, const Vec3& n) {
        const double centre = n.dot(box.centre()), reach = n.cwiseAbs().dot(box.halfExtents());
        return {centre - reach, centre + reach};
    }
    [[gnu::always_inline]] static std::pair<double, double> extent(const Sphere& sphere, const Vec3& n) {
        const double centre = n.dot(sphere.centre);
        return {centre - sphere.radius, centre + sphere.radius};
    }
    const Part& part_;
    const PartCollider& collider_;
    const RelativePose& bInA_;
    bool ofA_;
    std::vector<Planes>& planes_;
    IndexSet& moved_;
};

// Cheap rejection before the triangle test, when a face of the pair is at rest: the other
// triangle entirely beyond the at-rest face's plane (either side) or beyond one of its edge
// planes is separated from it along that direction, and needs no transform (the planes are
// moved to its frame instead, once per face and query). A's face's planes are tried first, then
// B's: a large face at rest against a part of small ones (a rigid ball on the rigid container
// mouth, whose faces are far smaller) rejects by its own planes most of the leaf pairs its box
// meets. The margin is far wider than the triangle test's own tolerance, so only pairs that
// test would also reject are skipped.
class RestPlaneFilter {
public:
    struct Scratch {
        MovedFacePlanes::Scratch ofA, ofB;
    };
    RestPlaneFilter(const Part& a, const PartCollider& colliderA, const Part& b, const PartCollider& colliderB, const RelativePose& bInA,
                    Scratch& scratch)
        : a_(a, colliderA, bInA, true, scratch.ofA), b_(b, colliderB, bInA, false, scratch.ofB) {}

    // A's face fa (pa: A's positions) against B's face fb (pb: B's), each in its own frame; by
    // B's face's planes too when `byB`.
    bool separated(Index fa, Index fb, std::span<const Vec3> pa, std::span<const Vec3> pb, const Face& faceA, const Face& faceB,
                   bool byB) {
        return (a_.atRest(fa) && a_.triangleBeyond(fa, pb, faceB)) || (byB && b_.atRest(fb) && b_.triangleBeyond(fb, pa, faceA));
    }

    // A subtree of B whose volume lies entirely beyond one of A's face planes holds no
    // triangle the face can touch (each would be rejected by separated()); `extra` widens the
    // margin.
    template <class Volume>
    bool separated(Index fa, const Volume& volumeB, double extra = 0.0) {
        return a_.atRest(fa) && a_.volumeBeyond(fa, volumeB, extra);
    }
    // The same for B's face and a subtree of A.
    template <class Volume>
    bool separatedByB(Index fb, const Volume& volumeA, double extra = 0.0) {
        return b_.atRest(fb) && b_.volumeBeyond(fb, volumeA, extra);
    }

    // How far one face's triangle lies beyond one of the planes of the other face, a rigid
    // part's (A's, then B's), less the margin separated() keeps: while the rigid parts do not
    // deform and the faces move less than that against each other, separated() rejects the pair
    // on that plane. 0 when no plane separates them, or neither part is rigid. Stops early once
    // the gap exceeds `enough`.
    double separation(Index fa, Index fb, std::span<const Vec3> pa, std::span<const Vec3> pb, const Face& faceA, const Face& faceB,
                      double enough) {
        double gap = a_.rigid() ? a_.gap(fa, pb, faceB, enough) : 0.0;
        if (gap <= enough && b_.rigid()) gap = std::max(gap, b_.gap(fb, pa, faceA, enough));
        return gap;
    }
    bool rigidA() const { return a_.rigid(); }
    bool rigidB() const { return b_.rigid(); }

private:
    MovedFacePlanes a_, b_;
};


// How far a point of B (within its bounding sphere) can have moved, in A's frame, between the
// relative poses `before` and `now`: |(R1 - R0) c + t1 - t0| + |R1 - R0| r, where the spectral
// norm |R1 - R0| = |R1 R0^T - I| = 2 sin(angle / 2) = 2 |q.vec| of the turn's quaternion.
inline double relativeMotion(const RelativePose& before, const RelativePose& now, const Sphere& localSphereB) {
    const Eigen::Matrix3d turn = now.rotation - before.rotation;
    const Eigen::Quaterniond q(Eigen::Matrix3d(now.rotation * before.rotation.transpose()));
    const double spectral = 2.0 * q.vec().norm() * (1.0 + 1e-12) + 1e-15;
    return (turn * localSphereB.centre + now.translation - before.translation).norm() + spectral * localSphereB.radius;
}

inline RelativePose relativePose(const Part& a, const Part& b) {
    // B's frame seen from A's: x_A = Ra^T (Rb x_B + tb - ta).
    const Eigen::Matrix3d ra = a.pose().rotation.toRotationMatrix(), rb = b.pose().rotation.toRotationMatrix();
    return RelativePose(ra.transpose() * rb, ra.transpose() * (b.pose().translation - a.pose().translation));
}

// This thread's scratch of the rest-plane filter (collision.cpp).
RestPlaneFilter::Scratch& restPlaneScratch();

// Sorts contacts[first..] into (faceA, faceB) order (collision.cpp).
void sortContacts(std::vector<Contact>& contacts, std::size_t first);

// How the triangle test reads two parts' faces: as solids when both rest meshes bound one, and
// with opposing faces pushed back when neither part is deformable (FaceSides).
inline FaceSides facesSides(const Part& a, const PartCollider& colliderA, const Part& b, const PartCollider& colliderB) {
    if (!colliderA.boundsSolid() || !colliderB.boundsSolid()) return FaceSides::TwoSided;
    return a.mode() == PartMode::Rigid && b.mode() == PartMode::Rigid ? FaceSides::RigidSolids : FaceSides::Solids;
}

// The exact test of one leaf pair (face of A, face of B) at the parts' current shapes and poses,
// shared by the full and the coherent query.
class LeafPairTester {
public:
    LeafPairTester(std::uint32_t idA, const Part& a, const PartCollider& colliderA, std::uint32_t idB, const Part& b,
                   const PartCollider& colliderB, ExactTest test, const RelativePose& bInA, std::vector<Contact>& contacts,
                   QueryStats& stats, RestPlaneFilter::Scratch& scratch = restPlaneScratch())
        : idA_(idA), idB_(idB), a_(a), b_(b), test_(test), sides_(facesSides(a, colliderA, b, colliderB)),
          bInA_(bInA), ra_(a.pose().rotation.toRotationMatrix()),
          pa_(a.state().positions), pb_(b.state().positions), facesA_(a.model().mesh.faces), facesB_(b.model().mesh.faces),
          filter_(a, colliderA, b, colliderB, bInA, scratch), contacts_(contacts), stats_(stats) {}

    void operator()(Index fa, Index fb) {
        const Face& f = facesB_[fb];
        ++stats_.exactTests;
        if (test_ == ExactTest::TriangleTriangle && filter_.separated(fa, fb, pa_, pb_, facesA_[fa], f, planesOfB_)) return;
        const Triangle tb{bInA_.apply(pb_[f[0]]), bInA_.apply(pb_[f[1]]), bInA_.apply(pb_[f[2]])};
        std::optional<TriangleContact> hit;
        if (test_ == ExactTest::SphereTriangle) {
            const Sphere s = faceSphere(pa_, facesA_[fa]);
            hit = sphereTriangleContact(s.centre, s.radius, tb);
        } else {
            hit = intersectTriangles(triangleOf(pa_, facesA_[fa]), tb, sides_);
        }
        if (!hit) return;
        ++stats_.contacts;
        contacts_.push_back({idA_, idB_, fa, fb, a_.pose().apply(hit->point), ra_ * hit->normal, hit->depth});
    }
    // Leaf pairs rejected by A's at-rest face's planes only, not by B's too: the coherent
    // query's scans, whose candidates lay within the motion since of both faces' planes when
    // taken: the planes of B's face rejected few of them, and testing them cost the rigid ball
    // resting on the rigid mouth 0.7 µs of its 6 µs narrow phase a step.
    void skipPlanesOfB() { planesOfB_ = false; }
    // Subtrees of B that A's at-rest leaf face cannot touch, and of A that B's cannot
    // (RestPlaneFilter).
    template <class Volume>
    bool prunes(Index fa, const Volume& volumeB) {
        return test_ == ExactTest::TriangleTriangle && filter_.separated(fa, volumeB);
    }
    template <class Volume>
    bool prunesByB(Index fb, const Volume& volumeA) {
        return test_ == ExactTest::TriangleTriangle && filter_.separatedByB(fb, volumeA);
    }
    // Whether planeGap() measures a gap (A rigid, triangle test), or is always 0. (The world
    // puts the rigid part first: B is rigid only when A is.)
    bool gapsByA() const { return test_ == ExactTest::TriangleTriangle && filter_.rigidA(); }
    // How far the two faces may move against each other before the exact test could find a
    // contact, by the rigid parts' face planes (RestPlaneFilter::separation).
    double planeGap(Index fa, Index fb, double enough) {
        return test_ == ExactTest::TriangleTriangle ? filter_.separation(fa, fb, pa_, pb_, facesA_[fa], facesB_[fb], enough) : 0.0;
    }
    // How far A's face may move (its vertices, in B's frame) before it reaches the plane of B's
    // face as it is now, less a margin far above the exact test's tolerance: while it stays
    // strictly on one side, intersectTriangles rejects the pair at once.
    double separationByB(Index fa, Index fb) {
        if (test_ != ExactTest::TriangleTriangle) return 0.0;
        const std::span<const Vec3> pa = a_.state().positions, pb = b_.state().positions;
        const Face& f = b_.model().mesh.faces[fb];
        const Vec3 n = (pb[f[1]] - pb[f[0]]).cross(pb[f[2]] - pb[f[0]]);
        const double length = n.norm();
        if (!(length > 0.0)) return 0.0;
        const Vec3 unit = n / length;
        const double offset = unit.dot(pb[f[0]]);
        double lowest = std::numeric_limits<double>::infinity(), highest = -lowest, reach2 = 0.0;
        const Face& g = a_.model().mesh.faces[fa];
        for (int i = 0; i < 3; ++i) {
            const Vec3 p = bInA_.rotation.transpose() * (pa[g[i]] - bInA_.translation);  // A's vertex in B's frame
            const double d = unit.dot(p) - offset;
            lowest = std::min(lowest, d);
            highest = std::max(highest, d);
            reach2 = std::max({reach2, (pa[g[i]] - pa[g[(i + 1) % 3]]).squaredNorm(), (pb[f[i]] - pb[f[(i + 1) % 3]]).squaredNorm()});
        }
        const double margin = 1e-8 * (1.0 + std::abs(offset) + reach2);
        return std::max({0.0, lowest - margin, -highest - margin}) * (1.0 - 1e-12);
    }
    // How far apart the two faces are along the best separating axis (triangleGap), less a
    // margin far above intersectTriangles' rounding; 0 when none separates them. Stops once it
    // exceeds `enough`.
    double separationOfTriangles(Index fa, Index fb, double enough = std::numeric_limits<double>::infinity()) {
        if (test_ != ExactTest::TriangleTriangle) return 0.0;
        const Face& f = facesB_[fb];
        const Triangle tb{bInA_.apply(pb_[f[0]]), bInA_.apply(pb_[f[1]]), bInA_.apply(pb_[f[2]])};
        const Triangle ta = triangleOf(pa_, facesA_[fa]);
        const double scale = std::max({ta.a.norm(), ta.b.norm(), ta.c.norm(), tb.a.norm(), tb.b.norm(), tb.c.norm()});
        const double tolerance = 1e-9 * (1.0 + scale);
        return std::max(0.0, triangleGap(ta, tb, enough + tolerance) - tolerance);
    }
    // B's subtrees beyond a plane of A's (rigid) leaf face by more than `margin`.
    template <class Volume>
    bool prunesBeyond(Index fa, const Volume& volumeB, double margin) {
        return gapsByA() && filter_.separated(fa, volumeB, margin);
    }
    // A's subtrees beyond a plane of B's (rigid) leaf face by more than `margin`.
    template <class Volume>
    bool prunesBeyondByB(Index fb, const Volume& volumeA, double margin) {
        return test_ == ExactTest::TriangleTriangle && filter_.rigidB() && filter_.separatedByB(fb, volumeA, margin);
    }

private:
    std::uint32_t idA_, idB_;
    const Part& a_;
    const Part& b_;
    ExactTest test_;
    FaceSides sides_;  // how intersectTriangles reads the faces (facesSides)
    bool planesOfB_ = true;  // the rest-plane filter tries B's face's planes too
    const RelativePose& bInA_;
    Eigen::Matrix3d ra_;
    std::span<const Vec3> pa_, pb_;
    std::span<const Face> facesA_, facesB_;
    RestPlaneFilter filter_;
    std::vector<Contact>& contacts_;
    QueryStats& stats_;
};

inline void requireBuiltFor(const PartCollider& colliderA, const PartCollider& colliderB, ExactTest test) {
    if (colliderA.exactTest() != test || colliderB.exactTest() != test)
        throw std::invalid_argument("queryPair: a collider was built for another exact test");
}

}  // namespace flexfit::detail
