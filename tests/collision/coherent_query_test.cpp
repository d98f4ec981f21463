// The coherent pair query (coherent_query.cpp) against the full query it stands for, contact for
// contact (faces, point, normal, depth, order), and against brute force over every face pair,
// on random motion sequences: rigid pairs, a rigid tool over a deforming part, two deforming
// parts; both bounding volumes and both exact tests. Then what makes it coherent: a pair at
// rest stops traversing, a moving pair traverses far less often than it queries, and a
// rebuilt hierarchy is never answered from the old candidates.
#include "collision/pair_query.hpp"
#include "collision/triangle_queries.hpp"
#include "flexfit/flexfit.hpp"
#include "same_contacts.hpp"
#include "test_bodies.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <tuple>

using namespace flexfit;
using flexfit::testing::expectSameContacts;
using flexfit::testing::rigidPart;

namespace {

// Face pairs in contact by testing every pair (no hierarchy).
std::set<std::pair<Index, Index>> bruteForceContacts(const Part& a, const Part& b, ExactTest test) {
    const Eigen::Matrix3d ra = a.pose().rotation.toRotationMatrix(), rb = b.pose().rotation.toRotationMatrix();
    const RelativePose bInA(ra.transpose() * rb, ra.transpose() * (b.pose().translation - a.pose().translation));
    const auto& pa = a.state().positions;
    const auto& pb = b.state().positions;
    std::set<std::pair<Index, Index>> out;
    for (Index fa = 0; fa < a.model().faceCount(); ++fa)
        for (Index fb = 0; fb < b.model().faceCount(); ++fb) {
            const Face& x = a.model().mesh.faces[fa];
            const Face& y = b.model().mesh.faces[fb];
            const Triangle ty{bInA.apply(pb[y[0]]), bInA.apply(pb[y[1]]), bInA.apply(pb[y[2]])};
            const Sphere s = faceSphere(pa, x);
            const bool hit = test == ExactTest::SphereTriangle ? sphereTriangleContact(s.centre, s.radius, ty).has_value()
                                                               : intersectTriangles({pa[x[0]], pa[x[1]], pa[x[2]]}, ty).has_value();
            if (hit) out.insert({fa, fb});
        }
    return out;
}

using flexfit::testing::pairsOf;

// Where along a line of poses the full query's contacts end, by bisection: at(s) poses the
// parts; `inside` touches and `outside` does not. Returns the last `outside`, 2^-60 of the
// interval from the edge.
template <class At>
double contactEdge(At at, const Part& a, const PartCollider& ca, const Part& b, const PartCollider& cb, double inside,
                   double outside) {
    for (int i = 0; i < 60; ++i) {
        at(0.5 * (inside + outside));
        std::vector<Contact> full;
        QueryStats ignored;
        queryPair(0, a, ca, 1, b, cb, ExactTest::TriangleTriangle, full, ignored);
        (full.empty() ? outside : inside) = 0.5 * (inside + outside);
    }
    return outside;
}

// A small random rigid motion: a turn of up to `turn` radians about a random axis (about the
// part's origin) and a shift of up to `shift`; now and then (1 in 25) a jump ten times as large.
Pose nudged(const Pose& pose, std::mt19937& rng, double shift, double turn) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const double scale = std::uniform_int_distribution<int>(0, 24)(rng) == 0 ? 10.0 : 1.0;
    Pose next = pose;
    const Vec3 axis = Vec3(u(rng), u(rng), u(rng)).normalized();
    next.rotation = (Eigen::Quaterniond(Eigen::AngleAxisd(scale * turn * u(rng), axis)) * pose.rotation).normalized();
    next.translation += scale * shift * Vec3(u(rng), u(rng), u(rng));
    return next;
}

struct Variant {
    BoundingVolumeKind kind;
    ExactTest test;
    std::size_t leafGroup = detail::kDefaultLeafGroup;  // the traversals' (pair_query.hpp)
};

class CoherentQuery : public ::testing::TestWithParam<Variant> {
protected:
    void SetUp() override {
#if defined(__SANITIZE_ADDRESS__)
        // Sanitizer builds run ~20x slower: the default group size only (its traversals take
        // every code path the others do); the Release run checks every size.
        if (GetParam().leafGroup != detail::kDefaultLeafGroup) GTEST_SKIP() << "Release only: another group size";
#endif
    }
};

