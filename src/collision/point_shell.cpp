// The point-shell queries (collision.hpp): a deformable part's masses against a rigid part's
// signed distance field, in full or from what the pair's last query found.
#include "collision/pair_query.hpp"
#include "core/lanes256.hpp"
#include "flexfit/distance_field.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace flexfit {
using namespace detail;
namespace {

// The masses a query samples, gathered first and sampled together (SignedDistanceField::
// sampleMany: four a vector), then turned into contacts in the order they were gathered, so
// the contacts come in the same order as sampling them one at a time.
class MassSampler {
public:
    MassSampler(std::uint32_t idA, const Part& a, const SignedDistanceField& field, std::uint32_t idB, const Part& b,
                const RelativePose& bInA, std::vector<Contact>& contacts, QueryStats& stats)
        : idA_(idA), idB_(idB), a_(a), field_(field), b_(b), bInA_(bInA), ra_(a.pose().rotation.toRotationMatrix()),
          contacts_(contacts), stats_(stats), batch_(scratch()) {
        // One sampler at a time per thread: a second would clear the first one's queue.
        if (batch_.inUse) throw std::logic_error("point shell: a second MassSampler on one thread");
        batch_.inUse = true;
        batch_.masses.clear();
        batch_.points.clear();
    }
    ~MassSampler() { batch_.inUse = false; }
    MassSampler(const MassSampler&) = delete;
    MassSampler& operator=(const MassSampler&) = delete;

    Vec3 pointOf(Index m) const { return bInA_.apply(b_.state().positions[m]); }

    // Queues mass m at p (A's frame) for sampling, unless it cannot touch: a free vertex (no
    // surface to push) or outside the grid. Says which.
    enum class Queued { Yes, FreeVertex, OutsideGrid };
    Queued queue(Index m, const Vec3& p) {
        if (b_.model().topology.facesOf(m).empty()) return Queued::FreeVertex;
        ++stats_.candidatePairs;
        if (!field_.inGrid(p)) return Queued::OutsideGrid;
        ++stats_.exactTests;
        batch_.masses.push_back(m);
        batch_.points.push_back(p);
        return Queued::Yes;
    }

    // Samples the queued masses; a contact for each at <= 0. done(k, distance) sees the k-th
    // queued mass's sampled distance, in queuing order.
    template <class Done>
    void sampleQueued(Done done) {
        const std::size_t n = batch_.masses.size();
        batch_.samples.resize(n);
        field_.sampleMany(batch_.points, batch_.samples);
        std::size_t k = 0;
#if defined(FLEXFIT_LANES256)
        if (detail::lanesEnabled())
            for (; k + 4 <= n; k += 4) addFourContacts(k, done);
#endif
        for (; k < n; ++k) {
            const SignedDistanceField::Interpolated& s = batch_.samples[k];
            if (s.distance <= 0.0) addContact(batch_.masses[k], batch_.points[k], s);
            done(k, s.distance);
        }
    }

    std::size_t queuedCount() const { return batch_.masses.size(); }
    Index queuedMass(std::size_t k) const { return batch_.masses[k]; }
    const Vec3& queuedPoint(std::size_t k) const { return batch_.points[k]; }

private:
    struct Batch {
        std::vector<Index> masses;
        std::vector<Vec3> points;
        std::vector<SignedDistanceField::Interpolated> samples;
        bool inUse = false;
    };
    // This thread's batch, kept between queries so its capacity stays.
    static Batch& scratch() {
        thread_local Batch batch;
        return batch;
    }

#if defined(FLEXFIT_LANES256)
    // Queued samples k..k+3 as the scalar loop takes them (addContact, then done), the contacts'
    // points and normals 4 at a time by the same operations in the same order (lanes256.hpp).
    template <class Done>
    FLEXFIT_AVX2_LANES void addFourContacts(std::size_t k, Done& done) {
        using namespace detail::lanes;
        const SignedDistanceField::Interpolated* s = &batch_.samples[k];
        if (s[0].distance > 0.0 && s[1].distance > 0.0 && s[2].distance > 0.0 && s[3].distance > 0.0) {
            for (int j = 0; j < 4; ++j) done(k + std::size_t(j), s[j].distance);
            return;
        }
        const Lanes3 gradient = gather([&](int j) -> const Vec3& { return s[j].gradient; });
        const __m256d g = _mm256_sqrt_pd(dot(gradient, gradient));
        const Lanes3 point = add(rotate(broadcast(a_.pose().rotation), gather([&](int j) -> const Vec3& { return batch_.points[k + std::size_t(j)]; })),
                                 broadcast(a_.pose().translation));
        const Stored3 points = store(point), normals = store(negate(times(ra_, divide(gradient, g))));
        alignas(32) double norms[4];
        _mm256_store_pd(norms, g);
        for (int j = 0; j < 4; ++j) {
            const std::size_t q = k + std::size_t(j);
            if (s[j].distance <= 0.0) {
                if (norms[j] > 1e-9)
                    pushContact(batch_.masses[q], points[j], normals[j], s[j].distance);
                else
                    addContact(batch_.masses[q], batch_.points[q], s[j]);
            }
            done(q, s[j].distance);
        }
    }
#endif

