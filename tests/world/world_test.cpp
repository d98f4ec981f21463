// The world (src/world/world.cpp): its profile partitions every step among the stages, runs
// are deterministic, a deformable rim stops or yields to a ball by its stiffness, settings
// change while it runs, and its calls refuse what does not exist; the default per-step
// restoration at another time step is reported in warnings(); mass loads name the user's vertices.
#include "shuffled_mesh.hpp"
#include "test_bodies.hpp"
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <thread>

using namespace flexfit;
using namespace flexfit::testing;

TEST(World, ProfilePartitionsEveryStepAmongTheStages) {
    // Every stage has work: the operator presses a dynamic ball (operator input, rigid motion)
    // into a deformable rim (broad and narrow phase, contact response, zone dynamics
    // and retirement), and an assembly rule is checked every step.
    World world;
    PartSettings rim;
    rim.zones.contactLevel = 3;
    const BodyId torus = world.add(buildPartModel(makeContainerMouth(), {Material::rigid(), 1.0, {}, {}, {}, {}}), rim, BodySettings{}, Pose{});
    BodySettings heavy = dynamicBody(Vec3(0, -3, 0));
    heavy.density = 0.01;
    const BodyId ball = world.add(buildPartModel(makeIcoSphere(8.5, 2)), rigidPart(), heavy, at(Vec3(0, 9.5, 0)));
    AssemblyRule rule;
    rule.primary = ball;
    rule.secondary = torus;
    rule.technique = SnapTechnique::ProximitySnap;
    rule.distanceTolerance = 1e-6;
    world.addAssembly(rule);
    world.grab(ball, GrabSettings{1.0});
    world.setGrabTarget(at(Vec3(0, 3, 0)));  // into the rim
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < 300; ++i) {
        world.step();
        const Profile& p = world.profile();
        double sum = 0.0;
        for (double seconds : p.lastSeconds) sum += seconds;
        ASSERT_NEAR(sum, p.lastStepSeconds, 1e-9 * p.lastStepSeconds) << "step " << i;  // nothing charged twice or dropped
    }
    const double outside = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const Profile& p = world.profile();
    ASSERT_FALSE(world.contacts().empty());
    EXPECT_GT(world.part(torus).movingMasses().size(), 0u);
    EXPECT_EQ(p.steps, 300u);
    EXPECT_GE(p.substeps, 300u);
    double sum = 0.0;
    for (std::size_t s = 0; s < kStageCount; ++s) {
        EXPECT_GT(p.totalSeconds[s], 0.0) << labelOf(Stage(s)) << " did work and was charged nothing";
        sum += p.totalSeconds[s];
    }
    EXPECT_NEAR(sum, p.totalStepSeconds, 1e-9 * p.totalStepSeconds);
    EXPECT_LE(p.totalStepSeconds, outside);  // measured inside the calls that the clock here surrounds
}

// Two clock readings, a call and the profile's bookkeeping: about 1 us in Release; the
// sanitizers instrument every one of them (measured 2.003 us under ASan + UBSan, with 9 stages).
#if defined(__SANITIZE_ADDRESS__)
constexpr double kCallOverhead = 10e-6;
#else
constexpr double kCallOverhead = 2e-6;
#endif

