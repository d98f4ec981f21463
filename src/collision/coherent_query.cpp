// The coherent pair query (collision.hpp, queryPairCoherent): the pair's candidates from its
// last traversal, kept while the motion since stays within their margin.
#include "collision/pair_query.hpp"

#include <limits>
#include <tuple>

namespace flexfit {
using namespace detail;

namespace {

// Margins of the coherent query, as shares of the smaller mean leaf size: the first one, and
// the range an adapted one stays in (wider margins made traversals, the tail of a step, cost
// more than they saved: measured on the ball-torus scenes). The margin adapts so that the
// extra tests motion brings cost about what a traversal does: a traversal's node tests
// against the candidates tested since beyond those tested right after it. Candidates are taken
// again once that excess has cost kScanBudget traversals, with a margin of twice the motion
// seen (at most half the old one); when the motion leaves the margin first, with twice it
// (unless the excess already spent half its budget). The queries between two traversals then
// cost at most about (1 + kScanBudget) traversals; a pair at rest tests no excess and never
// traverses again.
constexpr double kFirstMarginShare = 0.02;
constexpr double kMinMarginShare = 1e-4;
constexpr double kMaxMarginShare = 0.05;
constexpr double kScanBudget = 1.0;
// When the motion outruns the widest margin within a query (a part deforming fast), taking
// candidates costs more than a plain traversal and saves nothing: this many queries are
// answered by plain traversals before candidates are tried again (measured: a tool pressed
// into a 60,000-face part whose zone moves every step, 80 against 62 us a step).
constexpr std::uint32_t kPlainQueries = 16;

// B's leaves as a ball metric: a box leaf within its earlier box grown by d along each axis is
// within sqrt(3) d of it.
double ballDrift(const PartCollider& collider, double drift) {
    return collider.kind() == BoundingVolumeKind::Aabb ? std::sqrt(3.0) * drift : drift;
}

// How far B's frame has moved in A's since the candidates were taken (for points of B's
// bounding sphere), or infinity when they cannot be used.
double motionSince(const PartCollider& colliderA, const PartCollider& colliderB, const RelativePose& bInA, const PairCoherence& c) {
    if (!c.valid || c.generationA != colliderA.generation() || c.generationB != colliderB.generation())
        return std::numeric_limits<double>::infinity();
    return relativeMotion(c.pose, bInA, colliderB.localSphere());
}

// How far A's frame has moved in B's (for points of A's bounding sphere); the candidates are
// valid (motionSince is finite).
double motionOfA(const RelativePose& bInA, const PartCollider& colliderA, const PairCoherence& c) {
    const Eigen::Matrix3d before = c.pose.rotation.transpose(), now = bInA.rotation.transpose();
    return relativeMotion(RelativePose(before, -(before * c.pose.translation)), RelativePose(now, -(now * bInA.translation)),
                          colliderA.localSphere());
}

bool scansSpentBudget(const PairCoherence& c) { return double(c.scanCost) > kScanBudget * double(c.traversalCost); }

double maxMargin(const PartCollider& colliderA, const PartCollider& colliderB) {
    return kMaxMarginShare * std::min(colliderA.leafScale(), colliderB.leafScale());
}

double nextMargin(const PartCollider& colliderA, const PartCollider& colliderB, double slack, const PairCoherence& c) {
    const double scale = std::min(colliderA.leafScale(), colliderB.leafScale());
    if (!c.valid || !std::isfinite(slack)) return c.margin > 0.0 ? std::min(c.margin, maxMargin(colliderA, colliderB)) : kFirstMarginShare * scale;
    double margin = c.margin;
    if (scansSpentBudget(c))
        margin = std::min(2.0 * slack, 0.5 * c.margin);
    else if (double(c.scanCost) < 0.5 * kScanBudget * double(c.traversalCost))
        margin = 2.0 * c.margin;
    return std::clamp(margin, kMinMarginShare * scale, maxMargin(colliderA, colliderB));
}

template <class BA, class BB>
void takeCandidates(const Bvh<BA>& bvhA, const Bvh<BB>& bvhB, const PartCollider& colliderA, const PartCollider& colliderB,
                    const RelativePose& bInA, double margin, LeafPairTester& tester, PairCoherence& c, QueryStats& stats) {
    c.candidates.clear();
    // A pair separated by more than the margin stays so while the candidates are used: by a
    // plane of A's face (A rigid), by the plane of B's face, or along a separating axis of the
    // two triangles (the dearest, tried last).
    auto record = [&](Index fa, Index fb) {
        double separation = tester.separationByA(fa, fb, margin);
        if (separation > margin) return;
        separation = std::max(separation, tester.separationByB(fa, fb));
        if (separation > margin) return;
        separation = std::max(separation, tester.separationOfTriangles(fa, fb));
        if (separation <= margin) c.candidates.push_back({fa, fb, separation});
    };
    auto beyondMargin = [&](Index fa, const auto& volumeB) { return tester.prunesBeyond(fa, volumeB, margin); };
    QueryStats traversal;
    traverse(bvhA, bvhB, bInA, traversal, record, beyondMargin, margin);
    stats.volumeTests += traversal.volumeTests;
    c.traversalCost = traversal.volumeTests;
    c.scanCost = 0;
    std::sort(c.candidates.begin(), c.candidates.end(),
              [](const PairCoherence::Candidate& x, const PairCoherence::Candidate& y) { return std::tie(x.faceA, x.faceB) < std::tie(y.faceA, y.faceB); });
    c.pose = bInA;
    c.margin = margin;
    c.driftA = colliderA.drift();
    c.driftB = colliderB.drift();
    c.vertexDriftA = colliderA.vertexDrift();
    c.vertexDriftB = colliderB.vertexDrift();
    c.generationA = colliderA.generation();
    c.generationB = colliderB.generation();
    c.queriesSince = 0;
    c.valid = true;
    ++c.traversals;
}

// Tests the candidates as the full query tests its leaf pairs; those whose separation exceeds
// `reach` cannot touch and are skipped.
template <class BA, class BB>
void scanCandidates(const Bvh<BA>& bvhA, const Bvh<BB>& bvhB, const RelativePose& bInA, double reach, LeafPairTester& tester,
                    PairCoherence& c, QueryStats& stats) {
    c.tested = 0;
    c.overlapping = 0;
    for (const PairCoherence::Candidate& k : c.candidates) {
        if (k.separation > reach) continue;
        ++c.tested;
        if (!overlap(bvhA.leafVolume(k.faceA), bvhB.leafVolume(k.faceB), bInA)) continue;
        ++c.overlapping;
        tester(k.faceA, k.faceB);
    }
    stats.volumeTests += c.tested;
    stats.candidatePairs += c.overlapping;
    if (c.queriesSince == 0)
        c.testedAfterTraversal = c.tested;
    else
        c.scanCost += c.tested - std::min(c.tested, c.testedAfterTraversal);
}

}  // namespace

void queryPairCoherent(std::uint32_t idA, const Part& a, const PartCollider& colliderA, std::uint32_t idB, const Part& b,
                       const PartCollider& colliderB, ExactTest test, PairCoherence& coherence, std::vector<Contact>& contacts,
                       QueryStats& stats) {
    requireBuiltFor(colliderA, colliderB, test);
    if (coherence.plainQueriesLeft > 0) {
        --coherence.plainQueriesLeft;
        return queryPair(idA, a, colliderA, idB, b, colliderB, test, contacts, stats);
    }
    const RelativePose bInA = relativePose(a, b);
    LeafPairTester tester(idA, a, colliderA, idB, b, test, bInA, contacts, stats);
    dispatch(colliderA, colliderB, [&](const auto& bvhA, const auto& bvhB) {
        // A's leaves grown by the margin cover A's drift and the motion of B's leaves. A candidate
        // separated by a gap (a plane of A's face, A rigid; the plane of B's face; or an axis)
        // stays so while the two faces' vertices move, relative to each other, less than it:
        // A's by its own moves, B's by the relative motion in A's frame and its own moves (for
        // B's plane, the other way round: A's points in B's frame).
        const double motion = motionSince(colliderA, colliderB, bInA, coherence);
        const double moveA = colliderA.vertexDrift() - coherence.vertexDriftA, moveB = colliderB.vertexDrift() - coherence.vertexDriftB;
        const double reach = std::max(motion, motionOfA(bInA, colliderA, coherence)) + moveA + moveB;
        const double leaves = motion + (colliderA.drift() - coherence.driftA) + ballDrift(colliderB, colliderB.drift() - coherence.driftB);
        // Candidates separated by more than the margin were dropped: the reach stays within it.
        const double slack = std::max(leaves, reach);
        if (!(slack <= coherence.margin) && coherence.valid && coherence.queriesSince <= 1 &&
            coherence.margin >= maxMargin(colliderA, colliderB)) {
            coherence.valid = false;  // outrun: plain traversals for a while
            coherence.plainQueriesLeft = kPlainQueries;
            ++coherence.plainSpells;
            return queryPair(idA, a, colliderA, idB, b, colliderB, test, contacts, stats);
        }
        if (!(slack <= coherence.margin) || scansSpentBudget(coherence)) {
            takeCandidates(bvhA, bvhB, colliderA, colliderB, bInA, nextMargin(colliderA, colliderB, slack, coherence), tester, coherence, stats);
            return scanCandidates(bvhA, bvhB, bInA, 0.0, tester, coherence, stats);
        }
        scanCandidates(bvhA, bvhB, bInA, reach, tester, coherence, stats);
    });
    ++coherence.queriesSince;
}

}  // namespace flexfit