// Runs `steps` queries of the pair (a presses b): the coherent answer must be the full one,
// every step; every tenth step, also brute force's face pairs. Returns the traversals made.
struct PairRun {
    Part& a;
    Part& b;
    PartCollider ca, cb;
    ExactTest test;
    PairCoherence coherence;
    detail::ScopedLeafGroup group;

    PairRun(Part& a_, Part& b_, Variant v)
        : a(a_), b(b_), ca(a_, v.kind, v.test), cb(b_, v.kind, v.test), test(v.test), group(v.leafGroup) {}

    void refit() {
        for (auto [part, collider] : {std::pair{&a, &ca}, std::pair{&b, &cb}}) {
            collider->refit(*part, part->changedMasses());
            part->clearChangedMasses();
        }
    }
    std::size_t check(int step, bool bruteForce) {
        std::vector<Contact> coherent, full;
        QueryStats s1, s2;
        queryPairCoherent(0, a, ca, 1, b, cb, test, coherence, coherent, s1);
        queryPair(0, a, ca, 1, b, cb, test, full, s2);
        expectSameContacts(coherent, full, step);
        if (bruteForce) {
            EXPECT_EQ(pairsOf(coherent), bruteForceContacts(a, b, test)) << "step " << step;
        }
        return coherent.size();
    }
};

}  // namespace

TEST_P(CoherentQuery, RigidPairsInRandomMotionGetTheFullQuerysContacts) {
    // A level-2 sphere tumbling and drifting against the (rigid) container-mouth-like torus: 400
    // queries, small moves with occasional jumps.
    std::mt19937 rng(11);
    Part torus(buildPartModel(makeTorus(3.0, 1.0, 32, 16)), rigidPart());
    Part ball(buildPartModel(makeIcoSphere(1.5, 2)), rigidPart());
    ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(3.0, 2.2, 0.0)});
    PairRun run(torus, ball, GetParam());
    std::size_t contacts = 0;
    for (int step = 0; step < 400; ++step) {
        Pose next = nudged(ball.pose(), rng, 0.002, 0.002);
        // Stay near the tube: pulled back towards a point on it.
        next.translation += 0.05 * (Vec3(3.0, 2.0, 0.0) - next.translation);
        ball.setPose(next);
        contacts += run.check(step, step % 40 == 0);
    }
    EXPECT_GT(contacts, 0u);  // the sequence does touch
    EXPECT_LT(run.coherence.traversals, 400u / 3) << "the candidates are reused";
}

TEST_P(CoherentQuery, ARigidToolOverADeformingPartGetsTheFullQuerysContacts) {
    // A ball pressed into a torus while a zone there deforms (forces on the masses under it),
    // and the ball drifts and turns: the part's hierarchy refits every step.
    std::mt19937 rng(5);
    Part torus(buildPartModel(makeTorus(3.0, 1.0, 32, 16)));
    Part ball(buildPartModel(makeIcoSphere(1.0, 2)), rigidPart());
    const Index pressed = 0;  // a mass on the outer equator, at (4, 0, 0)
    ball.setPose(Pose{Eigen::Quaterniond::Identity(), torus.model().restPositions[pressed] + Vec3(0.9, 0.0, 0.0)});
    torus.openZone(ZoneSeed::mass(pressed), 2);
    PairRun run(ball, torus, GetParam());
    std::size_t contacts = 0;
    for (int step = 0; step < 200; ++step) {
        torus.applyForce(pressed, Vec3(-20.0, 0.0, 0.0));
        torus.step();
        ball.setPose(nudged(ball.pose(), rng, 0.004, 0.01));
        run.refit();
        contacts += run.check(step, step % 25 == 0);
    }
    EXPECT_GT(contacts, 0u);
    EXPECT_LT(run.coherence.traversals, 200u);
}