TEST(World, NoWorkHappensOutsideTheProfiledInterval) {
    // The stages partition the interval between the step's first and last clock readings, so
    // they add up to lastStepSeconds by construction. What this checks independently: timed
    // from outside, a step lasts that interval plus two clock readings and a call, never plus
    // real work (the median over many steps, so a preemption cannot decide it). A dynamic ball
    // in sub-steps presses a deformable rim: every stage has work.
    World world;
    PartSettings rim;
    rim.zones.contactLevel = 3;
    world.add(buildPartModel(makeContainerMouth(), {Material::rigid(), 1.0, {}, {}, {}, {}}), rim, BodySettings{}, Pose{});
    BodySettings heavy = dynamicBody(Vec3(0, -3, 0));
    heavy.density = 0.01;
    world.add(buildPartModel(makeIcoSphere(8.5, 2)), rigidPart(), heavy, at(Vec3(0, 4.8, 0)));  // 0.2 above the rim
    std::vector<double> outsideMinusInside;
    int inContact = 0;
    for (int i = 0; i < 300; ++i) {
        const auto start = std::chrono::steady_clock::now();
        world.step();
        const double outside = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        outsideMinusInside.push_back(outside - world.profile().lastStepSeconds);
        inContact += !world.contacts().empty();
    }
    ASSERT_GT(inContact, 150);
    std::nth_element(outsideMinusInside.begin(), outsideMinusInside.begin() + 150, outsideMinusInside.end());
    EXPECT_GE(outsideMinusInside[150], 0.0);
    EXPECT_LT(outsideMinusInside[150], kCallOverhead) << "work outside the stages";
}

TEST(World, DeterministicRun) {
    auto run = [] {
        BallTorus scene(16.0, 1e-3, Vec3(0.3, -20, 0.1));
        for (int i = 0; i < 400; ++i) scene.world.step();
        return std::make_pair(scene.world.centreOfMass(scene.ball), scene.world.body(scene.ball).linearVelocity);
    };
    const auto a = run(), b = run();
    EXPECT_EQ(a.first, b.first);
    EXPECT_EQ(a.second, b.second);
}

TEST(World, PrepareTakesTheFirstStepsWalkAndChangesNoResult) {
    // A ball just above a deformable rim (the point shell answers the pair), pushed through it:
    // with prepare() the first step walks none of the rim's rest masses (the cold world's first
    // step walks them), and 300 steps end in the same state, bit for bit.
    auto build = [](World& world) {
        PartSettings rim;
        rim.mode = PartMode::RigidDeformable;
        rim.zones.contactLevel = 3;
        world.add(buildPartModel(makeContainerMouth()), rim, BodySettings{}, Pose{});
        BodySettings ball;
        ball.motion = MotionType::Dynamic;
        ball.density = 0.01;
        return world.add(buildPartModel(makeIcoSphere(8.5, 2)), rigidPart(), ball, at(Vec3(0, 4.7, 0)));
    };
    World warm, cold;
    const BodyId warmBall = build(warm), coldBall = build(cold);
    warm.prepare();
    EXPECT_EQ(warm.stepCount(), 0u);
    EXPECT_EQ(warm.stateHash(), cold.stateHash());
    std::size_t warmFirst = 0, coldFirst = 0;
    for (int i = 0; i < 300; ++i) {
        warm.applyForce(warmBall, Vec3(0, -2500, 0));
        cold.applyForce(coldBall, Vec3(0, -2500, 0));
        warm.step();
        cold.step();
        if (i == 0) {
            warmFirst = warm.collision().stats().volumeTests;
            coldFirst = cold.collision().stats().volumeTests;
        }
    }
    EXPECT_LT(warmFirst * 10, coldFirst) << warmFirst << " against " << coldFirst;
    EXPECT_FALSE(warm.contacts().empty());
    EXPECT_EQ(warm.stateHash(), cold.stateHash());
    EXPECT_EQ(warm.collision().faceQueries(), cold.collision().faceQueries());
}

