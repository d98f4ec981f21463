// The broad phase (broad_phase.cpp): candidate pairs against brute-force sphere pairs, refit
// against rebuild.
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <random>
#include <set>

using namespace flexfit;

TEST(BroadPhase, EqualsBruteForceAndRefitEqualsRebuild) {
    std::mt19937 rng(20);
    std::uniform_real_distribution<double> u(-12, 12);
    const auto model = buildPartModel(makeIcoSphere(2.0, 1));
    std::vector<std::unique_ptr<Part>> parts;
    CollisionWorld refit(CollisionSettings{ExactTest::TriangleTriangle, BroadPhaseUpdate::Refit}),
        rebuild(CollisionSettings{ExactTest::TriangleTriangle, BroadPhaseUpdate::Rebuild});
    for (BodyId i = 0; i < 40; ++i) {
        parts.push_back(std::make_unique<Part>(model));
        parts.back()->translate(Vec3(u(rng), u(rng), u(rng)));
        refit.add(i, *parts.back());
        rebuild.add(i, *parts.back());
    }
    for (int round = 0; round < 5; ++round) {
        for (auto& p : parts) p->translate(Vec3(u(rng), u(rng), u(rng)) * 0.2);
        refit.update();
        rebuild.update();
        std::set<std::pair<BodyId, BodyId>> expected;
        for (BodyId i = 0; i < parts.size(); ++i)
            for (BodyId j = i + 1; j < parts.size(); ++j) {
                const Sphere a = refit.collider(i).worldSphere(*parts[i]), b = refit.collider(j).worldSphere(*parts[j]);
                if ((a.centre - b.centre).norm() <= a.radius + b.radius) expected.insert({i, j});
            }
        using PairSet = std::set<std::pair<BodyId, BodyId>>;
        const auto& got = refit.candidatePairs();
        EXPECT_EQ(PairSet(got.begin(), got.end()), expected);
        EXPECT_EQ(refit.candidatePairs(), rebuild.candidatePairs());
        EXPECT_FALSE(expected.empty());
    }
}

// Parts added between updates (a scene of thousands of parts: the tree was rebuilt at every
// add, 20,000 static parts took over a minute to load) join the tree at the next update, with
// the refit update as with the rebuilding one: the pairs equal brute force's after each round.
TEST(BroadPhase, PartsAddedBetweenUpdatesJoinTheTreeAtTheNext) {
    const auto model = buildPartModel(makeIcoSphere(1.0, 1));
    std::vector<std::unique_ptr<Part>> parts;
    CollisionWorld world(CollisionSettings{ExactTest::TriangleTriangle, BroadPhaseUpdate::Refit});
    using PairSet = std::set<std::pair<BodyId, BodyId>>;
    for (int round = 0; round < 4; ++round) {
        for (int k = 0; k < 3; ++k) {  // a row of touching balls, three more each round
            parts.push_back(std::make_unique<Part>(model));
            parts.back()->translate(Vec3(1.9 * double(parts.size()), 0, 0));
            world.add(BodyId(parts.size() - 1), *parts.back());
        }
        world.update();
        std::size_t leaves = 0;
        for (const auto& node : world.broadPhaseTree().nodes()) leaves += node.isLeaf();
        EXPECT_EQ(leaves, parts.size());
        PairSet expected;
        for (BodyId i = 0; i + 1 < parts.size(); ++i) expected.insert({i, i + 1});
        const auto& got = world.candidatePairs();
        EXPECT_EQ(PairSet(got.begin(), got.end()), expected) << "round " << round;
    }
}

// torus1 with no restoration (its deformation stays) in a collision world, with its bounding
// radius at rest and the brute-force largest displacement of its moving masses.
struct LooseTorus {
    static PartSettings loose() {
        PartSettings settings;
        settings.simulation.restoration.method = RestorationMethod::None;
        return settings;
    }
    LooseTorus() {
        world.add(0, part);
        world.update();
        restRadius = world.collider(0).localSphere().radius;
    }
    double largestMove() const {
        double largest = 0.0;
        for (Index m : part.movingMasses()) largest = std::max(largest, (part.state().positions[m] - model->restPositions[m]).norm());
        return largest;
    }
    std::shared_ptr<const PartModel> model = buildPartModel(makeTorus1());
    Part part{model, loose()};
    CollisionWorld world;
    double restRadius = 0.0;
};

TEST(BroadPhase, ADeformedPartsSphereGrowsByItsLargestDisplacement) {
    LooseTorus t;
    for (int i = 0; i < 200; ++i) {
        t.part.applyForce(0, Vec3(-20.0, 0.0, 0.0));
        t.part.step();
    }
    const double largest = t.largestMove();
    ASSERT_GT(largest, 0.1);
    t.world.update();
    EXPECT_NEAR(t.world.collider(0).localSphere().radius, t.restRadius + largest, 1e-12);
}

// The bound against brute force with the largest move placed at each position of the moving
// list in turn: every lane of its running maxima and the list's tail (a count not a multiple of
// 4). Exact: the largest squared norm's root is the largest norm.
TEST(BroadPhase, TheDisplacementBoundIsTheLargestMoveWhereverItLies) {
    LooseTorus t;
    t.part.applyForce(0, Vec3(-1.0, 0.0, 0.0));
    t.part.step();
    const std::vector<Index> moving(t.part.movingMasses().begin(), t.part.movingMasses().end());
    ASSERT_GE(moving.size(), 5u);  // at least one group of 4
    ASSERT_NE(moving.size() % 4, 0u);
    for (std::size_t k = 0; k < moving.size(); ++k) {
        t.part.displaceMass(moving[k], Vec3(0.0, 0.0, 0.01 * double(k + 1)));  // each larger than the last
        const double largest = t.largestMove();
        t.world.update();
        EXPECT_EQ(t.world.collider(0).localSphere().radius, t.restRadius + largest) << "largest at " << k << " of " << moving.size();
    }
}

