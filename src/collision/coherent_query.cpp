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
// When a list is outrun with the widest margin within kShortLived queries of its pose (a part
// deforming fast), taking lists costs more than it saves: at least the next kPlainQueries
// queries are plain traversals (measured: a tool pressed into a 60,000-face part whose zone
// moves every step, 80 against 62 us a step without them), and the following ones too while
// the motion from query to query would outrun a list of the widest margin within
// kSlowedQueries (twice kShortLived: no flapping at the edge).
constexpr std::uint32_t kPlainQueries = 16;
constexpr std::uint64_t kShortLived = 4;
constexpr std::uint64_t kSlowedQueries = 2 * kShortLived;

// B's leaves' growth as a ball metric: a box leaf within its earlier box grown by d along each
// axis is within sqrt(3) d of it.
double ballGrowth(const PartCollider& collider, double vertexMove) {
    const double growth = collider.leafGrowth(vertexMove);
    return collider.kind() == BoundingVolumeKind::Aabb ? std::sqrt(3.0) * growth : growth;
}

// How far B's frame has moved in A's since the take's pose (for points of B's bounding sphere),
// or infinity when its hierarchies were rebuilt since.
double motionSince(const PartCollider& colliderA, const PartCollider& colliderB, const RelativePose& bInA, const PairCoherence::Take& t) {
    if (t.generationA != colliderA.generation() || t.generationB != colliderB.generation()) return std::numeric_limits<double>::infinity();
    return relativeMotion(t.pose, bInA, colliderB.localSphere());
}

// How far A's frame has moved in B's (for points of A's bounding sphere).
double motionOfA(const RelativePose& bInA, const PartCollider& colliderA, const PairCoherence::Take& t) {
    const Eigen::Matrix3d before = t.pose.rotation.transpose(), now = bInA.rotation.transpose();
    return relativeMotion(RelativePose(before, -(before * t.pose.translation)), RelativePose(now, -(now * bInA.translation)),
                          colliderA.localSphere());
}

// What a take must still cover now: `leaves` for its leaf pairs (A's grown leaves hold A's
// drift and B's leaves' motion), `reach` for its gaps (the faces' vertices' largest relative
// move since). Both within the margin: it answers exactly.
struct Coverage {
    double leaves = 0.0, reach = 0.0;
    double slack() const { return std::max(leaves, reach); }
};

Coverage coverageOf(const PartCollider& colliderA, const PartCollider& colliderB, const RelativePose& bInA, const PairCoherence::Take& t) {
    const double motion = motionSince(colliderA, colliderB, bInA, t);
    if (!std::isfinite(motion)) return {motion, motion};
    const double moveA = colliderA.vertexDrift() - t.vertexDriftA, moveB = colliderB.vertexDrift() - t.vertexDriftB;
    return {motion + colliderA.leafGrowth(moveA) + ballGrowth(colliderB, moveB), std::max(motion, motionOfA(bInA, colliderA, t)) + moveA + moveB};
}

bool scansSpentBudget(const PairCoherence& c) { return double(c.scanCost) > kScanBudget * double(c.list.nodes); }

double maxMargin(const PartCollider& colliderA, const PartCollider& colliderB) {
    return kMaxMarginShare * std::min(colliderA.leafScale(), colliderB.leafScale());
}

double nextMargin(const PartCollider& colliderA, const PartCollider& colliderB, double slack, const PairCoherence& c) {
    const double scale = std::min(colliderA.leafScale(), colliderB.leafScale());
    if (!c.valid || !std::isfinite(slack)) return c.list.margin > 0.0 ? std::min(c.list.margin, maxMargin(colliderA, colliderB)) : kFirstMarginShare * scale;
    double margin = c.list.margin;
    if (scansSpentBudget(c))
        margin = std::min(2.0 * slack, 0.5 * c.list.margin);
    else if (double(c.scanCost) < 0.5 * kScanBudget * double(c.list.nodes))
        margin = 2.0 * c.list.margin;
    return std::clamp(margin, kMinMarginShare * scale, maxMargin(colliderA, colliderB));
}