TEST(World, DeformableRimStopsAWeakPushAndYieldsToAStrongOne) {
    auto run = [](double constraint, double push) {
        World world;
        PartSettings rim;
        rim.simulation.restoration = {RestorationMethod::Constraint, 0.0, 0.0, constraint};
        rim.simulation.globalDamping = 1.0;
        rim.zones.contactLevel = 3;
        BodySettings ball;
        ball.motion = MotionType::Dynamic;
        ball.density = 0.01;  // about 25 kg
        const BodyId torus = world.add(buildPartModel(makeContainerMouth(), {Material::rigid(), 1.0, {}, {}, {}, {}}), rim, BodySettings{}, Pose{});
        PartSettings rigid;
        rigid.mode = PartMode::Rigid;
        const BodyId b = world.add(buildPartModel(makeIcoSphere(8.5, 2)), rigid, ball, at(Vec3(0, 11, 0)));
        std::size_t deformed = 0;
        for (int i = 0; i < 2500; ++i) {
            if (push > 0) world.applyForce(b, Vec3(0, -push, 0));
            world.step();
            deformed = std::max(deformed, world.part(torus).movingMasses().size());
        }
        return std::make_pair(world.centreOfMass(b).y(), deformed);
    };
    // A 17 ball under its weight on a stiff rim (k_eff about 5,000 N/m per kg): it rests on the
    // locally deformed rim.
    const auto [resting, deformedStiff] = run(5e-3, 0.0);
    EXPECT_GT(resting, 2.0);
    EXPECT_GT(deformedStiff, 0u);
    // The same ball pushed with 2,500 N against a soft rim (about 11 N/m per kg): it passes.
    const auto [passed, deformedSoft] = run(1e-5, 2500.0);
    EXPECT_LT(passed, -20.0);
    EXPECT_GT(deformedSoft, deformedStiff / 2);
}

// A deforming part left at the restoration constraint's default per-step fraction, at a time
// step other than 1 ms, is reported once per add or settings change, word for word; chosen
// restorations, rigid parts and 1 ms steps are not.
TEST(World, TheDefaultPerStepRestorationAtAnotherTimeStepIsAWarning) {
    WorldSettings fast;
    fast.timeStep = 2e-4;
    World world(fast);
    const auto model = buildPartModel(makeTorus1());
    world.add(model, PartSettings{}, BodySettings{}, Pose{});
    ASSERT_EQ(world.warnings().size(), 1u);
    EXPECT_EQ(world.warnings()[0],
              "body 0: the restoration constraint's default fraction 0.001 is per step, chosen for 1 ms steps: at "
              "WorldSettings::timeStep = 0.0002 the part restores 5 times as fast and resists loads about 25 times as stiffly; "
              "RestorationSettings::constraintRate = 0.5 (1/s) keeps the restoration time, RestorationMethod::AnchorSprings a "
              "stiffness independent of the step");
    PartSettings rate, fraction, anchors, rigid;
    rate.simulation.restoration.constraintRate = 0.5;
    fraction.simulation.restoration.constraintFraction = 2e-3;
    anchors.simulation.restoration.method = RestorationMethod::AnchorSprings;
    rigid.mode = PartMode::Rigid;
    for (const PartSettings& chosen : {rate, fraction, anchors, rigid}) world.add(model, chosen, BodySettings{}, Pose{});
    EXPECT_EQ(world.warnings().size(), 1u);
    world.setPartSettings(3, PartSettings{});  // the anchored part back to the default
    ASSERT_EQ(world.warnings().size(), 2u);
    EXPECT_EQ(world.warnings()[1].rfind("body 3: the restoration constraint's default fraction", 0), 0u) << world.warnings()[1];
    World atOneMs;
    atOneMs.add(model, PartSettings{}, BodySettings{}, Pose{});
    EXPECT_TRUE(atOneMs.warnings().empty());
}

