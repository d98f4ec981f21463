// The coherent point-shell query (point_shell.cpp) against the full one, contact for contact, and
// against brute force (every mass sampled), while a rigid ball wanders over a torus whose masses
// a zone moves; then that a ball held still samples only the masses near it.
#include "collision/sampling_kernel.hpp"
#include "core/lanes256.hpp"
#include "flexfit/flexfit.hpp"
#include "same_contacts.hpp"
#include "test_bodies.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

using namespace flexfit;
using flexfit::testing::expectSameContacts;
using flexfit::testing::rigidPart;

namespace {

// Masses whose sample is <= 0, by sampling every one.
std::set<Index> bruteForce(const Part& ball, const SignedDistanceField& field, const Part& torus) {
    const Eigen::Matrix3d ra = ball.pose().rotation.toRotationMatrix();
    std::set<Index> out;
    for (Index m = 0; m < torus.model().massCount(); ++m) {
        const Vec3 p = ra.transpose() * (torus.pose().apply(torus.state().positions[m]) - ball.pose().translation);
        if (field.inGrid(p) && field.sample(p).distance <= 0.0) out.insert(m);
    }
    return out;
}

struct BallOverTorus {
    std::shared_ptr<const PartModel> ballModel = buildPartModel(makeIcoSphere(0.9, 2));
    SignedDistanceField field{ballModel->mesh, ballModel->topology};
    Part ball{ballModel, rigidPart()};
    Part torus{buildPartModel(makeTorus(1.0, 0.35, 48, 16))};
    PartCollider collider{torus, BoundingVolumeKind::Aabb};
    BallOverTorus() { collider.buildRestPointTree(torus); }

    std::vector<Contact> coherent(PointShellCoherence& c, QueryStats& stats) {
        std::vector<Contact> out;
        queryPointShellCoherent(0, ball, field, 1, torus, collider.restPointTree(), collider.localSphere(), c, out, stats);
        return out;
    }
    std::vector<Contact> full() {
        std::vector<Contact> out;
        QueryStats stats;
        queryPointShell(0, ball, field, 1, torus, collider.restPointTree(), out, stats);
        return out;
    }
};

}  // namespace

TEST(PointShellCoherent, AWanderingBallOverADeformingTorusGetsTheFullQuerysContacts) {
    // The ball drifts over the tube (small steps, a jump now and then, turning); a zone under it
    // is pushed in and released, so masses move, come to rest and move again.
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    BallOverTorus s;
    s.ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(1.0, 1.1, 0.0)});
    PointShellCoherence coherence;
    std::size_t contacts = 0;
    for (int step = 0; step < 300; ++step) {
        if (step % 100 < 60) s.torus.applyForce(12, Vec3(0.0, -2.0, 0.0));  // mass 12: top of the tube at u = 0
        s.torus.step();
        const double scale = step % 37 == 0 ? 10.0 : 1.0;
        Pose next = s.ball.pose();
        next.translation += scale * 0.004 * Vec3(u(rng), u(rng), u(rng)) + 0.02 * (Vec3(1.0, 1.1, 0.0) - next.translation);
        next.rotation = (Eigen::Quaterniond(Eigen::AngleAxisd(scale * 0.01 * u(rng), Vec3(u(rng), u(rng), 1.0).normalized())) * next.rotation).normalized();
        s.ball.setPose(next);
        QueryStats stats;
        const std::vector<Contact> got = s.coherent(coherence, stats);
        expectSameContacts(got, s.full(), step);
        if (step % 20 == 0) {
            std::set<Index> masses;
            for (const Contact& c : got) masses.insert(c.massB);
            EXPECT_EQ(masses, bruteForce(s.ball, s.field, s.torus)) << "step " << step;
        }
        contacts += got.size();
    }
    EXPECT_GT(contacts, 0u);
    EXPECT_LT(coherence.traversals, 300u / 2) << "the rest masses' list is reused";
}