TEST_P(CoherentQuery, TwoDeformingPartsGetTheFullQuerysContacts) {
    // Two tori interlocked face to face, each with a zone pushed towards the other.
    std::mt19937 rng(9);
    const auto model = buildPartModel(makeTorus(3.0, 1.0, 24, 12));
    Part a(model), b(model);
    b.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(0.0, 1.9, 0.0)});
    const Index top = 3, bottom = 9;  // masses on the upper and lower rings of the tube (v = 90, 270 degrees)
    a.openZone(ZoneSeed::mass(top), 2);
    b.openZone(ZoneSeed::mass(bottom), 2);
    PairRun run(a, b, GetParam());
    std::size_t contacts = 0;
    for (int step = 0; step < 150; ++step) {
        a.applyForce(top, Vec3(0.0, 5.0, 0.0));
        b.applyForce(bottom, Vec3(0.0, -5.0, 0.0));
        a.step();
        b.step();
        b.setPose(nudged(b.pose(), rng, 0.002, 0.002));
        run.refit();
        contacts += run.check(step, step % 30 == 0);
    }
    EXPECT_GT(contacts, 0u);
}

INSTANTIATE_TEST_SUITE_P(VolumesAndTests, CoherentQuery,
                         ::testing::Values(Variant{BoundingVolumeKind::Aabb, ExactTest::TriangleTriangle},
                                           Variant{BoundingVolumeKind::Sphere, ExactTest::TriangleTriangle},
                                           Variant{BoundingVolumeKind::Aabb, ExactTest::SphereTriangle},
                                           Variant{BoundingVolumeKind::Aabb, ExactTest::TriangleTriangle, 1},
                                           Variant{BoundingVolumeKind::Sphere, ExactTest::TriangleTriangle, 8}),
                         [](const auto& variant) {
                             return std::string(toString(variant.param.kind)) + "_" + std::string(toString(variant.param.test)) + "_group" +
                                    std::to_string(variant.param.leafGroup);
                         });

TEST(CoherentQueryCost, APairAtRestStopsTraversing) {
    // A ball resting in the torus's hole: after a few queries, none traverses, and each
    // query tests a few dozen candidates, not the hierarchies.
    Part torus(buildPartModel(makeTorus(3.0, 1.0, 64, 32)), rigidPart());
    Part ball(buildPartModel(makeIcoSphere(2.2, 3)), rigidPart());
    ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(0.0, 1.0, 0.0)});
    PartCollider ct(torus, BoundingVolumeKind::Aabb), cb(ball, BoundingVolumeKind::Aabb);
    PairCoherence coherence;
    std::vector<Contact> contacts, full;
    QueryStats coherentStats, fullStats;
    for (int i = 0; i < 10; ++i) queryPairCoherent(0, torus, ct, 1, ball, cb, ExactTest::TriangleTriangle, coherence, contacts, coherentStats);
    const std::uint64_t settled = coherence.traversals;
    for (int i = 0; i < 100; ++i) {
        contacts.clear();
        coherentStats = {};
        queryPairCoherent(0, torus, ct, 1, ball, cb, ExactTest::TriangleTriangle, coherence, contacts, coherentStats);
    }
    queryPair(0, torus, ct, 1, ball, cb, ExactTest::TriangleTriangle, full, fullStats);
    EXPECT_EQ(coherence.traversals, settled);
    ASSERT_FALSE(contacts.empty());
    EXPECT_EQ(pairsOf(contacts), pairsOf(full));
    // What it costs: the candidates it tested against the full query's node visits.
    EXPECT_LT(coherentStats.volumeTests * 5, fullStats.volumeTests) << coherentStats.volumeTests << " vs " << fullStats.volumeTests;
}

