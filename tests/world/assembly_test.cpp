// Snapping: each technique's positive and negative case (geometry worked out by hand), the
// interpolated snap, and a ball falling through the container mouth assembled by zone
// snap-fitting in the world.
#include "flexfit/flexfit.hpp"
#include "test_bodies.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace flexfit;

namespace {

using flexfit::testing::at;

AssemblyRule rule(SnapTechnique technique) {
    AssemblyRule r;
    r.name = toString(technique);
    r.technique = technique;
    r.finalRelativePose = at(Vec3(0, -8, 0));
    r.primaryVector = {Vec3(0, -1, 0), Vec3(0, 1, 0)};  // a vertical diameter of the primary
    r.secondaryVector = {Vec3(0, -9, 0), Vec3(0, -7, 0)};
    r.area.shape = AssemblyArea::Shape::Cylinder;
    r.area.frame = at(Vec3(0, -8, 0));
    r.area.radius = 3.0;
    r.area.halfHeight = 2.0;
    return r;
}

}  // namespace

TEST(Assembly, CollisionSnapNeedsContact) {
    const AssemblyRule r = rule(SnapTechnique::CollisionSnap);
    EXPECT_TRUE(snapConditionHolds(r, at(Vec3(5, 5, 5)), Pose{}, true));
    EXPECT_FALSE(snapConditionHolds(r, at(Vec3(0, -8, 0)), Pose{}, false));
}

TEST(Assembly, ProximitySnapWithinDistanceAndAngle) {
    const AssemblyRule r = rule(SnapTechnique::ProximitySnap);
    const Pose secondary = at(Vec3(10, 0, 0));
    EXPECT_TRUE(snapConditionHolds(r, at(Vec3(10.3, -8, 0.2), 0.1), secondary, false));
    EXPECT_FALSE(snapConditionHolds(r, at(Vec3(10.8, -8, 0)), secondary, false));      // too far
    EXPECT_FALSE(snapConditionHolds(r, at(Vec3(10, -8, 0), 0.5), secondary, false));   // turned too much
}

TEST(Assembly, VectorSnapRefusesTheWrongOrientation) {
    const AssemblyRule r = rule(SnapTechnique::VectorSnap);
    EXPECT_TRUE(snapConditionHolds(r, at(Vec3(0.2, -8, 0)), Pose{}, false));
    // Upside down: the primary's origin lands on the secondary's end and vice versa.
    EXPECT_FALSE(snapConditionHolds(r, at(Vec3(0, -8, 0), M_PI, Vec3::UnitX()), Pose{}, false));
    EXPECT_FALSE(snapConditionHolds(r, at(Vec3(0, -6, 0)), Pose{}, false));  // ends 2 apart
}

TEST(Assembly, ZoneSnapNeedsTheWholeVectorInsideTheArea) {
    const AssemblyRule r = rule(SnapTechnique::ZoneSnap);
    EXPECT_TRUE(snapConditionHolds(r, at(Vec3(1, -8.5, 0)), Pose{}, false));
    EXPECT_FALSE(snapConditionHolds(r, at(Vec3(0, -5.5, 0)), Pose{}, false));   // upper end out (y -4.5 > -6)
    EXPECT_FALSE(snapConditionHolds(r, at(Vec3(3.5, -8, 0)), Pose{}, false));   // beside the cylinder
    AssemblyRule box = r;
    box.area.shape = AssemblyArea::Shape::Box;
    box.area.halfExtents = Vec3(1, 2, 1);
    EXPECT_TRUE(snapConditionHolds(box, at(Vec3(0.5, -8, -0.5)), Pose{}, false));
    EXPECT_FALSE(snapConditionHolds(box, at(Vec3(1.5, -8, 0)), Pose{}, false));
    AssemblyRule sphere = r;
    sphere.area.shape = AssemblyArea::Shape::Sphere;
    sphere.area.radius = 1.5;
    EXPECT_TRUE(snapConditionHolds(sphere, at(Vec3(0, -8.3, 0)), Pose{}, false));
    EXPECT_FALSE(snapConditionHolds(sphere, at(Vec3(0, -8.7, 0)), Pose{}, false));  // lower end at -9.7
}

