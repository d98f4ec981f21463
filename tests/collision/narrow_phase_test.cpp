// The narrow phase (narrow_phase.cpp): its contacts against the pairwise queries it stands
// for, one body's contacts against the whole narrow phase, the hierarchies refitted only
// when a query needs them, never by reading them, and its traversal count.
#include "flexfit/flexfit.hpp"
#include "same_contacts.hpp"
#include "test_bodies.hpp"

#include <gtest/gtest.h>

#include <random>
#include <set>
#include <tuple>

using namespace flexfit;
using flexfit::testing::expectSameContacts;
using flexfit::testing::rigidPart;

namespace {

using ContactKey = std::tuple<BodyId, BodyId, Index, Index>;

std::set<ContactKey> keysOf(const std::vector<Contact>& contacts) {
    std::set<ContactKey> keys;
    for (const Contact& c : contacts) keys.insert({c.partA, c.partB, c.faceA, c.faceB});
    return keys;
}

// Unit spheres scattered in a small box, registered in order; isRigid(i) picks each mode.
// The face query for every pair (the default would answer rigid-deformable pairs of these
// equal spheres by the point shell).
CollisionSettings facesEverywhere() {
    CollisionSettings settings;
    settings.rigidDeformable = RigidDeformableQuery::Faces;
    return settings;
}

struct Heap {
    std::vector<std::unique_ptr<Part>> parts;
    CollisionWorld world{facesEverywhere()};

    Heap(BodyId count, unsigned seed, bool (*isRigid)(BodyId)) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> u(-1.6, 1.6);
        const auto model = buildPartModel(makeIcoSphere(1.0, 2));
        for (BodyId i = 0; i < count; ++i) {
            parts.push_back(std::make_unique<Part>(model, isRigid(i) ? rigidPart() : PartSettings{}));
            parts.back()->translate(Vec3(u(rng), u(rng), u(rng)));
            world.add(i, *parts.back());
        }
    }
};

}  // namespace

TEST(NarrowPhase, ContactsAreThePairwiseQueriesOfTheCandidatePairs) {
    // Five spheres in a loose heap, some rigid, some deformable: every candidate pair queried
    // with its pressing part first gives exactly the narrow phase's contacts.
    Heap heap(5, 3, [](BodyId i) { return i % 2 == 1; });
    auto& [parts, world] = heap;
    const std::vector<Contact> contacts = world.findContacts();
    std::vector<Contact> expected;
    for (auto [a, b] : world.candidatePairs()) {
        const bool da = parts[a]->mode() != PartMode::Rigid, db = parts[b]->mode() != PartMode::Rigid;
        if (da && !db) std::swap(a, b);  // the rigid part presses
        QueryStats stats;
        queryPair(a, *parts[a], world.collider(a), b, *parts[b], world.collider(b), ExactTest::TriangleTriangle, expected, stats);
    }
    ASSERT_FALSE(contacts.empty());
    EXPECT_EQ(keysOf(contacts), keysOf(expected));
    EXPECT_EQ(contacts.size(), expected.size());
}

TEST(NarrowPhase, OneBodysContactsAreItsShareOfTheNarrowPhase) {
    Heap heap(6, 8, [](BodyId i) { return i != 2; });
    auto& [parts, world] = heap;
    const std::vector<Contact> all = world.findContacts();
    for (BodyId id = 0; id < 6; ++id) {
        std::set<ContactKey> share, rigidShare;
        for (const Contact& c : all) {
            if (c.partA != id && c.partB != id) continue;
            share.insert({c.partA, c.partB, c.faceA, c.faceB});
            const BodyId other = c.partA == id ? c.partB : c.partA;
            if (parts[other]->mode() == PartMode::Rigid) rigidShare.insert({c.partA, c.partB, c.faceA, c.faceB});
        }
        EXPECT_EQ(keysOf(world.contactsOf(id)), share) << "body " << id;
        EXPECT_EQ(keysOf(world.contactsOf(id, true)), rigidShare) << "body " << id;
    }
}