// What a take assumes of the pair now: its relative pose, the colliders' drifts and generations.
void notePose(PairCoherence::Take& t, const PartCollider& colliderA, const PartCollider& colliderB, const RelativePose& bInA) {
    t.pose = bInA;
    t.vertexDriftA = colliderA.vertexDrift();
    t.vertexDriftB = colliderB.vertexDrift();
    t.generationA = colliderA.generation();
    t.generationB = colliderB.generation();
}

// Begins a take at the current pose and state.
void startTake(PairCoherence::Take& t, const PartCollider& colliderA, const PartCollider& colliderB, const RelativePose& bInA, double margin,
               std::uint64_t query) {
    t.startQuery = query;
    t.candidates.clear();
    t.stack.assign(1, {0, 0});
    t.nodes = 0;
    t.settledUpTo = 0;
    t.sorted = false;
    t.margin = margin;
    notePose(t, colliderA, colliderB, bInA);
}

// A candidate's dearer gaps, now: A's face beyond the plane of B's, or the faces apart along a
// separating axis. A gap g now means no touch while the faces move less than g from now on;
// from the take on, they have moved at most `reach` until now, so they move less than g from
// now on while their motion since the take stays below g - reach: that is the take's bound.
// The separating axes are skipped once the plane's gap already clears the list's margin.
void settle(PairCoherence::Candidate& k, double reach, double margin, LeafPairTester& tester) {
    double now = tester.separationByB(k.faceA, k.faceB);
    if (now - reach <= margin) now = std::max(now, tester.separationOfTriangles(k.faceA, k.faceB, margin + reach));
    k.separation = std::max(k.separation, now - reach);
    k.settled = true;
}

// Candidates settled beyond the margin: no scan of the list reaches them.
void dropUnreachable(PairCoherence::Take& t) {
    std::erase_if(t.candidates, [&](const PairCoherence::Candidate& k) { return k.settled && k.separation > t.margin; });
}

// A settle counts as this many node pairs of a walk's budget. Measured in the rigid ball's walks
// on the rigid mouth: a slice of 1,087 node pairs took about 60 µs, one of 272 settles 35-40 µs,
// so a settle costs about 2.5 node pairs of a walk; 4 keeps settle slices the cheaper.
constexpr std::size_t kSettleNodes = 4;

// Goes on with the take for up to `budget` node pairs, at its pose; true once complete.
// `tester` must be at the take's pose. A pair whose faces lie farther apart than the margin
// stays so while the take is used. With A rigid, the take measures the cheap gap only (beyond a
// plane of A's face); the dearer ones (by B's plane, along the triangles' separating axes)
// follow the traversal when the take is walked (`settling`), slice by slice, and a take finished
// at once leaves them to the scans that reach each pair (a take computing them for every near
// pair cost 3x its plain traversal: a rigid ball coming to rest on the rigid mouth, 2,468 near
// pairs, 236 within the margin by all three gaps). With A deforming there is no cheap gap:
// every near pair would wait, and the scans of a tool pressed into a part paid more than the
// take saved (Wuson x1, tools/tool_press.py, 5 rounds in development: 19.8 against 27.5 us a
// step's narrow phase), so the take settles each.
template <class BA, class BB>
bool advanceTake(PairCoherence::Take& t, std::size_t budget, const Bvh<BA>& bvhA, const Bvh<BB>& bvhB, LeafPairTester& tester,
                 QueryStats& stats, bool settling) {
    const double margin = t.margin;
    const bool deferred = tester.gapsByA();
    auto record = [&](Index fa, Index fb) {
        PairCoherence::Candidate k{fa, fb, tester.planeGap(fa, fb, margin), false};
        if (k.separation > margin) return;
        if (!deferred) settle(k, 0.0, margin, tester);
        if (k.separation <= margin) t.candidates.push_back(k);
    };
    auto beyondMargin = [&](Index fa, const auto& volumeB) { return tester.prunesBeyond(fa, volumeB, margin); };
    auto beyondMarginByB = [&](Index fb, const auto& volumeA) { return tester.prunesBeyondByB(fb, volumeA, margin); };
    QueryStats walk;
    if (!bvhA.empty() && !bvhB.empty())
        traverseFrom(t.stack, budget, bvhA, bvhB, t.pose, walk, record, beyondMargin, margin, beyondMarginByB);
    else t.stack.clear();
    stats.volumeTests += walk.volumeTests;
    t.nodes += walk.volumeTests;
    if (!t.stack.empty()) return false;
    if (deferred) {  // the record settled nothing: settle now, or leave all to the scans
        if (!settling) return true;  // in traversal order: sorting every near pair would cost the scan more than it saves
        for (std::size_t spent = walk.volumeTests; t.settledUpTo < t.candidates.size(); ++t.settledUpTo, spent += kSettleNodes) {
            if (spent >= budget) return false;
            settle(t.candidates[t.settledUpTo], 0.0, margin, tester);
        }
        dropUnreachable(t);
    }
    std::sort(t.candidates.begin(), t.candidates.end(),
              [](const PairCoherence::Candidate& x, const PairCoherence::Candidate& y) { return std::tie(x.faceA, x.faceB) < std::tie(y.faceA, y.faceB); });
    t.sorted = true;
    return true;
}