TEST(Assembly, InterpolationIsContinuous) {
    const Pose a = at(Vec3(0, 0, 0)), b = at(Vec3(2, 4, 0), 1.0);
    EXPECT_TRUE(interpolate(a, b, 0).translation.isApprox(a.translation));
    EXPECT_TRUE(interpolate(a, b, 1).rotation.isApprox(b.rotation));
    const Pose half = interpolate(a, b, 0.5);
    EXPECT_TRUE(half.translation.isApprox(Vec3(1, 2, 0)));
    EXPECT_NEAR(half.rotation.angularDistance(a.rotation), 0.5, 1e-12);
}

TEST(Assembly, BallThroughTheMouthIsAssembledByZoneSnapFitting) {
    auto run = [](double areaHalfHeight) {
        World world;
        PartSettings rigid;
        rigid.mode = PartMode::Rigid;
        const BodyId mouth = world.add(buildPartModel(makeContainerMouth()), rigid, BodySettings{}, Pose{});
        BodySettings ball;
        ball.motion = MotionType::Dynamic;
        const BodyId b = world.add(buildPartModel(makeIcoSphere(7.0, 2)), rigid, ball, at(Vec3(0, 9, 0)));
        AssemblyRule r = rule(SnapTechnique::ZoneSnap);
        r.primary = b;
        r.secondary = mouth;
        r.primaryVector = {Vec3(0, -7, 0), Vec3(0, 7, 0)};  // the ball's vertical diameter
        r.area.frame = at(Vec3(0, -12, 0));                  // inside the container, below the mouth
        r.area.radius = 7.5;
        r.area.halfHeight = areaHalfHeight;
        r.finalRelativePose = at(Vec3(0, -12, 0));
        r.snapDuration = 0.1;
        world.addAssembly(r);
        for (int i = 0; i < 2500; ++i) world.step();
        return std::make_tuple(world.assemblyEvents(), world.centreOfMass(b), world.assembled(0));
    };
    const auto [events, centre, done] = run(8.0);
    ASSERT_EQ(events.size(), 1u);
    EXPECT_EQ(events[0].technique, SnapTechnique::ZoneSnap);
    EXPECT_TRUE(done);
    EXPECT_LT((centre - Vec3(0, -12, 0)).norm(), 1e-9);  // exactly at its final place, held there
    EXPECT_LT(events[0].primaryPoseBefore.translation.y(), 0.0);
    // An area too short for the 14-long vector never takes it: the ball falls on.
    const auto [none, fallen, never] = run(6.0);
    EXPECT_TRUE(none.empty());
    EXPECT_FALSE(never);
    EXPECT_LT(fallen.y(), -20.0);
}

TEST(Assembly, SnappingTakesThePartFromTheOperator) {
    World world(WorldSettings{1e-3, Vec3::Zero(), {}, 0.25, 4096, 4});
    PartSettings rigid;
    rigid.mode = PartMode::Rigid;
    const BodyId base = world.add(buildPartModel(makeIcoSphere(1.0, 1)), rigid, BodySettings{}, Pose{});
    BodySettings dynamic;
    dynamic.motion = MotionType::Dynamic;
    const BodyId peg = world.add(buildPartModel(makeIcoSphere(1.0, 1)), rigid, dynamic, at(Vec3(10, 0, 0)));
    AssemblyRule r = rule(SnapTechnique::ProximitySnap);
    r.primary = peg;
    r.secondary = base;
    r.finalRelativePose = at(Vec3(5, 0, 0));
    world.addAssembly(r);
    world.grab(peg);
    for (int i = 0; i < 1000 && world.assemblyEvents().empty(); ++i) {
        world.setGrabTarget(at(Vec3(10 - 5e-3 * (i + 1), 0, 0)));  // the operator brings it in at 5 m/s
        world.step();
    }
    ASSERT_EQ(world.assemblyEvents().size(), 1u);
    EXPECT_FALSE(world.grabbed());
    EXPECT_NEAR(world.assemblyEvents()[0].primaryPoseBefore.translation.x(), 5.5, 0.05);  // within 0.5 of the goal
}

