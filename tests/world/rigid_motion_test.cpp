// The rigid motion stage (src/world/rigid_motion.cpp) against analytic mechanics (free fall,
// torque-free rotation), its sub-steps against the no-tunnelling bound, and balls against the
// container-mouth torus (outer diameter 25, inner 15): wider balls never pass, at any speed
// reached in the experiments and the largest time step; narrower ones do. A stack stepped in
// steps longer than its gaps take to close comes to rest (statics: zero velocity, each box on
// the one below).
#include "test_bodies.hpp"
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

using namespace flexfit;
using namespace flexfit::testing;

TEST(RigidMotion, FreeFallFollowsTheParabola) {
    World world(WorldSettings{1e-3, Vec3(0, -9.81, 0), {}, 0.25, 4096, 4});
    const BodyId ball = world.add(buildPartModel(makeIcoSphere(1.0, 2)), rigidPart(), dynamicBody(Vec3(2, 5, 0)), at(Vec3(0, 100, 0)));
    const Vec3 start = world.centreOfMass(ball);
    for (int i = 0; i < 1000; ++i) world.step();
    const double t = world.time();
    const Vec3 expected = start + Vec3(2, 5, 0) * t + 0.5 * Vec3(0, -9.81, 0) * t * t;
    // Semi-implicit Euler: the position leads the parabola by g h t / 2.
    EXPECT_LT((world.centreOfMass(ball) - expected).norm(), 0.5 * 9.81 * 1e-3 * t + 1e-9);
    EXPECT_NEAR(world.body(ball).linearVelocity.y(), 5 - 9.81 * t, 1e-9);
}

TEST(RigidMotion, TorqueFreeRotationConservesAngularMomentum) {
    WorldSettings settings;
    settings.gravity = Vec3::Zero();
    settings.timeStep = 1e-4;
    World world(settings);
    BodySettings b = dynamicBody();
    b.angularVelocity = Vec3(0.3, 2.0, 0.1);  // near the intermediate axis would tumble; this is near the major one
    const BodyId id = world.add(buildPartModel(makeTorus(3.0, 1.0, 32, 16)), rigidPart(), b, Pose{});
    auto momentum = [&] {
        const Eigen::Matrix3d r = world.part(id).pose().rotation.toRotationMatrix();
        const Eigen::Matrix3d inertia = (r * world.body(id).inverseInertia * r.transpose()).inverse();
        return Vec3(inertia * world.body(id).angularVelocity);
    };
    const Vec3 l0 = momentum();
    for (int i = 0; i < 10000; ++i) world.step();
    EXPECT_LT((momentum() - l0).norm() / l0.norm(), 2e-2);
}

// A spin whose motion overflows in one step leaves no distance to quote: the error says the
// speeds are no longer finite (it printed "moves -nan units in one step").
TEST(RigidMotion, ASpinThatOverflowsIsADivergenceNamingTheSpeeds) {
    World world(WorldSettings{1e-3, Vec3::Zero(), {}, 0.25, 4096, 4});
    BodySettings b = dynamicBody();
    b.angularVelocity = Vec3(1e300, 0, 0);
    world.add(buildPartModel(makeIcoSphere(1.0, 1)), rigidPart(), b, Pose{});
    try {
        for (int i = 0; i < 3; ++i) world.step();
        ADD_FAILURE() << "no divergence";
    } catch (const DivergenceError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("body 0 diverged at t = 0 s: its velocity or angular velocity is no longer finite"), std::string::npos) << what;
        EXPECT_EQ(what.find("units in one step"), std::string::npos) << what;
    }
}

TEST(RigidMotion, BallWiderThanTheOpeningRestsOnTheRim) {
    BallTorus scene(17.0, 2e-3, Vec3::Zero());
    for (int i = 0; i < 1000; ++i) scene.world.step();
    const double resting = scene.ballHeight();
    EXPECT_GT(resting, 0.0);  // above the torus's middle plane: held by the rim
    for (int i = 0; i < 250; ++i) scene.world.step();
    EXPECT_NEAR(scene.ballHeight(), resting, 0.05);  // and stays there
    EXPECT_LT(scene.world.body(scene.ball).linearVelocity.norm(), 0.2);
}

