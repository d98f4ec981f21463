// The operator's grab against the analytic critically damped oscillator and statics (the
// coupling holds a body's weight), and forces on selected masses and faces.
#include "flexfit/flexfit.hpp"
#include "test_bodies.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace flexfit;

namespace {

using flexfit::testing::at;

struct GrabbedBall {
    World world;
    BodyId ball = 0;
    explicit GrabbedBall(Vec3 gravity, MotionType motion = MotionType::Dynamic)
        : world(WorldSettings{1e-3, gravity, {}, 0.25, 4096, 4}) {
        PartSettings rigid;
        rigid.mode = PartMode::Rigid;
        BodySettings b;
        b.motion = motion;
        ball = world.add(buildPartModel(makeIcoSphere(1.0, 2)), rigid, b, at(Vec3::Zero()));
    }
    void run(double seconds) {
        for (int i = 0, n = int(std::lround(seconds / world.settings().timeStep)); i < n; ++i) world.step();
    }
};

}  // namespace

TEST(Operator, GrabFollowsAMovingTargetAsTheCriticallyDampedOscillator) {
    GrabbedBall s(Vec3::Zero());
    s.world.grab(s.ball);
    const double x0 = s.world.centreOfMass(s.ball).x(), u = 1.0;  // target moves at u along x
    const double omega = 2.0 * M_PI * 10.0;
    for (double t : {0.02, 0.05, 0.1, 0.3}) {
        while (s.world.time() < t - 1e-9) {
            s.world.setGrabTarget(at(Vec3(u * s.world.time(), 0, 0)));  // the device, sampled now
            s.world.step();
        }
        // Error e = x - u t from e(0) = 0, e'(0) = -u under critical damping: -u t exp(-w t).
        const double expected = -u * t * std::exp(-omega * t);
        EXPECT_NEAR(s.world.centreOfMass(s.ball).x() - x0 - u * t, expected, 4e-4) << "t = " << t;
    }
    EXPECT_LT(s.world.coupling().force.norm(), 1e-3 * s.world.body(s.ball).mass * omega * omega);
}

TEST(Operator, CouplingCarriesTheWeightOfTheHeldBody) {
    GrabbedBall s(Vec3(0, -9.81, 0));
    s.world.grab(s.ball);
    s.run(1.0);
    const double weight = s.world.body(s.ball).mass * 9.81;
    const Coupling& c = s.world.coupling();
    ASSERT_TRUE(c.active);
    EXPECT_NEAR(c.force.y() / weight, 1.0, 1e-6);
    EXPECT_NEAR(c.force.x(), 0.0, 1e-9 * weight);
    // Sag of a spring k = m w^2 holding m g: g / w^2.
    const double omega = 2.0 * M_PI * 10.0;
    EXPECT_NEAR(s.world.centreOfMass(s.ball).y(), -9.81 / (omega * omega), 1e-6);
}

TEST(Operator, GrabRotatesTheBodyToTheTarget) {
    GrabbedBall s(Vec3::Zero());
    s.world.grab(s.ball);
    const Eigen::Quaterniond turned(Eigen::AngleAxisd(0.5, Vec3(0, 1, 0)));
    s.world.setGrabTarget(Pose{turned, Vec3::Zero()});
    s.run(1.0);
    EXPECT_LT(s.world.part(s.ball).pose().rotation.angularDistance(turned), 1e-4);
    EXPECT_LT(s.world.coupling().torque.norm(), 1e-6);
}

TEST(Operator, KinematicBodyFollowsTheTargetExactly) {
    GrabbedBall s(Vec3::Zero(), MotionType::Kinematic);
    s.world.grab(s.ball);
    s.world.setGrabTarget(at(Vec3(0, 2, 0)));
    s.world.step();
    EXPECT_NEAR(s.world.part(s.ball).pose().translation.y(), 2.0, 1e-12);
    EXPECT_NEAR(s.world.body(s.ball).linearVelocity.y(), 2.0 / 1e-3, 1e-6);
}

TEST(Operator, ReleaseStopsTheCoupling) {
    GrabbedBall s(Vec3(0, -9.81, 0));
    s.world.grab(s.ball);
    s.run(0.2);
    s.world.release();
    EXPECT_FALSE(s.world.coupling().active);
    const double v0 = s.world.body(s.ball).linearVelocity.y();
    s.run(0.1);
    EXPECT_NEAR(s.world.body(s.ball).linearVelocity.y(), v0 - 9.81 * 0.1, 1e-6);  // free fall again
}