TEST(World, PartSettingsChangeWhileRunning) {
    WorldSettings settings;
    settings.timeStep = 2e-3;
    World world(settings);
    PartSettings rim;
    rim.simulation.restoration = {RestorationMethod::AnchorSprings, 10.0, 6.0, 1e-3};
    rim.zones.contactLevel = 2;
    const BodyId torus = world.add(buildPartModel(makeTorus1()), rim, BodySettings{}, Pose{});
    // A kinematic probe above the top of the tube (torus1: R = 10, r = 2.5).
    PartSettings rigid;
    rigid.mode = PartMode::Rigid;
    BodySettings kinematic;
    kinematic.motion = MotionType::Kinematic;
    const BodyId probe = world.add(buildPartModel(makeIcoSphere(1.0, 2)), rigid, kinematic, Pose{{1, 0, 0, 0}, Vec3(10, 4, 0)});
    const double before = world.contactStiffness(torus);
    // Stiffer anchors and deeper contact zones, live: the contact stiffness follows (mean spring
    // k + k_a), new zones take the new level. The part's own time step and gravity are kept as
    // given and not used: the world's step context rules.
    PartSettings changed = world.part(torus).settings();
    changed.simulation.restoration.anchorStiffness = 50.0;
    changed.simulation.timeStep = 0.5;
    changed.simulation.gravity = Vec3(0, -9.81, 0);
    changed.zones.contactLevel = 4;
    world.setPartSettings(torus, changed);
    EXPECT_NEAR(world.contactStiffness(torus) - before, 40.0, 1e-12);
    EXPECT_EQ(world.part(torus).settings().simulation.timeStep, 0.5);
    world.setKinematicTarget(probe, Pose{{1, 0, 0, 0}, Vec3(10, 3.3, 0)});  // 0.2 into the tube
    world.step();
    ASSERT_FALSE(world.contacts().empty());
    std::vector<int> depths;
    world.part(torus).zoneDepths(depths);
    EXPECT_EQ(*std::max_element(depths.begin(), depths.end()), 3);  // contact zones of level 4: depths 0..3
    EXPECT_EQ(world.part(torus).time(), 2e-3);                      // the world's step, not the part's 0.5 s
    // A mode change or invalid settings are refused and change nothing.
    PartSettings rigidMode = changed;
    rigidMode.mode = PartMode::Rigid;
    EXPECT_THROW(world.setPartSettings(torus, rigidMode), InputError);
    PartSettings bad = changed;
    bad.simulation.restoration.anchorStiffness = -1.0;
    EXPECT_THROW(world.setPartSettings(torus, bad), InputError);
    EXPECT_EQ(world.part(torus).settings().simulation.restoration.anchorStiffness, 50.0);
    EXPECT_THROW(world.setPartSettings(7, changed), InputError);
}

TEST(World, ZoneMassesFeelNoGravityAndPartsKeepTheirSettings) {
    // An open zone under the world's gravity, nothing touching it: its masses stay exactly at
    // rest (a part's rest shape is its shape under its own weight), although the part's own
    // settings, kept as given, ask for gravity.
    World world;  // gravity -9.81 along y
    PartSettings settings;
    settings.simulation.gravity = Vec3(0, -9.81, 0);
    settings.zones.retireCheckInterval = 1000000;
    const BodyId torus = world.add(buildPartModel(makeTorus1()), settings, BodySettings{}, Pose{});
    world.openZone(torus, ZoneSeed::mass(17), 3);
    ASSERT_GT(world.part(torus).movingMasses().size(), 0u);
    for (int i = 0; i < 200; ++i) world.step();
    EXPECT_GT(world.part(torus).movingMasses().size(), 0u);
    EXPECT_EQ(world.part(torus).state().positions, world.part(torus).model().restPositions);
    EXPECT_EQ(world.part(torus).settings().simulation.gravity, Vec3(0, -9.81, 0));
}

TEST(World, CallsRefuseBodiesThatDoNotExist) {
    World world;
    world.add(buildPartModel(makeIcoSphere(1.0, 1)), rigidPart(), dynamicBody(), Pose{});
    EXPECT_THROW(world.applyForce(1, Vec3::UnitX()), InputError);
    EXPECT_THROW(world.applyForceAt(3, Vec3::UnitX(), Vec3::Zero()), InputError);
    EXPECT_THROW(world.setVelocity(1, Vec3::Zero(), Vec3::Zero()), InputError);
    EXPECT_THROW(world.setKinematicTarget(1, Pose{}), InputError);
    EXPECT_THROW(world.openZone(1, ZoneSeed::mass(0), 2), InputError);
    EXPECT_THROW(world.contactStiffness(1), InputError);
    EXPECT_THROW(world.applyMassForce(1, 0, Vec3::UnitX()), InputError);
    EXPECT_THROW(world.part(1), InputError);
    EXPECT_THROW(world.body(1), InputError);
    EXPECT_THROW(world.centreOfMass(1), InputError);
    EXPECT_THROW(world.assembled(0), InputError);
    EXPECT_THROW(world.applyForce(0, Vec3(NAN, 0, 0)), InputError);  // and forces that are not finite
    EXPECT_THROW(world.setVelocity(0, Vec3(INFINITY, 0, 0), Vec3::Zero()), InputError);
    world.step();
    EXPECT_TRUE(world.body(0).linearVelocity.allFinite());
}