    void pushContact(Index m, const Vec3& point, const Vec3& normal, double distance) {
        ++stats_.contacts;
        contacts_.push_back({idA_, idB_, 0, b_.model().topology.facesOf(m)[0], point, normal, -distance, m});
    }

    void addContact(Index m, const Vec3& p, const SignedDistanceField::Interpolated& s) {
        // The gradient is the outward normal (zero only on a symmetry plane of the field,
        // where the exact closest point decides).
        const double g = s.gradient.norm();
        const Vec3 outward = g > 1e-9 ? Vec3(s.gradient / g) : field_.query(p).normal;
        pushContact(m, a_.pose().apply(p), -(ra_ * outward), s.distance);
    }

    std::uint32_t idA_, idB_;
    const Part& a_;
    const SignedDistanceField& field_;
    const Part& b_;
    const RelativePose& bInA_;
    Eigen::Matrix3d ra_;
    std::vector<Contact>& contacts_;
    QueryStats& stats_;
    Batch& batch_;
};

// Walks B's rest-point tree depth first from `stack` (the root to begin), at most `budget`
// nodes: leaf(mass) for each leaf reached whose rest position may sample <= 0 when moved by up
// to `margin` from where `pose` puts it (the field's Lipschitz bound prunes the others). A
// subtree of at most `bucket` leaves that is not pruned is not descended: each of its leaves is
// reached, in the same order, and the caller prunes them on their own samples (the walk's
// nodes near the leaves prune few, and a sample 8 a vector costs a fraction of a node's test).
// Each leaf so reached counts as a node. The walk can stop and resume: it depends only on the
// pose, the margin and the stack. Returns the nodes visited.
template <class Leaf>
std::size_t walkRestPoints(const SignedDistanceField& field, const Bvh<Aabb>& restPoints, const RelativePose& pose, double margin,
                           std::vector<std::int32_t>& stack, std::size_t budget, std::size_t bucket, Leaf leaf) {
    const auto& nodes = restPoints.nodes();
    std::size_t visited = 0;
    while (!stack.empty() && visited < budget) {
        const std::int32_t n = stack.back();
        const auto& node = nodes[std::size_t(n)];
        stack.pop_back();
        ++visited;
        if (node.isLeaf()) {
            leaf(node.item);
            continue;
        }
        if (field.clearOf(pose.apply(node.volume.centre()), node.volume.halfExtents().norm() + margin)) continue;
        if (restPoints.itemCount(n) <= bucket) {  // its leaves, in the order a descent meets them
            for (std::int32_t k = n + 1; k < restPoints.subtreeEnd(n); ++k) {
                if (!nodes[std::size_t(k)].isLeaf()) continue;
                leaf(nodes[std::size_t(k)].item);
                ++visited;
            }
            continue;
        }
        stack.push_back(node.right);
        stack.push_back(node.left);
    }
    return visited;
}

// The coherent query's rest-mass list: a margin of kMarginCells cells of the field; a new
// list's walk starts once B's rest sphere has moved kShellWalkStart of the margin. While B
// moves, each query walks the rest of the last walk's nodes spread over kShellWalkSpread of the
// queries the old list still covers at the last query's motion but one, or over
// kShellWalkShare queries where that is more (at least kShellMinWalkNodes); at rest, 1 /
// kShellWalkShare of them (walkBudget). A walk the motion still outruns (an acceleration, or
// more than about 0.3 of the margin a query) is finished inside one query (walksAtOnce counts
// them).
// Measured on the ball-torus haptic scene: a walk of ~7,400 nodes costs ~45 ns a node; the
// ball leaves a margin in ~35 steps. With a fixed share alone, every walk of that scene after
// the first was outrun and finished at once (265 to 2,200 nodes in one step). With the share as
// a floor under the spread (before 2026-12-07), each walk took 16 queries, half of the contact
// steps walked ~460 nodes each (~22 us), and those steps were the whole in-contact tail; spread
// over 2/3 of the list's life, walks follow one another, nearly every step walks ~210 nodes,
// and the tail fell (bench/results/tail_repeats_haptic_1207.csv). Two thirds, not all, leaves a third of
// the list's life for an acceleration before a walk must finish at once. Listing subtrees of up
// to kShellWalkBucket masses whole (walkRestPoints) took the haptic scene's walking from 9.8 to
// about 7 us a contact step (4: 8.4 us; 16 and 32 within noise of 8), and the samples a step
// 1,559 -> 1,539 (the list keeps fewer masses).
constexpr double kMarginCells = 2.0;
constexpr double kShellWalkStart = 0.4;
constexpr std::size_t kShellWalkShare = 16;
constexpr std::size_t kShellMinWalkNodes = 128;
constexpr double kShellWalkSpread = 2.0 / 3.0;
// The walk's buckets: subtrees of at most this many masses, listed whole and pruned by their
// samples (walkRestPoints).
constexpr std::size_t kShellWalkBucket = 8;

// Nodes for this query's slice of the walk under way: at rest the share; moving, the rest of
// the last walk's nodes over kShellWalkSpread of the queries the list still covers at `speed`
// (motion a query) but one, or over kShellWalkShare of them (all but one when fewer): never a
// larger slice than the share or the list's remaining queries ask.
std::size_t walkBudget(const PointShellCoherence& c, double motion, double speed) {
    if (!(speed > 0.0)) return std::max(kShellMinWalkNodes, c.traversalCost / kShellWalkShare);
    const double covered = (c.margin - motion) / speed;  // queries the list still covers
    if (!(covered >= 2.0)) return std::numeric_limits<std::size_t>::max();  // the last one: finish
    const std::size_t left = c.traversalCost > c.walk.nodes ? c.traversalCost - c.walk.nodes : 0;
    const double queries = std::max(kShellWalkSpread * (covered - 1.0), std::min(covered - 1.0, double(kShellWalkShare)));
    return std::max(kShellMinWalkNodes, std::size_t(std::ceil(double(left) / queries)));
}

void startWalk(PointShellCoherence::Walk& w, const RelativePose& pose, double margin) {
    w.stack.assign(1, 0);
    w.masses.clear();
    w.pose = pose;
    w.margin = margin;
    w.nodes = 0;
    w.active = true;
}

// Advances the walk by up to `budget` nodes; true when it is complete. Each listed mass keeps
// the distance its rest position samples at the walk's pose, or a lower bound of it where the
// field's cell is not computed (sampleLowerBounds: a walk computes no node; a listed mass is
// only skipped on its distance, so a lower bound skips less, never wrongly). The leaves in the
// grid are sampled together after the slice (4 or 8 a vector); a leaf outside the grid, or
// whose distance stays clear over the walk's margin, is not listed: the list is used only
// while B has moved less than the margin, over which such a mass is skipped (the same contacts,
// in the same order, as listing it).
bool advanceWalk(PointShellCoherence::Walk& w, const SignedDistanceField& field, const Bvh<Aabb>& restPoints, std::size_t budget,
                 QueryStats& stats) {
    thread_local std::vector<Index> reached;  // in the grid, in walk order
    thread_local std::vector<Vec3> points;
    thread_local std::vector<double> samples;
    reached.clear();
    points.clear();
    const std::size_t visited = walkRestPoints(field, restPoints, w.pose, w.margin, w.stack, budget, kShellWalkBucket, [&](Index m) {
        const Vec3 p = w.pose.apply(restPoints.leafVolume(m).centre());
        ++stats.exactTests;
        if (field.inGrid(p)) {
            reached.push_back(m);
            points.push_back(p);
        }
    });
    samples.resize(points.size());
    field.sampleLowerBounds(points, samples);
    const double clearOverMargin = field.clearDistance(w.margin);
    for (std::size_t k = 0; k < reached.size(); ++k)
        if (!(samples[k] > clearOverMargin)) w.masses.push_back({reached[k], samples[k]});
    w.nodes += visited;
    stats.volumeTests += visited;
    return w.stack.empty();
}

void takeWalk(PointShellCoherence& c) {
    c.restMasses.swap(c.walk.masses);
    c.pose = c.walk.pose;
    c.margin = c.walk.margin;
    c.traversalCost = c.walk.nodes;
    c.walk.active = false;
    c.valid = true;
    ++c.traversals;
}

#if defined(FLEXFIT_LANES256)
// The moving masses' skip test 4 at a time (each point turned into A's frame and its squared
// distance to its last sample, by the same operations as the scalar loop: lanes256.hpp);
// sampleMoved(m, p) for each mass not skipped, in order. Returns how many masses it took (a
// multiple of 4).
template <class SampleMoved>
FLEXFIT_AVX2_LANES std::size_t sampleMovedFours(std::span<const Index> moving, const Part& b, const RelativePose& bInA,
                                                const PointShellCoherence& c, SampleMoved& sampleMoved) {
    using namespace detail::lanes;
    const Lanes3 translation = broadcast(bInA.translation);
    const Vec3Array& positions = b.state().positions;
    const std::size_t n = moving.size() / 4 * 4;
    for (std::size_t i = 0; i < n; i += 4) {
        const Index* four = &moving[i];
        const Lanes3 p = add(times(bInA.rotation, gather([&](int j) -> const Vec3& { return positions[four[j]]; })), translation);
        const Lanes3 last = gather([&](int j) -> const Vec3& { return c.lastSamples[four[j]].point; });
        const Lanes3 moved = sub(p, last);
        const __m256d reach = _mm256_set_pd(c.lastSamples[four[3]].squaredReach, c.lastSamples[four[2]].squaredReach,
                                            c.lastSamples[four[1]].squaredReach, c.lastSamples[four[0]].squaredReach);
        const int skipped = _mm256_movemask_pd(_mm256_cmp_pd(dot(moved, moved), reach, _CMP_LT_OQ));
        if (skipped == 0xf) continue;
        const Stored3 points = store(p);
        for (int j = 0; j < 4; ++j)
            if (!(skipped & (1 << j))) sampleMoved(four[j], points[j]);
    }
    return n;
}
#endif

}  // namespace