// The next take becomes the list.
void useNext(PairCoherence& c) {
    std::swap(c.list, c.next);
    c.walking = false;
    c.valid = true;
    c.queriesSince = 0;
    c.scanCost = 0;
    ++c.traversals;
}

// Tests the list's candidates as the full query tests its leaf pairs; those whose separation
// exceeds `reach` cannot touch and are skipped (settled first when their take's bound alone
// does not skip them). The tests beyond those of the list's first query are what the motion
// since added (scanCost). The contacts come in (faceA, faceB) order, as the full query's (from
// a sorted list, or sorted after).
template <class BA, class BB>
void scanCandidates(const Bvh<BA>& bvhA, const Bvh<BB>& bvhB, const RelativePose& bInA, double reach, LeafPairTester& tester,
                    PairCoherence& c, std::vector<Contact>& contacts, QueryStats& stats) {
    const std::size_t first = contacts.size();
    std::size_t tested = 0;
    bool unreachable = false;
    for (PairCoherence::Candidate& k : c.list.candidates) {
        if (k.separation > reach) continue;
        if (!k.settled) {
            settle(k, reach, c.list.margin, tester);
            unreachable = unreachable || k.separation > c.list.margin;
            if (k.separation > reach) continue;
        }
        ++tested;
        if (!overlap(bvhA.leafVolume(k.faceA), bvhB.leafVolume(k.faceB), bInA)) continue;
        ++stats.candidatePairs;
        tester(k.faceA, k.faceB);
    }
    stats.volumeTests += tested;
    if (unreachable) dropUnreachable(c.list);
    if (!c.list.sorted) sortContacts(contacts, first);
    if (c.queriesSince == 0)
        c.testedAfterTraversal = tested;
    else
        c.scanCost += tested - std::min(tested, c.testedAfterTraversal);
}

// In plain traversals: whether this query is to be one as well (then noted as the last): for
// the first kPlainQueries, and after while the leaves' motion since the last one (coverageOf,
// infinite once a hierarchy was rebuilt, which ends them) would outrun a list of the widest
// margin within kSlowedQueries queries.
bool stillTooFast(const PartCollider& colliderA, const PartCollider& colliderB, const RelativePose& bInA, PairCoherence& c) {
    const double step = coverageOf(colliderA, colliderB, bInA, c.lastPlain).leaves;
    ++c.plainQueries;
    c.plain = std::isfinite(step) && (c.plainQueries < kPlainQueries || step * double(kSlowedQueries) > maxMargin(colliderA, colliderB));
    if (c.plain) notePose(c.lastPlain, colliderA, colliderB, bInA);
    return c.plain;
}