// World calls name a mass by the user's vertex: a model renumbered for locality and the same
// shuffled mesh in its given order, loaded at the same vertices, move alike (up to the
// summation order), a deforming part and a rigid dynamic body.
TEST(World, MassLoadsNameTheUsersVertexInEveryVertexOrder) {
    const TriMesh shuffled = shuffledVertices(makeTorus(3.0, 1.0, 24, 16), 7);
    const Vec3 force(0.2, -0.1, 0.05), kick(0.0, 0.5, 0.0);
    std::vector<Vec3> shapes[2];
    Pose ballPoses[2];
    for (const VertexOrder order : {VertexOrder::AsGiven, VertexOrder::Locality}) {
        PartModelSettings settings;
        settings.vertexOrder = order;
        const auto model = buildPartModel(shuffled, settings);
        ASSERT_EQ(model->renumbered(), order == VertexOrder::Locality);
        World world;
        const BodyId part = world.add(model, PartSettings{}, BodySettings{}, Pose{});
        const BodyId ball = world.add(model, rigidPart(), dynamicBody(), at(Vec3(20, 0, 0)));
        world.openZone(part, ZoneSeed::mass(11), 2);
        EXPECT_TRUE(world.part(part).isMoving(model->massOf(11)));
        world.kickMass(part, 200, kick);
        world.kickMass(ball, 200, kick);
        for (int i = 0; i < 60; ++i) {
            world.applyMassForce(part, 37, force);
            world.applyMassForce(ball, 37, force);
            world.step();
        }
        const int k = order == VertexOrder::Locality;
        world.part(part).vertexWorldPositions(shapes[k]);
        ballPoses[k] = world.part(ball).pose();
        EXPECT_THROW(world.applyMassForce(part, Index(shuffled.vertices.size()), force), InputError);
        EXPECT_THROW(world.kickMass(ball, Index(shuffled.vertices.size()), kick), InputError);
    }
    for (const Index v : {37u, 200u}) EXPECT_GT((shapes[0][v] - shuffled.vertices[v]).norm(), 1e-4) << "vertex " << v << " was loaded";
    for (std::size_t v = 0; v < shuffled.vertices.size(); ++v) EXPECT_NEAR((shapes[1][v] - shapes[0][v]).norm(), 0.0, 1e-12) << v;
    EXPECT_NEAR((ballPoses[1].translation - ballPoses[0].translation).norm(), 0.0, 1e-12);
    EXPECT_NEAR(ballPoses[1].rotation.angularDistance(ballPoses[0].rotation), 0.0, 1e-12);
    EXPECT_GT(ballPoses[0].rotation.angularDistance(Eigen::Quaterniond::Identity()), 1e-4) << "the loads turned the body";
}