TEST(NarrowPhase, HierarchiesRefitWhenAQueryNeedsThemAndNotWhenRead) {
    // A deformable torus pressed by a force and a probe sphere at its rim. The next face query
    // refits its hierarchy from the part's changed masses, lists the body as refitted, and
    // gives the contacts of a hierarchy rebuilt from scratch; with the list cleared, the next
    // query refits nothing. (Reading a collider cannot refit it: collider() is const.)
    const auto torusModel = buildPartModel(makeTorus1());
    Part torus(torusModel);
    Part probe(buildPartModel(makeIcoSphere(3.0, 3)), rigidPart());
    probe.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(12.0, 0.5, 0.0)});
    CollisionWorld world{facesEverywhere()};
    world.add(0, probe);
    world.add(1, torus);
    for (int i = 0; i < 300; ++i) {
        torus.applyForce(0, Vec3(-40.0, 5.0, 0.0));
        torus.step();
    }
    const std::size_t refitsBefore = world.collider(1).refitNodeCount();
    const std::vector<Contact> contacts = world.findContacts();
    EXPECT_GT(world.collider(1).refitNodeCount(), refitsBefore);
    ASSERT_EQ(world.refittedBodies().size(), 1u);
    EXPECT_EQ(world.refittedBodies()[0], 1u);

    const PartCollider rebuilt(torus, BoundingVolumeKind::Aabb), probeCollider(probe, BoundingVolumeKind::Aabb);
    std::vector<Contact> expected;
    QueryStats stats;
    queryPair(0, probe, probeCollider, 1, torus, rebuilt, ExactTest::TriangleTriangle, expected, stats);
    ASSERT_FALSE(expected.empty());
    EXPECT_EQ(keysOf(contacts), keysOf(expected));
    // With the part's list cleared, the next query has nothing to refit.
    torus.clearChangedMasses();
    const std::size_t refitsAfter = world.collider(1).refitNodeCount();
    world.findContacts();
    EXPECT_EQ(world.collider(1).refitNodeCount(), refitsAfter);
    EXPECT_TRUE(world.refittedBodies().empty());
}

TEST(NarrowPhase, PointShellPairsNeedNoRefit) {
    // Under the point-shell query a deformable part met only by a closed rigid part, smooth at
    // its scale (no sharp faces), is tested mass by mass: its face hierarchy is never refitted.
    CollisionSettings settings;
    settings.rigidDeformable = RigidDeformableQuery::PointShell;
    Part ball(buildPartModel(makeIcoSphere(3.0, 2)), rigidPart());
    ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(12.0, 0.5, 0.0)});
    Part torus(buildPartModel(makeTorus2()));
    ASSERT_TRUE(findSharpFeatures(ball, restResolution(torus)).empty());
    CollisionWorld world(settings);
    world.add(0, ball);
    world.add(1, torus);
    for (int i = 0; i < 100; ++i) {
        torus.applyForce(0, Vec3(-10.0, 0.0, 0.0));
        torus.step();
    }
    const std::vector<Contact> contacts = world.findContacts();
    ASSERT_FALSE(contacts.empty());
    for (const Contact& c : contacts) EXPECT_NE(c.massB, kNoMass);  // point-shell contacts
    EXPECT_TRUE(world.refittedBodies().empty());
    EXPECT_EQ(world.collider(1).refitNodeCount(), 0u);
}

namespace {

// A ball pressed into a deformed torus2, answered by the point shell: each world built the same.
struct PressedTorus {
    Part ball{buildPartModel(makeIcoSphere(3.0, 2)), rigidPart()};
    Part torus{buildPartModel(makeTorus2())};
    CollisionWorld world;

    explicit PressedTorus(RigidDeformableQuery query) : world([&] {
        CollisionSettings settings;
        settings.rigidDeformable = query;
        return settings;
    }()) {
        ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(12.0, 0.5, 0.0)});
        world.add(0, ball);
        world.add(1, torus);
        for (int i = 0; i < 100; ++i) {
            torus.applyForce(0, Vec3(-10.0, 0.0, 0.0));
            torus.step();
        }
    }
};

}  // namespace

TEST(NarrowPhase, AWarmUpTakesThePairsFirstTraversalAndChangesNoContact) {
    // The same pair twice, by the point shell and by faces: a warmed world's first narrow phase
    // gives a cold one's contacts field for field, without the cold one's walk or traversal;
    // the warm-up itself reports nothing (no contacts, stats or query counts).
    for (const RigidDeformableQuery query : {RigidDeformableQuery::PointShell, RigidDeformableQuery::Faces}) {
        PressedTorus warm(query), cold(query);
        warm.world.warmUp();
        EXPECT_TRUE(warm.world.contacts().empty());
        EXPECT_EQ(warm.world.stats().volumeTests, 0u);
        EXPECT_EQ(warm.world.faceQueries(), 0u);
        EXPECT_EQ(warm.world.faceTraversals(), 0u);
        const std::vector<Contact> warmContacts = warm.world.findContacts();
        const std::vector<Contact> coldContacts = cold.world.findContacts();
        ASSERT_FALSE(coldContacts.empty());
        expectSameContacts(warmContacts, coldContacts, 0);
        if (query == RigidDeformableQuery::PointShell) {
            // The cold query walks the torus's rest masses near the ball; the warm one reads the
            // list the warm-up walked.
            EXPECT_LT(warm.world.stats().volumeTests * 4, cold.world.stats().volumeTests)
                << warm.world.stats().volumeTests << " against " << cold.world.stats().volumeTests;
        } else {
            EXPECT_EQ(warm.world.faceQueries(), 1u);
            EXPECT_EQ(warm.world.faceTraversals(), 0u);  // the warm-up's candidates still cover
            EXPECT_EQ(cold.world.faceTraversals(), 1u);
        }
    }
}