// The next list's walk: started at kWalkStart of the margin, 1 / kWalkShare of the last
// traversal's volume tests a query (at least kMinWalkNodes).
constexpr double kWalkStart = 0.25;
constexpr std::size_t kWalkShare = 8;
constexpr std::size_t kMinWalkNodes = 256;

}  // namespace

void queryPairCoherent(std::uint32_t idA, const Part& a, const PartCollider& colliderA, std::uint32_t idB, const Part& b,
                       const PartCollider& colliderB, ExactTest test, PairCoherence& c, std::vector<Contact>& contacts,
                       QueryStats& stats) {
    requireBuiltFor(colliderA, colliderB, test);
    const RelativePose bInA = relativePose(a, b);
    const auto plainTraversal = [&] {
        ++c.plainTraversals;
        queryPair(idA, a, colliderA, idB, b, colliderB, test, contacts, stats);
    };
    if (c.plain && stillTooFast(colliderA, colliderB, bInA, c)) return plainTraversal();
    Coverage now = c.valid ? coverageOf(colliderA, colliderB, bInA, c.list) : Coverage{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    const bool outrun = !(now.slack() <= c.list.margin);
    ++c.queries;
    // Outrun with the widest margin by the motion of a few queries since the list's pose.
    if (outrun && c.valid && c.queries - c.list.startQuery <= kShortLived && c.list.margin >= maxMargin(colliderA, colliderB)) {
        c.valid = c.walking = false;  // the motion outruns the widest margin: plain traversals while it does
        c.plain = true;
        c.plainQueries = 0;
        notePose(c.lastPlain, colliderA, colliderB, bInA);
        return plainTraversal();
    }
    dispatch(colliderA, colliderB, [&](const auto& bvhA, const auto& bvhB) {
        // The next list: finished now when the current one no longer covers (if it covers, else
        // taken afresh) or its tests spent their budget; else walked a slice, from kWalkStart of
        // the margin.
        const bool atOnce = outrun || scansSpentBudget(c);
        if (atOnce && c.walking && !(coverageOf(colliderA, colliderB, bInA, c.next).slack() <= c.next.margin)) c.walking = false;
        if (!c.walking && (atOnce || now.slack() > kWalkStart * c.list.margin)) {
            startTake(c.next, colliderA, colliderB, bInA, nextMargin(colliderA, colliderB, now.slack(), c), c.queries);
            c.walking = true;
        }
        if (c.walking) {
            const std::size_t budget = atOnce ? std::numeric_limits<std::size_t>::max() : std::max(kMinWalkNodes, c.list.nodes / kWalkShare);
            std::vector<Contact> none;
            // The walker and the query's tester (at the current pose) share the thread's
            // rest-plane scratch: the walker is gone before the tester is made. (A scratch of
            // its own was cold when a rigid pair first met: the ball's first contact on the
            // rigid mouth took its list in 330-400 µs, a warm scratch 55-65 µs.)
            LeafPairTester walker(idA, a, colliderA, idB, b, colliderB, test, c.next.pose, none, stats);
            if (advanceTake(c.next, budget, bvhA, bvhB, walker, stats, !atOnce)) {
                const Coverage next = coverageOf(colliderA, colliderB, bInA, c.next);
                if (next.slack() <= c.next.margin) {
                    useNext(c);
                    now = next;
                } else {
                    c.walking = false;  // outrun while walking: the next query takes one at once
                }
            }
        }
        if (!(now.slack() <= c.list.margin)) {  // only when a list taken at once was outrun as it was taken: never at one pose
            c.valid = false;
            return plainTraversal();
        }
        LeafPairTester tester(idA, a, colliderA, idB, b, colliderB, test, bInA, contacts, stats);
        tester.skipPlanesOfB();
        scanCandidates(bvhA, bvhB, bInA, now.reach, tester, c, contacts, stats);
        ++c.scans;
    });
    ++c.queriesSince;
}

}  // namespace flexfit