TEST(CoherentQuery, AGapMeasuredAfterTheTakeCountsTheMotionBeforeIt) {
    // A candidate's dearer gaps are measured by the first query whose reach attains it, not at
    // the take: what bounds the take's gap is that gap less the motion since. A ball taken
    // apart from the torus (0.1 of the margin), moved away (0.3: its gaps measured there), then
    // back past the take's pose into contact (-0.05), all within the list's margin: the one
    // list answers, with the full query's contacts. Kept at the later gap alone (0.3 of the
    // margin against the 0.15 moved since the take), the contact pairs would be skipped.
    Part torus(buildPartModel(makeTorus(3.0, 1.0, 64, 32)), rigidPart());
    Part ball(buildPartModel(makeIcoSphere(1.0, 3)), rigidPart());
    PartCollider ct(torus, BoundingVolumeKind::Aabb), cb(ball, BoundingVolumeKind::Aabb);
    auto at = [&](double x) { ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(x, 0.0, 0.0)}); };
    auto full = [&] {
        std::vector<Contact> out;
        QueryStats ignored;
        queryPair(0, torus, ct, 1, ball, cb, ExactTest::TriangleTriangle, out, ignored);
        return out;
    };
    const double outside = contactEdge(at, torus, ct, ball, cb, 4.5, 5.5);  // where the ball meets the torus's outer side
    double margin = 0.0;
    {
        PairCoherence probe;
        std::vector<Contact> contacts;
        QueryStats stats;
        at(outside + 0.1);
        queryPairCoherent(0, torus, ct, 1, ball, cb, ExactTest::TriangleTriangle, probe, contacts, stats);
        margin = probe.list.margin;
    }
    ASSERT_GT(margin, 0.0);
    PairCoherence coherence;
    int step = 0;
    for (const double share : {0.1, 0.3, -0.05}) {
        at(outside + share * margin);
        std::vector<Contact> contacts;
        QueryStats stats;
        queryPairCoherent(0, torus, ct, 1, ball, cb, ExactTest::TriangleTriangle, coherence, contacts, stats);
        expectSameContacts(contacts, full(), step++);
        if (step == 1) {  // taken at once: the pairs wait for the scans to settle them
            EXPECT_FALSE(coherence.list.sorted);
            EXPECT_TRUE(std::any_of(coherence.list.candidates.begin(), coherence.list.candidates.end(),
                                    [](const PairCoherence::Candidate& k) { return !k.settled; }));
        }
        if (share < 0.0) {
            EXPECT_FALSE(contacts.empty());
        }
    }
    EXPECT_EQ(coherence.traversals, 1u) << "one list, taken by the first query, answers all three";
    EXPECT_FALSE(coherence.walking) << "no walk began: every motion stayed within a quarter of the margin";
}

TEST(CoherentQuery, AWalkedTakeSettlesItsPairsOverSeveralQueries) {
    // A rigid A's walked take settles its near pairs after its traversal, a slice of the walk's
    // budget a query (kSettleNodes each). A ball in the torus's hole drifting slowly up and down
    // through where it comes off the ring (a fiftieth of the margin a query; about 2,000 near
    // pairs a take): some walk must be seen between slices with pairs settled and pairs left,
    // every answer is the full query's, and each list in use after a walk has all its pairs
    // settled and sorted.
    Part torus(buildPartModel(makeTorus(3.0, 1.0, 64, 32)), rigidPart());
    Part ball(buildPartModel(makeIcoSphere(2.2, 3)), rigidPart());
    PairRun run(torus, ball, {BoundingVolumeKind::Aabb, ExactTest::TriangleTriangle});
    // The ball sits in the torus's hole, touching it along a ring: many near pairs.
    auto at = [&](double y) { ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(0.0, y, 0.0)}); };
    const double outside = contactEdge(at, torus, run.ca, ball, run.cb, 0.5, 3.0);  // where the ball comes off the ring
    at(outside);
    run.check(0, false);
    const double margin = run.coherence.list.margin;
    ASSERT_GT(margin, 0.0);
    int midSettle = 0, walkedLists = 0, contacts = 0;
    double y = outside + 0.5 * margin;
    for (int step = 1; step < 120; ++step) {
        y += (step % 100 < 50 ? -0.02 : 0.02) * margin;  // 50 queries down, 50 up: -0.5 to +0.5 margin
        at(y);
        const std::uint64_t before = run.coherence.traversals;
        contacts += int(run.check(step, step == 50) > 0);
        const PairCoherence::Take& next = run.coherence.next;
        if (run.coherence.walking && next.stack.empty() && next.settledUpTo > 0 && next.settledUpTo < next.candidates.size())
            ++midSettle;
        if (run.coherence.traversals > before && run.coherence.list.sorted) {
            ++walkedLists;
            for (const PairCoherence::Candidate& k : run.coherence.list.candidates) EXPECT_TRUE(k.settled) << "step " << step;
            EXPECT_TRUE(std::is_sorted(run.coherence.list.candidates.begin(), run.coherence.list.candidates.end(),
                                       [](const auto& p, const auto& q) { return std::tie(p.faceA, p.faceB) < std::tie(q.faceA, q.faceB); }));
        }
    }
    EXPECT_GT(contacts, 0) << "the ball reaches the torus";
    EXPECT_GT(walkedLists, 0) << "some list came from a walk";
    EXPECT_GT(midSettle, 0) << "no walk was seen settling across queries";
    RecordProperty("queries_mid_settle", midSettle);
}