TEST(NarrowPhase, FaceTraversalsCountTheWholeTraversalsOfAPairTooFastForLists) {
    // A ball jumping about a rigid tube, 0.3 a step (far beyond any list's margin): the coherent
    // query answers nearly every step by a whole traversal, and faceTraversals counts them as
    // the plain query's count does; at rest, lists answer and the count stops.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Part torus(buildPartModel(makeTorus(3.0, 1.0, 24, 12)), rigidPart());
    Part ball(buildPartModel(makeIcoSphere(1.0, 1)), rigidPart());
    CollisionWorld coherent, plain([] {
        CollisionSettings settings;
        settings.coherent = false;
        return settings;
    }());
    for (CollisionWorld* world : {&coherent, &plain}) {
        world->add(0, torus);
        world->add(1, ball);
    }
    const Vec3 home(3.0, 1.6, 0.0);
    for (int step = 0; step < 130; ++step) {
        ball.setPose(Pose{Eigen::Quaterniond::Identity(), home + 0.3 * Vec3(u(rng), u(rng), u(rng))});
        expectSameContacts(coherent.findContacts(), plain.findContacts(), step);
    }
    EXPECT_EQ(plain.faceQueries(), 130u);
    EXPECT_EQ(plain.faceTraversals(), 130u);
    EXPECT_EQ(coherent.faceQueries(), 130u);
    EXPECT_GE(coherent.faceTraversals(), 110u) << "whole traversals answer the jumps";
    const std::uint64_t jumping = coherent.faceTraversals();
    for (int step = 0; step < 60; ++step) coherent.findContacts();
    EXPECT_LE(coherent.faceTraversals(), jumping + 18) << "at rest, at most the 16 plain queries and a list";
}

// Rigid pairs at the poses of their last query are answered by it: the same contacts, field
// for field and in order, as a world that queries every time (coherent = false), with no face
// query run. A pair one of whose parts moved, or deforms, is queried again.
TEST(NarrowPhase, RigidPairsAtTheirLastPosesAreAnsweredWithoutAQuery) {
    Heap heap(6, 8, [](BodyId i) { return i != 2; });  // body 2 deforms
    auto& [parts, world] = heap;
    CollisionSettings plainSettings = facesEverywhere();
    plainSettings.coherent = false;
    CollisionWorld plain(plainSettings);
    for (BodyId i = 0; i < parts.size(); ++i) plain.add(i, *parts[i]);
    auto pairsWith = [&](auto touches) {  // the candidate pairs `touches` selects
        std::uint64_t n = 0;
        for (auto [a, b] : world.candidatePairs()) n += touches(a) || touches(b);
        return n;
    };
    auto expectAsPlain = [&](int round) {
        const std::uint64_t before = world.faceQueries();
        const std::vector<Contact> got = world.findContacts();
        flexfit::testing::expectSameContacts(got, plain.findContacts(), round);
        return world.faceQueries() - before;
    };
    ASSERT_GT(expectAsPlain(0), 0u);  // every pair queried once
    ASSERT_GT(world.contacts().size(), 0u);
    const std::uint64_t deformingPairs = pairsWith([](BodyId i) { return i == 2; });
    ASSERT_GT(deformingPairs, 0u);
    ASSERT_LT(deformingPairs, world.candidatePairs().size());
    EXPECT_EQ(expectAsPlain(1), deformingPairs);  // nothing moved: only body 2's pairs queried
    // A rigid body in contact with another rigid one moves a little.
    const auto rigidContact = std::find_if(world.contacts().begin(), world.contacts().end(),
                                           [](const Contact& c) { return c.partA != 2 && c.partB != 2; });
    ASSERT_NE(rigidContact, world.contacts().end());
    const BodyId moved = rigidContact->partA;
    parts[moved]->translate(Vec3(1e-6, -2e-6, 0.0));
    EXPECT_EQ(expectAsPlain(2), pairsWith([&](BodyId i) { return i == 2 || i == moved; }));
    parts[moved]->setPose(parts[moved]->pose());  // the same pose written again: still answered
    EXPECT_EQ(expectAsPlain(3), deformingPairs);
    // One body's rigid contacts: the same answers.
    const std::uint64_t before = world.faceQueries();
    flexfit::testing::expectSameContacts(world.contactsOf(moved, true), plain.contactsOf(moved, true), 4);
    EXPECT_EQ(world.faceQueries(), before);
}