TEST(PointShellCoherent, AWalkKeepsAheadOfASteadyMotion) {
    // A ball sliding across the torus at a steady speed, a margin every ~7 queries (a 1/16 share
    // of a walk a query would be outrun): each new list is walked in slices sized by the motion,
    // none finished inside one query, and the contacts stay the full query's.
    BallOverTorus s;
    PointShellCoherence coherence;
    std::size_t contacts = 0, largestSlice = 0, largestWalk = 0;
    for (int step = 0; step < 300; ++step) {
        s.ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(-1.5 + 0.01 * step, 0.5, 0.1)});
        QueryStats stats;
        const std::vector<Contact> got = s.coherent(coherence, stats);
        expectSameContacts(got, s.full(), step);
        contacts += got.size();
        if (step > 0) largestSlice = std::max(largestSlice, stats.volumeTests);
        largestWalk = std::max(largestWalk, coherence.traversalCost);
    }
    EXPECT_GT(contacts, 0u);
    EXPECT_GT(coherence.traversals, 10u) << "the motion needs new lists";
    EXPECT_EQ(coherence.walksAtOnce, 0u);
    // No query walks much of a list (its own slice of the walk, plus the rest masses it reads).
    EXPECT_LT(largestSlice * 2, largestWalk) << largestSlice << " nodes in one query, walks up to " << largestWalk;
}

TEST(PointShellCoherent, ASlowMotionSpreadsEachWalkOverMoreQueriesThanTheShare) {
    // A ball sliding slowly over a fine torus (a margin every ~66 queries): each walk is spread
    // over 2/3 of the queries its list still covers, more than the 16 of the share at rest, so
    // a walking query walks far less than 1/16 of a list (the in-contact tail of the haptic
    // scene was such slices); none is finished at once, and the contacts stay the full query's.
    BallOverTorus s;
    s.torus = Part(buildPartModel(makeTorus(1.0, 0.35, 192, 64)));
    s.collider = PartCollider(s.torus, BoundingVolumeKind::Aabb);
    s.collider.buildRestPointTree(s.torus);
    PointShellCoherence coherence;
    std::size_t contacts = 0, walked = 0, walkingQueries = 0, largestWalk = 0;
    for (int step = 0; step < 400; ++step) {
        s.ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(-0.2 + 0.001 * step, 0.5, 0.1)});
        QueryStats stats;
        const std::vector<Contact> got = s.coherent(coherence, stats);
        if (step % 10 == 0) expectSameContacts(got, s.full(), step);
        contacts += got.size();
        if (step > 0 && stats.volumeTests > 0) {
            walked += stats.volumeTests;
            ++walkingQueries;
        }
        largestWalk = std::max(largestWalk, coherence.traversalCost);
    }
    EXPECT_GT(contacts, 0u);
    EXPECT_GT(coherence.traversals, 4u) << "the motion needs new lists";
    EXPECT_EQ(coherence.walksAtOnce, 0u);
    // The share would walk 1/16 of a list a query; spread, a walking query walks under 1/24.
    ASSERT_GT(walkingQueries, 0u);
    EXPECT_LT(24 * walked / walkingQueries, largestWalk) << walked / walkingQueries << " nodes a walking query, walks up to " << largestWalk;
}

TEST(PointShellCoherent, MovingMassesOutsideTheGridAreSampledOnceTheBallComes) {
    // A zone moves masses of the tube far below the ball, outside its field's grid;
    // the ball then comes down and presses them: the coherent query must sample them again
    // when they enter the grid (an earlier version skipped them for good).
    BallOverTorus s;
    const Vec3 far(1.0, -3.0, 0.0), over(1.0, -0.9, 0.0);  // mass 12: (1, -0.35, 0), the tube's underside at u = 0
    s.ball.setPose(Pose{Eigen::Quaterniond::Identity(), far});
    PointShellCoherence coherence;
    std::size_t movingContacts = 0;
    for (int step = 0; step < 60; ++step) {
        s.torus.applyForce(12, Vec3(0.0, -0.5, 0.0));  // keeps the zone around mass 12 moving
        s.torus.step();
        const double t = std::clamp((step - 10) / 30.0, 0.0, 1.0);
        s.ball.setPose(Pose{Eigen::Quaterniond::Identity(), (1.0 - t) * far + t * over});
        QueryStats stats;
        const std::vector<Contact> got = s.coherent(coherence, stats);
        expectSameContacts(got, s.full(), step);
        for (const Contact& c : got) movingContacts += s.torus.isMoving(c.massB);
    }
    EXPECT_GT(movingContacts, 0u);
}

TEST(PointShellCoherent, ABallHeldStillSamplesOnlyTheMassesNearIt) {
    // Pressed into the tube, the zone there moving: after a few queries, the samples are about
    // the contacts (masses near the surface), not every moving mass and every reached rest mass.
    BallOverTorus s;
    s.ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(1.0, 1.1, 0.0)});
    s.torus.openZone(ZoneSeed::mass(12), 4);
    PointShellCoherence coherence;
    QueryStats first, last;
    for (int step = 0; step < 40; ++step) {
        s.torus.applyForce(12, Vec3(0.0, -0.5, 0.0));
        s.torus.step();
        QueryStats stats;
        const std::vector<Contact> got = s.coherent(coherence, stats);
        expectSameContacts(got, s.full(), step);
        (step == 0 ? first : last) = stats;
    }
    ASSERT_GT(last.contacts, 0u);
    EXPECT_LT(last.exactTests, first.exactTests / 2) << last.exactTests << " samples against " << first.exactTests;
}