// Sanitizer builds run ~30x slower: they check the largest time step and the tightest ball
// only, and not the ball both pushed and thrown (the Release run checks the whole sweep; the
// sanitizers look for memory errors, which the same code paths would show with either ball, and
// the pushed ball and the thrown one run the contact and the sub-step paths apart; the pushed
// and thrown ball took 45 s there, most of it in its crossing step).
#if defined(__SANITIZE_ADDRESS__)
constexpr double kTimeSteps[] = {1.0 / 30};
constexpr double kBallWidths[] = {1.005};
constexpr bool kPushedAndThrown = false;
#else
constexpr double kTimeSteps[] = {1.0 / 120, 1.0 / 30};
constexpr double kBallWidths[] = {1.005, 2.0};
constexpr bool kPushedAndThrown = true;
#endif

namespace {

// The radius of the largest sphere about the origin inside a convex mesh: its nearest face plane.
double inRadius(const TriMesh& mesh) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const Face& f : mesh.faces) {
        const Vec3 &a = mesh.vertices[f[0]], &b = mesh.vertices[f[1]], &c = mesh.vertices[f[2]];
        nearest = std::min(nearest, std::abs((b - a).cross(c - a).normalized().dot(a)));
    }
    return nearest;
}

// An icosphere (level 3) whose inscribed sphere has radius `radius`: every point of that
// sphere is inside the polyhedron, so the ball is at least that wide in every direction.
TriMesh ballAtLeast(double radius) {
    const double unit = inRadius(makeIcoSphere(1.0, 3));
    return makeIcoSphere(radius / unit, 3);
}

struct ThinPart {
    const char* name;
    TriMesh mesh;
    double opening;  // radius of the largest circle through it, about the y axis
};

// Drops (and pushes, and throws) the ball down the y axis at the part; returns the lowest
// height its centre reached inside the opening (within `opening` of the axis): below 0, it went
// through. (A ball thrown hard can bounce off a faceted rim and fall past the part's outside.)
double lowestThrough(const ThinPart& part, const TriMesh& ball, double force, double speed, double dt, double duration) {
    World world(WorldSettings{dt, Vec3(0, -9.81, 0), {}, 0.25, 4096, 8});
    world.add(buildPartModel(part.mesh), rigidPart(), BodySettings{}, Pose{});
    const double radius = boundingBox(ball).sizes().y() / 2;
    const BodyId id = world.add(buildPartModel(ball), rigidPart(), dynamicBody(Vec3(0, -speed, 0)), at(Vec3(0, radius + 3.0, 0)));
    double lowest = world.centreOfMass(id).y();
    for (double t = 0; t < duration; t += dt) {
        world.applyForce(id, Vec3(0, -force, 0));
        world.step();
        const Vec3 centre = world.centreOfMass(id);
        if (std::hypot(centre.x(), centre.z()) < part.opening) lowest = std::min(lowest, centre.y());
    }
    return lowest;
}

}  // namespace

namespace {

// Balls from a hair (0.5 %) wider than the opening to twice it, pushed with up to 1e6 N and
// thrown at up to 1e4 units/s with time steps up to 1/30 s: none gets through. A ball 10 %
// narrower than the opening falls through. (One test per part, so ctest runs them side by side:
// together they were the suite's longest under the sanitizers, 108 s.)
void expectNoTunnelling(const ThinPart& part) {
    for (double width : kBallWidths) {
        const TriMesh ball = ballAtLeast(width * part.opening);
        for (double force : {0.0, 1e6})
            for (double speed : {0.0, 1e4}) {
                if (force > 0.0 && speed > 0.0 && !kPushedAndThrown) continue;
                for (double dt : kTimeSteps)
                    EXPECT_GT(lowestThrough(part, ball, force, speed, dt, 0.5), 0.0)
                        << part.name << ": ball " << width << " x the opening, force " << force << ", speed " << speed << ", dt " << dt;
            }
    }
    const TriMesh narrower = makeIcoSphere(0.9 * part.opening, 3);  // its vertices are on the sphere
    EXPECT_LT(lowestThrough(part, narrower, 0.0, 0.0, 1.0 / 120, 2.5), -5.0) << part.name;
}

}  // namespace

TEST(RigidMotion, NoTunnellingThroughTheContainerMouthUnderAnyLoad) {
    expectNoTunnelling({"container mouth", makeContainerMouth(), 7.5});  // opening 15
}

TEST(RigidMotion, NoTunnellingThroughAPlateUnderAnyLoad) {
    expectNoTunnelling({"plate", makePlateWithHole(Vec3(6, 0.25, 6), 2.0, 2.0), 2.0});  // 0.5 thick, square hole
}