TEST(World, WorldsSteppedOnSeveralThreadsAtOnceMatchEachRunAlone) {
    // Each world keeps its own state and the library's scratch is per thread: a program may
    // step several worlds at once (a sweep in threads, a server of sessions). Two scenes, a
    // ball through a deformable rim by the point shell and a rigid ball onto the rigid mouth by
    // faces (the coherent queries, zones, the contact solver), each run alone and then both
    // twice on four threads at once: the same state, bit for bit.
    auto run = [](int which) {
        if (which == 0) {
            World world;
            PartSettings rim;
            rim.zones.contactLevel = 3;
            world.add(buildPartModel(makeContainerMouth()), rim, BodySettings{}, Pose{});
            BodySettings heavy = dynamicBody(Vec3(0, -3, 0));
            heavy.density = 0.01;
            world.add(buildPartModel(makeIcoSphere(8.5, 2)), rigidPart(), heavy, at(Vec3(0, 5.5, 0)));
            int inContact = 0;
            for (int i = 0; i < 400; ++i) {
                world.step();
                inContact += !world.contacts().empty();
            }
            return std::make_pair(world.stateHash(), inContact);
        }
        BallTorus rigid(16.0, 1e-3, Vec3(0.3, -20, 0.1));
        int inContact = 0;
        for (int i = 0; i < 1000; ++i) {
            rigid.world.step();
            inContact += rigid.world.body(rigid.ball).linearVelocity.y() > -1.0;  // held up by the mouth (it falls at 20)
        }
        return std::make_pair(rigid.world.stateHash(), inContact);
    };
    const std::pair<std::uint64_t, int> alone[2] = {run(0), run(1)};
    ASSERT_GT(alone[0].second, 100);
    ASSERT_GT(alone[1].second, 100);
    std::pair<std::uint64_t, int> together[4] = {};
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t) threads.emplace_back([&, t] { together[t] = run(t % 2); });
    for (std::thread& t : threads) t.join();
    for (int t = 0; t < 4; ++t) EXPECT_EQ(together[t], alone[t % 2]) << "thread " << t;
}

TEST(World, SettingsWithAnEnumValueThatIsNoneOrASubnormalStepAreRefused) {
    // An integer cast to an enum (from a binding, a file read by the user's own code) ran as
    // some value; a subnormal step overflowed h/m. Each is an InputError naming the setting.
    auto refused = [](auto make, const std::string& words) {
        try {
            make();
            ADD_FAILURE() << "accepted: " << words;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    };
    WorldSettings bad;
    bad.collision.exactTest = static_cast<ExactTest>(42);
    refused([&] { World w(bad); }, "exact test 42 is not one of its values");
    bad = WorldSettings{};
    bad.timeStep = 1e-320;
    refused([&] { World w(bad); }, "below the smallest normal double");
    World world;
    const auto ball = buildPartModel(makeIcoSphere(1.0, 1));
    BodySettings body;
    body.motion = static_cast<MotionType>(9);
    refused([&] { world.add(ball, rigidPart(), body, Pose{}); }, "body motion 9");
    PartSettings part = rigidPart();
    part.mode = static_cast<PartMode>(7);
    refused([&] { world.add(ball, part, BodySettings{}, Pose{}); }, "part mode 7");
    part = PartSettings{};
    part.simulation.integrator = static_cast<Integrator>(42);
    refused([&] { world.add(ball, part, BodySettings{}, Pose{}); }, "integrator 42");
    EXPECT_EQ(world.bodyCount(), 0u);
    world.add(ball, rigidPart(), BodySettings{}, Pose{});
    world.add(ball, rigidPart(), BodySettings{}, at(Vec3(5, 0, 0)));
    AssemblyRule rule;
    rule.primary = 0;
    rule.secondary = 1;
    rule.technique = static_cast<SnapTechnique>(12);
    refused([&] { world.addAssembly(rule); }, "technique 12");
}

TEST(World, SubstepsAndContactIterationsHaveTheScenesBounds) {
    // 2^31 contact iterations a sub-step never ended; the API now has the scene file's bounds.
    for (const auto& [substeps, iterations] : {std::pair{0, 8}, std::pair{kMostSubsteps + 1, 8}, std::pair{16, 0}, std::pair{16, 2147483647}}) {
        WorldSettings s;
        s.maxSubsteps = substeps;
        s.contactIterations = iterations;
        EXPECT_THROW(World w(s), InputError) << substeps << " " << iterations;
    }
    WorldSettings most;
    most.maxSubsteps = kMostSubsteps;
    most.contactIterations = kMostContactIterations;
    World accepted(most);
    EXPECT_EQ(accepted.bodyCount(), 0u);
}