TEST(PointShellCoherent, AWalkListsOnlyTheRestMassesThatCanTouchWithinItsMargin) {
    // The walk lists small subtrees whole and prunes their masses on their own samples: the
    // list keeps no mass outside the grid or clear of the surface over the margin (those the
    // query would skip while the list is used), and still every mass that a brute-force sample
    // at the list's pose finds within the margin of the surface.
    BallOverTorus s;
    s.ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(1.0, 0.8, 0.0)});
    PointShellCoherence coherence;
    QueryStats stats;
    ASSERT_FALSE(s.coherent(coherence, stats).empty());
    ASSERT_TRUE(coherence.valid);
    const double clear = s.field.clearDistance(coherence.margin);
    std::set<Index> listed;
    for (const auto& [m, distance] : coherence.restMasses) {
        EXPECT_LE(distance, clear) << "mass " << m;
        listed.insert(m);
    }
    std::size_t near = 0;
    for (Index m = 0; m < s.torus.model().massCount(); ++m) {
        const Vec3 p = coherence.pose.apply(s.torus.model().restPositions[m]);
        if (!s.field.inGrid(p) || s.field.sample(p).distance > coherence.margin) continue;
        ++near;
        EXPECT_TRUE(listed.contains(m)) << "mass " << m << " samples " << s.field.sample(p).distance;
    }
    EXPECT_GT(near, 0u);
    EXPECT_LT(listed.size(), s.torus.model().massCount() / 2);
}

TEST(PointShell, ContactsFourAtATimeEqualOneAtATime) {
    // The AVX2 paths (samples, contacts and the coherent query's skip test 4 at a time)
    // against one at a time (ScopedScalarSampling, ScopedScalarLanes), bit for bit, by the full and the coherent
    // query, as a turning ball wanders over a deforming torus.
    if (!detail::vectorSamplingEnabled() || !detail::lanesEnabled()) GTEST_SKIP() << "no AVX2 on this CPU: one path only";
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    BallOverTorus s;
    s.ball.setPose(Pose{Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vec3(0.3, 1.0, -0.5).normalized())), Vec3(1.0, 1.05, 0.0)});
    std::size_t contacts = 0;
    PointShellCoherence vectorCoherence, scalarCoherence;
    std::size_t mostMoving = 0;
    s.torus.openZone(ZoneSeed::mass(12), 6);  // many moving masses under the ball
    for (int step = 0; step < 120; ++step) {
        if (step % 60 < 40) s.torus.applyForce(12, Vec3(0.0, -2.0, 0.0));
        s.torus.step();
        Pose next = s.ball.pose();
        next.translation += 0.004 * Vec3(u(rng), u(rng), u(rng)) + 0.02 * (Vec3(1.0, 1.05, 0.0) - next.translation);
        next.rotation = (Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * u(rng), Vec3(u(rng), u(rng), 1.0).normalized())) * next.rotation).normalized();
        s.ball.setPose(next);
        QueryStats vectorStats, scalarStats;
        const std::vector<Contact> vector = s.full(), vectorCoherent = s.coherent(vectorCoherence, vectorStats);
        std::vector<Contact> scalar, scalarCoherent;
        {
            const detail::ScopedScalarSampling oneAtATime;
            const detail::ScopedScalarLanes lanesOneAtATime;
            scalar = s.full();
            scalarCoherent = s.coherent(scalarCoherence, scalarStats);
        }
        // The same masses sampled: the skip test decided alike.
        EXPECT_EQ(vectorStats.exactTests, scalarStats.exactTests) << "step " << step;
        EXPECT_EQ(vectorStats.candidatePairs, scalarStats.candidatePairs) << "step " << step;
        mostMoving = std::max(mostMoving, s.torus.movingMasses().size());
        expectSameContacts(vector, scalar, step);
        expectSameContacts(vectorCoherent, scalarCoherent, step);
        expectSameContacts(vectorCoherent, vector, step);
        contacts += vector.size();
    }
    EXPECT_GT(contacts, 400u);
    EXPECT_GT(mostMoving, 40u);  // the skip test ran on groups of 4
}