TEST(RigidMotion, SubStepsKeepEachMoveBelowTheTravelBound) {
    // A ball thrown at 300 units/s with h = 10 ms travels 3 units a step; the thinnest body's
    // bound is 0.25 x 1.0 (its own smallest half-extent), so each step takes ceil(3 / 0.25) = 12
    // sub-steps (gravity off, nothing in the way).
    WorldSettings settings;
    settings.timeStep = 1e-2;
    settings.gravity = Vec3::Zero();
    World world(settings);
    world.add(buildPartModel(makeIcoSphere(1.0, 3)), rigidPart(), dynamicBody(Vec3(300, 0, 0)), Pose{});
    const double halfExtent = world.body(0).thickness;
    ASSERT_NEAR(halfExtent, 1.0, 1e-9);
    for (int i = 0; i < 10; ++i) world.step();
    EXPECT_EQ(world.profile().substeps, 10u * std::uint64_t(std::ceil(3.0 / (0.25 * halfExtent) - 1e-12)));
    EXPECT_NEAR(world.centreOfMass(0).x(), 30.0, 1e-9);
}

namespace {

BodySettings kinematicBody() {
    BodySettings b;
    b.motion = MotionType::Kinematic;
    return b;
}

}  // namespace

TEST(RigidMotion, AKinematicBodyIsStoppedByAStaticPart) {
    // Sent through a slab 0.5 thick in one step: it stops on the slab, not beyond it, and its
    // velocity is the move it made.
    World world(WorldSettings{1e-3, Vec3::Zero(), {}, 0.25, 4096, 8});
    world.add(buildPartModel(makeBox(Vec3(5, 0.25, 5))), rigidPart(), BodySettings{}, Pose{});
    const BodyId box = world.add(buildPartModel(makeBox(Vec3::Constant(0.5), 2)), rigidPart(), kinematicBody(), at(Vec3(0, 3, 0)));
    world.setKinematicTarget(box, at(Vec3(0, -3, 0)));
    world.step();
    const double y = world.centreOfMass(box).y();
    EXPECT_GT(y, 0.75 - 0.01 * 0.25 - 1e-9);  // on the slab, at most the contact slop into it
    EXPECT_LT(y, 0.75 + 6.0 / 64);            // within the last bisection of a sub-step
    EXPECT_NEAR(world.body(box).linearVelocity.y(), (y - 3.0) / 1e-3, 1e-6);
    // Unblocked, it reaches its target exactly.
    world.setKinematicTarget(box, at(Vec3(4, 3, 1)));
    world.step();
    EXPECT_EQ(world.part(box).pose().translation, Vec3(4, 3, 1));
}

TEST(RigidMotion, AKinematicBodyPushesDynamicBodiesAlongItsWay) {
    // A kinematic cube swept 5 units in one step through the place of a dynamic cube: the
    // dynamic cube is pushed ahead of it, not left behind or passed through.
    World world(WorldSettings{1e-3, Vec3::Zero(), {}, 0.25, 4096, 8});
    const BodyId pusher = world.add(buildPartModel(makeBox(Vec3::Constant(0.5), 2)), rigidPart(), kinematicBody(), Pose{});
    const BodyId pushed = world.add(buildPartModel(makeBox(Vec3::Constant(0.5), 2)), rigidPart(), dynamicBody(), at(Vec3(2, 0, 0)));
    world.setKinematicTarget(pusher, at(Vec3(5, 0, 0)));
    world.step();
    EXPECT_EQ(world.part(pusher).pose().translation, Vec3(5, 0, 0));
    EXPECT_GT(world.centreOfMass(pushed).x() - 5.0, 1.0 - 0.25);  // ahead, overlapping less than a sub-step's travel
    EXPECT_GT(world.body(pushed).linearVelocity.x(), 0.0);
}

TEST(RigidMotion, AKinematicBodyDeformsThePartsItCrosses) {
    // A kinematic ball crosses the tube of a rigid-deformable torus in one step: neither its
    // start nor its target touches the torus, yet the masses on its way are pressed.
    World world;
    const BodyId torus = world.add(buildPartModel(makeTorus1()), PartSettings{}, BodySettings{}, Pose{});
    const BodyId ball = world.add(buildPartModel(makeIcoSphere(1.0, 2)), rigidPart(), kinematicBody(), at(Vec3(10, 5, 0)));
    world.setKinematicTarget(ball, at(Vec3(10, -5, 0)));
    world.step();
    EXPECT_EQ(world.part(ball).pose().translation, Vec3(10, -5, 0));
    EXPECT_GT(world.part(torus).movingMasses().size(), 0u);
    double deepest = 0.0;
    for (Index m : world.part(torus).movingMasses())
        deepest = std::max(deepest, (world.part(torus).state().positions[m] - world.part(torus).model().restPositions[m]).norm());
    EXPECT_GT(deepest, 0.1);
}