TEST(Operator, RefusesStaticBodiesAndUnstableCouplings) {
    World world;
    PartSettings rigid;
    rigid.mode = PartMode::Rigid;
    const BodyId wall = world.add(buildPartModel(makeIcoSphere(1.0, 1)), rigid, BodySettings{}, Pose{});
    EXPECT_THROW(world.grab(wall), InputError);
    BodySettings b;
    b.motion = MotionType::Dynamic;
    const BodyId ball = world.add(buildPartModel(makeIcoSphere(1.0, 1)), rigid, b, at(Vec3(5, 0, 0)));
    GrabSettings stiff;
    stiff.stiffness = 1e12;
    EXPECT_THROW(world.grab(ball, stiff), InputError);
    EXPECT_FALSE(world.grabbed());
    GrabSettings nan;
    nan.frequency = std::nan("");
    EXPECT_THROW(world.grab(ball, nan), InputError);
    EXPECT_NO_THROW(world.grab(ball));
}

TEST(Operator, DefaultCouplingIsStableAtLargeTimeSteps) {
    World world(WorldSettings{0.02, Vec3::Zero(), {}, 0.25, 4096, 4});
    PartSettings rigid;
    rigid.mode = PartMode::Rigid;
    BodySettings b;
    b.motion = MotionType::Dynamic;
    const BodyId ball = world.add(buildPartModel(makeIcoSphere(1.0, 1)), rigid, b, Pose{});
    world.grab(ball);
    world.setGrabTarget(at(Vec3(3, 0, 0)));
    for (int i = 0; i < 200; ++i) world.step();
    EXPECT_NEAR(world.centreOfMass(ball).x() - world.body(ball).centreOfMass.x(), 3.0, 1e-3);
}

TEST(Operator, FaceForceDeformsADeformablePartAndPushesARigidOne) {
    World world(WorldSettings{1e-3, Vec3::Zero(), {}, 0.25, 4096, 4});
    PartSettings soft;
    const BodyId torus = world.add(buildPartModel(makeTorus1()), soft, BodySettings{}, Pose{});
    world.applyFaceForce(torus, 0, Vec3(0, -30, 0));
    world.step();
    EXPECT_EQ(world.part(torus).zoneCount(), 1u);
    EXPECT_GT(world.part(torus).movingMasses().size(), 0u);
    EXPECT_THROW(world.applyFaceForce(torus, 1u << 30, Vec3::UnitY()), InputError);

    PartSettings rigid;
    rigid.mode = PartMode::Rigid;
    BodySettings b;
    b.motion = MotionType::Dynamic;
    const BodyId ball = world.add(buildPartModel(makeIcoSphere(1.0, 2)), rigid, b, at(Vec3(0, 20, 0)));
    // A force on the ball's top-most mass along x: linear push plus torque r x F about the centre.
    Index top = 0;
    const auto& rest = world.part(ball).model().restPositions;
    for (Index m = 0; m < rest.size(); ++m)
        if (rest[m].y() > rest[top].y()) top = m;
    world.applyMassForce(ball, top, Vec3(1, 0, 0));
    world.step();
    EXPECT_NEAR(world.body(ball).linearVelocity.x(), 1e-3 * world.body(ball).inverseMass, 1e-12);
    EXPECT_LT(world.body(ball).angularVelocity.z(), 0.0);  // (0, r, 0) x (1, 0, 0) points along -z

    // A kick on the same mass of the rigid ball: the impulse m_i dv at that mass, at once.
    const RigidBody before = world.body(ball);
    const Vec3 r = world.part(ball).worldPosition(top) - world.centreOfMass(ball);
    const double mi = world.part(ball).model().mass[top];
    world.kickMass(ball, top, Vec3(0, 0, 2));
    const Eigen::Matrix3d rot = world.part(ball).pose().rotation.toRotationMatrix();
    const Vec3 expectedSpin = rot * before.inverseInertia * rot.transpose() * r.cross(Vec3(0, 0, 2 * mi));
    EXPECT_LT((world.body(ball).linearVelocity - before.linearVelocity - Vec3(0, 0, 2 * mi * before.inverseMass)).norm(), 1e-12);
    EXPECT_LT((world.body(ball).angularVelocity - before.angularVelocity - expectedSpin).norm(), 1e-12);
    EXPECT_THROW(world.kickMass(ball, 1u << 30, Vec3::UnitY()), InputError);
    EXPECT_THROW(world.kickMass(ball, 0, Vec3(NAN, 0, 0)), InputError);
}