TEST(Assembly, RulesAreCountedAndARefusedRuleIsNotAdded) {
    World world(WorldSettings{1e-3, Vec3::Zero(), {}, 0.25, 4096, 4});
    PartSettings rigid;
    rigid.mode = PartMode::Rigid;
    const BodyId a = world.add(buildPartModel(makeIcoSphere(1.0, 1)), rigid, BodySettings{}, Pose{});
    const BodyId b = world.add(buildPartModel(makeIcoSphere(1.0, 1)), rigid, BodySettings{}, at(Vec3(5, 0, 0)));
    EXPECT_EQ(world.assemblyCount(), 0u);
    AssemblyRule r = rule(SnapTechnique::ProximitySnap);
    r.primary = a;
    r.secondary = b;
    EXPECT_EQ(world.addAssembly(r), 0u);
    r.secondary = 7;  // no such body
    EXPECT_THROW(world.addAssembly(r), InputError);
    r.secondary = b;
    r.snapDuration = -1.0;
    EXPECT_THROW(world.addAssembly(r), InputError);
    r.snapDuration = 0.0;
    r.primaryVector.end = r.primaryVector.origin;  // zero length: no direction
    EXPECT_THROW(world.addAssembly(r), InputError);
    r.primaryVector = AssemblyVector{};
    r.secondaryVector.origin = Vec3(0.0, std::nan(""), 0.0);
    EXPECT_THROW(world.addAssembly(r), InputError);
    r.secondaryVector = AssemblyVector{};
    // A final pose or area frame that is not a pose, a tolerance or area size that is not a
    // length: each refused (a NaN pose snapped the primary to NaN; a zero quaternion to none).
    const AssemblyRule good = r;
    for (const Eigen::Quaterniond& q : {Eigen::Quaterniond(0, 0, 0, 0), Eigen::Quaterniond(std::nan(""), 0, 0, 0),
                                        Eigen::Quaterniond(1e200, 0, 0, 0)}) {
        r = good;
        r.finalRelativePose.rotation = q;
        EXPECT_THROW(world.addAssembly(r), InputError);
        r = good;
        r.area.frame.rotation = q;
        EXPECT_THROW(world.addAssembly(r), InputError);
    }
    r = good;
    r.finalRelativePose.translation.x() = INFINITY;
    EXPECT_THROW(world.addAssembly(r), InputError);
    for (double* field : {&r.distanceTolerance, &r.angleTolerance, &r.vectorTolerance, &r.area.radius, &r.area.halfHeight,
                          &r.area.halfExtents.x()})
        for (const double bad : {-1.0, std::nan(""), double(INFINITY)}) {
            r = good;  // the pointers stay into r
            *field = bad;
            EXPECT_THROW(world.addAssembly(r), InputError) << bad;
        }
    EXPECT_EQ(world.assemblyCount(), 1u);
    EXPECT_THROW((void)world.assembled(1), InputError);
}

// The world fixes static rigid bodies in the broad phase (never paired with each other), but
// not an assembly's primary: a static primary touching a static secondary still snaps by
// collision, as before fixed bodies existed.
TEST(Assembly, AStaticPrimaryTouchingAStaticSecondaryStillSnapsByCollision) {
    World world(WorldSettings{1e-3, Vec3::Zero(), {}, 0.25, 4096, 4});
    PartSettings rigid;
    rigid.mode = PartMode::Rigid;
    BodySettings fixedBody;
    fixedBody.motion = MotionType::Static;
    const auto ball = buildPartModel(makeIcoSphere(1.0, 2));
    const BodyId secondary = world.add(ball, rigid, fixedBody, Pose{});
    const BodyId primary = world.add(ball, rigid, fixedBody, at(Vec3(1.9, 0, 0)));  // overlapping by 0.1
    const BodyId bystander = world.add(ball, rigid, fixedBody, at(Vec3(-1.9, 0, 0)));
    EXPECT_TRUE(world.collision().fixed(primary));
    AssemblyRule r = rule(SnapTechnique::CollisionSnap);
    r.primary = primary;
    r.secondary = secondary;
    world.addAssembly(r);
    EXPECT_FALSE(world.collision().fixed(primary));
    EXPECT_TRUE(world.collision().fixed(bystander));
    world.step();
    ASSERT_EQ(world.assemblyEvents().size(), 1u);
    EXPECT_EQ(world.assemblyEvents()[0].rule, r.name);
    // The two fixed bodies that touch (secondary and bystander) make no contact.
    for (const Contact& c : world.contacts()) EXPECT_FALSE((c.partA == secondary && c.partB == bystander) || (c.partA == bystander && c.partB == secondary));
}