TEST(RigidMotion, AKinematicBodyTurnsToItsTargetTheShortWay) {
    // A target turned 270 degrees about y is reached exactly, with the spin of the short way
    // round: -90 degrees in the step.
    World world(WorldSettings{1e-3, Vec3::Zero(), {}, 0.25, 4096, 8});
    const BodyId box = world.add(buildPartModel(makeBox(Vec3(1, 0.5, 0.25))), rigidPart(), kinematicBody(), Pose{});
    const Pose target{Eigen::Quaterniond(Eigen::AngleAxisd(1.5 * M_PI, Vec3::UnitY())), Vec3(0, 0, 0)};
    world.setKinematicTarget(box, target);
    world.step();
    EXPECT_LT(world.part(box).pose().rotation.angularDistance(target.rotation), 1e-12);
    EXPECT_LT((world.body(box).angularVelocity - Vec3(0, -0.5 * M_PI / 1e-3, 0)).norm(), 1e-6);
    EXPECT_GT(world.profile().substeps, 1u);  // the swept turn took sub-steps
}

// examples/stack.toml (three boxes put 1e-4 apart on a floor) stepped at 20 Hz: gravity moves a
// box 0.025 a step, four times the contact slop, so each box's move is cut short. Before the
// cut bodies were settled again against the others' cut moves, the bottom box was held back by
// the middle box's whole move, no gap ever closed, and the standing boxes' velocities grew by g
// h a step (29.4 after 3 s) with their sub-steps. At rest: every box still (well below g h =
// 0.49), each on the one below within the contact slop, one sub-step a step.
TEST(RigidMotion, AStackSteppedInStepsLongerThanItsGapsComesToRest) {
    std::ifstream file(FLEXFIT_EXAMPLES_DIR "/stack.toml");
    std::stringstream text;
    text << file.rdbuf();
    std::string scene = text.str();
    const std::string fine = "time_step = 0.001";
    ASSERT_NE(scene.find(fine), std::string::npos);
    scene.replace(scene.find(fine), fine.size(), "time_step = 0.05");
    SceneRun run(parseScene(scene, "stack.toml", FLEXFIT_EXAMPLES_DIR));
    World& world = run.world();
    while (!run.finished()) run.step();
    const std::uint64_t substeps = world.profile().substeps;
    run.step();
    EXPECT_EQ(world.profile().substeps - substeps, 1u);
    const double slop = world.settings().contactSlop * 0.6;  // the thinnest body: the top box, 0.6 thick
    const double halves[] = {0.6, 0.45, 0.3};
    double top = 0.0;  // the floor's
    for (BodyId box = 1; box <= 3; ++box) {
        EXPECT_LT(world.body(box).linearVelocity.norm(), 0.05) << "box " << box;
        EXPECT_LT(world.body(box).angularVelocity.norm(), 0.05) << "box " << box;
        const double bottomFace = world.centreOfMass(box).y() - halves[box - 1];
        EXPECT_NEAR(bottomFace, top, slop) << "box " << box;
        top = world.centreOfMass(box).y() + halves[box - 1];
    }
}

// The no-tunnelling bound is the world's, from its thinnest body: a body far away declared
// 1e-12 thick holds every sub-step of a falling ball to 1e-12 / 4, and the ball's step then
// fails. The error names the thin body and its thickness (it named only the ball, with a
// bound printed as 0.000000).
TEST(RigidMotion, ABoundTooSmallToFollowNamesTheThinnestBody) {
    WorldSettings settings;
    settings.gravity = Vec3(0, -9.81, 0);
    World world(settings);
    const auto ball = buildPartModel(makeIcoSphere(1.0, 1));
    world.add(ball, rigidPart(), dynamicBody(Vec3(0, -5, 0)), at(Vec3(0, 5, 0)));
    BodySettings thin;
    thin.motion = MotionType::Static;
    thin.thickness = 1e-12;
    world.add(ball, rigidPart(), thin, at(Vec3(100, 0, 0)));
    try {
        for (int i = 0; i < 10; ++i) world.step();
        ADD_FAILURE() << "the ball followed a bound of 1e-12";
    } catch (const DivergenceError& e) {
        const std::string text = e.what();
        EXPECT_NE(text.find("thinnest body's thickness, 1e-12: body 1"), std::string::npos) << text;
    }
}