void queryPointShell(std::uint32_t idA, const Part& a, const SignedDistanceField& fieldA, std::uint32_t idB, const Part& b,
                     const Bvh<Aabb>& restPointsB, std::vector<Contact>& contacts, QueryStats& stats) {
    const RelativePose bInA = relativePose(a, b);
    MassSampler sampler(idA, a, fieldA, idB, b, bInA, contacts, stats);
    for (Index m : b.movingMasses()) sampler.queue(m, sampler.pointOf(m));
    // The masses at rest, through the tree of rest positions (their current positions).
    if (!restPointsB.empty()) {
        std::vector<std::int32_t> stack(1, 0);
        stats.volumeTests += walkRestPoints(fieldA, restPointsB, bInA, 0.0, stack, std::numeric_limits<std::size_t>::max(), 1, [&](Index m) {
            if (!b.region().moves(m)) sampler.queue(m, sampler.pointOf(m));
        });
    }
    sampler.sampleQueued([](std::size_t, double) {});
}

void queryPointShellCoherent(std::uint32_t idA, const Part& a, const SignedDistanceField& fieldA, std::uint32_t idB, const Part& b,
                             const Bvh<Aabb>& restPointsB, const Sphere& restSphereB, PointShellCoherence& c,
                             std::vector<Contact>& contacts, QueryStats& stats) {
    const RelativePose bInA = relativePose(a, b);
    MassSampler sampler(idA, a, fieldA, idB, b, bInA, contacts, stats);
    const std::size_t massCount = b.model().massCount();
    if (c.lastSamples.size() != massCount) c.lastSamples.assign(massCount, {});  // none yet
    // Moving masses: skipped while they stay closer to their last sample than it was far from
    // the surface (slope sqrt(3)); any other is sampled, and that sample kept.
    const auto sampleMoved = [&](Index m, const Vec3& p) {
        // Not sampled: a free vertex never touches; one outside the grid is not sampled again
        // until it can have entered it (the margin covers rounding in the two squares).
        PointShellCoherence::LastSample& last = c.lastSamples[m];
        switch (sampler.queue(m, p)) {
            case MassSampler::Queued::Yes: break;
            case MassSampler::Queued::FreeVertex: last = {p, std::numeric_limits<double>::infinity()}; break;
            case MassSampler::Queued::OutsideGrid: last = {p, fieldA.squaredDistanceToGrid(p) * (1.0 - 1e-9)}; break;
        }
    };
    const std::span<const Index> moving = b.movingMasses();
    std::size_t i = 0;
#if defined(FLEXFIT_LANES256)
    if (detail::lanesEnabled()) i = sampleMovedFours(moving, b, bInA, c, sampleMoved);
#endif
    for (; i < moving.size(); ++i) {
        const Index m = moving[i];
        const Vec3 p = sampler.pointOf(m);
        const PointShellCoherence::LastSample& last = c.lastSamples[m];
        if (!((p - last.point).squaredNorm() < last.squaredReach)) sampleMoved(m, p);
    }
    const std::size_t movingQueued = sampler.queuedCount();
    // Masses at rest: those the list's walk reached with the margin, while B's rest sphere has
    // moved less than it since that walk's pose; each skipped while its sample there stays
    // clear over that motion.
    const auto keepMovingSamples = [&](std::size_t k, double distance) {
        if (k >= movingQueued) return;
        c.lastSamples[sampler.queuedMass(k)] = {sampler.queuedPoint(k), fieldA.squaredClearReach(distance)};
    };
    if (restPointsB.empty()) return sampler.sampleQueued(keepMovingSamples);
    const double margin = kMarginCells * fieldA.cellSize();
    auto motionSince = [&](const RelativePose& pose) { return relativeMotion(pose, bInA, restSphereB); };
    double motion = c.valid ? motionSince(c.pose) : std::numeric_limits<double>::infinity();
    const double speed = c.valid ? motionSince(c.lastQuery) : 0.0;
    c.lastQuery = bInA;
    if (!(motion <= c.margin)) {
        // The list no longer covers: finish the walk under way if it covers now, else walk anew.
        if (!(c.walk.active && motionSince(c.walk.pose) <= c.walk.margin)) startWalk(c.walk, bInA, margin);
        c.walksAtOnce += c.valid;  // the first walk of all has nothing to be spread over
        advanceWalk(c.walk, fieldA, restPointsB, std::numeric_limits<std::size_t>::max(), stats);
        takeWalk(c);
        motion = motionSince(c.pose);
    } else {
        if (!c.walk.active && motion > kShellWalkStart * c.margin) startWalk(c.walk, bInA, margin);
        const std::size_t budget = walkBudget(c, motion, speed);
        const bool whole = budget == std::numeric_limits<std::size_t>::max() && c.walk.nodes == 0;  // started now, no query to spread over
        if (c.walk.active && advanceWalk(c.walk, fieldA, restPointsB, budget, stats)) {
            c.walksAtOnce += whole;
            if (motionSince(c.walk.pose) <= c.walk.margin) {
                takeWalk(c);
                motion = motionSince(c.pose);
            } else {
                c.walk.active = false;  // outrun: the next query walks at once
            }
        }
    }
    const double clearAbove = fieldA.clearDistance(motion);  // staysClear(distance, motion), once
    for (const auto& [m, distance] : c.restMasses) {
        if (distance > clearAbove || b.region().moves(m)) continue;
        sampler.queue(m, sampler.pointOf(m));
    }
    sampler.sampleQueued(keepMovingSamples);
}

}  // namespace flexfit