// Fixed bodies (Mobility::Fixed: static rigid parts) sit in a tree of their own and are never
// paired with each other: the pairs are brute force's minus those of two fixed bodies, with
// either update, and a fixed body made moving is paired with the fixed ones from the next
// update on. contactsOf gives a body the narrow phase's contacts in the same order.
TEST(BroadPhase, FixedBodiesArePairedOnlyWithMovingOnes) {
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> u(-8, 8);
    const auto model = buildPartModel(makeIcoSphere(2.0, 1));
    PartSettings rigid;
    rigid.mode = PartMode::Rigid;
    std::vector<std::unique_ptr<Part>> parts;
    std::vector<bool> fixed;
    CollisionWorld refit(CollisionSettings{ExactTest::TriangleTriangle, BroadPhaseUpdate::Refit}),
        rebuild(CollisionSettings{ExactTest::TriangleTriangle, BroadPhaseUpdate::Rebuild});
    for (BodyId i = 0; i < 40; ++i) {
        parts.push_back(std::make_unique<Part>(model, rigid));
        parts.back()->translate(Vec3(u(rng), u(rng), u(rng)));
        fixed.push_back(i % 3 != 0);  // two in three fixed, ids interleaved
        const Mobility mobility = fixed.back() ? Mobility::Fixed : Mobility::Moving;
        refit.add(i, *parts.back(), BoundingVolumeKind::Aabb, mobility);
        rebuild.add(i, *parts.back(), BoundingVolumeKind::Aabb, mobility);
    }
    using PairSet = std::set<std::pair<BodyId, BodyId>>;
    auto expectedPairs = [&] {
        PairSet expected;
        for (BodyId i = 0; i < parts.size(); ++i)
            for (BodyId j = i + 1; j < parts.size(); ++j) {
                const Sphere a = refit.collider(i).worldSphere(*parts[i]), b = refit.collider(j).worldSphere(*parts[j]);
                if ((a.centre - b.centre).norm() <= a.radius + b.radius && !(fixed[i] && fixed[j])) expected.insert({i, j});
            }
        return expected;
    };
    std::size_t fixedPairsSkipped = 0;
    for (int round = 0; round < 6; ++round) {
        for (BodyId i = 0; i < parts.size(); ++i)
            if (!fixed[i]) parts[i]->translate(Vec3(u(rng), u(rng), u(rng)) * 0.3);
        if (round == 3) {  // body 1 (fixed) starts to move
            refit.setMoving(1);
            rebuild.setMoving(1);
            fixed[1] = false;
            EXPECT_FALSE(refit.fixed(1));
        }
        refit.update();
        rebuild.update();
        const PairSet expected = expectedPairs();
        const auto& got = refit.candidatePairs();
        EXPECT_EQ(PairSet(got.begin(), got.end()), expected) << "round " << round;
        EXPECT_EQ(refit.candidatePairs(), rebuild.candidatePairs());
        EXPECT_TRUE(std::is_sorted(got.begin(), got.end()));
        for (BodyId i = 0; i < parts.size(); ++i)
            for (BodyId j = i + 1; j < parts.size(); ++j) {
                const Sphere a = refit.collider(i).worldSphere(*parts[i]), b = refit.collider(j).worldSphere(*parts[j]);
                fixedPairsSkipped += fixed[i] && fixed[j] && (a.centre - b.centre).norm() <= a.radius + b.radius;
            }
        // Each moving body's contactsOf: the narrow phase's contacts of its pairs, in order.
        const std::vector<Contact> all = rebuild.narrowPhase();
        for (BodyId i = 0; i < parts.size(); ++i) {
            if (fixed[i]) continue;
            std::vector<Contact> expectedContacts;
            for (const Contact& c : all)
                if (c.partA == i || c.partB == i) expectedContacts.push_back(c);
            const std::vector<Contact> own = rebuild.contactsOf(i);
            ASSERT_EQ(own.size(), expectedContacts.size()) << "body " << i;
            for (std::size_t c = 0; c < own.size(); ++c) {
                EXPECT_EQ(own[c].partA, expectedContacts[c].partA);
                EXPECT_EQ(own[c].faceB, expectedContacts[c].faceB);
                EXPECT_EQ(own[c].depth, expectedContacts[c].depth);
            }
        }
    }
    EXPECT_GT(fixedPairsSkipped, 0u);  // the random layout does put fixed bodies in reach of each other
}

TEST(BroadPhase, ADeformingPartCannotBeFixed) {
    CollisionWorld world;
    Part soft(buildPartModel(makeIcoSphere(1.0, 1)));  // rigid-deformable
    EXPECT_THROW(world.add(0, soft, BoundingVolumeKind::Aabb, Mobility::Fixed), std::invalid_argument);
    EXPECT_EQ(world.bodyCount(), 0u);
    world.add(0, soft);
    EXPECT_FALSE(world.fixed(0));
}