TEST(CoherentQueryCost, MotionThatOutrunsEveryListIsAnsweredByPlainQueriesUntilItSlows) {
    // A ball jumping about a tube (0.3 a step, far beyond the widest margin): the first list it
    // takes is outrun at once, and plain queries answer from then on, a list tried only where a
    // step happens to be short (a fixed 16 plain queries would try one every 17 queries). Then it
    // stops: 16 queries on, lists again, and the pair at rest traverses no more. Every answer
    // is the full query's.
    std::mt19937 rng(3);
    Part torus(buildPartModel(makeTorus(3.0, 1.0, 24, 12)), rigidPart());
    Part ball(buildPartModel(makeIcoSphere(1.0, 1)), rigidPart());
    ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(3.0, 1.6, 0.0)});
    PairRun run(torus, ball, {BoundingVolumeKind::Aabb, ExactTest::TriangleTriangle});
    int step = 0;
    for (; step < 130; ++step) {
        Pose next = nudged(ball.pose(), rng, 0.3, 0.0);
        next.translation += 0.5 * (Vec3(3.0, 1.6, 0.0) - next.translation);
        ball.setPose(next);
        run.check(step, false);
    }
    EXPECT_TRUE(run.coherence.plain);
    EXPECT_LE(run.coherence.traversals, 4u) << "lists taken while every one is outrun at once (16 plain queries each: 8)";
    EXPECT_GE(run.coherence.plainTraversals, 110u) << "whole traversals answered most of the 130 jumps";
    for (int rest = 0; rest < 17; ++rest, ++step) run.check(step, false);
    EXPECT_FALSE(run.coherence.plain) << "at rest, the plain queries end after their 16";
    EXPECT_TRUE(run.coherence.valid);
    const std::uint64_t settled = run.coherence.traversals, plainSettled = run.coherence.plainTraversals;
    for (int rest = 0; rest < 50; ++rest, ++step) run.check(step, false);
    EXPECT_EQ(run.coherence.traversals, settled);
    EXPECT_EQ(run.coherence.plainTraversals, plainSettled);
    // Every query is answered one way: by a whole traversal or by a scan of the list.
    EXPECT_EQ(run.coherence.plainTraversals + run.coherence.scans, std::uint64_t(step));
}

TEST(CoherentQueryCost, ARebuiltHierarchyIsTraversedAgain) {
    Part torus(buildPartModel(makeTorus(3.0, 1.0, 32, 16)));
    Part ball(buildPartModel(makeIcoSphere(1.0, 2)), rigidPart());
    ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(4.8, 0.0, 0.0)});
    PartCollider ct(torus, BoundingVolumeKind::Aabb), cb(ball, BoundingVolumeKind::Aabb);
    PairCoherence coherence;
    std::vector<Contact> contacts;
    QueryStats stats;
    queryPairCoherent(0, ball, cb, 1, torus, ct, ExactTest::TriangleTriangle, coherence, contacts, stats);
    queryPairCoherent(0, ball, cb, 1, torus, ct, ExactTest::TriangleTriangle, coherence, contacts, stats);
    EXPECT_EQ(coherence.traversals, 1u);
    // The torus moves its masses without a refit, then is rebuilt: new hierarchy, new candidates.
    for (Index m = 0; m < torus.model().massCount(); ++m) torus.displaceMass(m, Vec3(-0.3, 0.0, 0.0));
    ct.rebuild(torus);
    contacts.clear();
    queryPairCoherent(0, ball, cb, 1, torus, ct, ExactTest::TriangleTriangle, coherence, contacts, stats);
    EXPECT_EQ(coherence.traversals, 2u);
    std::vector<Contact> full;
    queryPair(0, ball, cb, 1, torus, ct, ExactTest::TriangleTriangle, full, stats);
    expectSameContacts(contacts, full, 0);
    // A collider built for the other exact test is refused, as by the full query.
    PartCollider spheres(torus, BoundingVolumeKind::Aabb, ExactTest::SphereTriangle);
    EXPECT_THROW(queryPairCoherent(0, ball, cb, 1, torus, spheres, ExactTest::TriangleTriangle, coherence, contacts, stats),
                 std::invalid_argument);
}
