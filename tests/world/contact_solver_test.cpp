// The contact solver stage (src/world/contact_solver.cpp) in worlds, against analytic
// mechanics: a box on an incline sticks below the friction angle and slides with
// a = g (sin theta - mu_k cos theta) above it; a box sliding to rest covers v0^2 / (2 mu_k g);
// colliding bodies conserve linear and angular momentum and never gain kinetic energy; a bounce
// keeps e^2 of its height; a stack stays at rest.
#include "flexfit/flexfit.hpp"
#include "test_bodies.hpp"
#include "world/contact_solver.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using namespace flexfit;
using namespace flexfit::testing;

namespace {

constexpr double kG = 9.81;

BodySettings withFriction(BodySettings b, double staticFriction, double kineticFriction, double restitution = 0.0) {
    b.staticFriction = staticFriction;
    b.kineticFriction = kineticFriction;
    b.restitution = restitution;
    return b;
}

Pose rotatedAbout(const Vec3& axis, double angle, const Vec3& position) {
    return Pose{Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized())), position};
}

std::shared_ptr<const PartModel> cube(double half) { return buildPartModel(makeBox(Vec3::Constant(half), 2)); }

// A static slab whose top face passes through the origin, tilted by theta about z, with
// friction; and a cube of half extent 0.5 resting on it. Down the slope is -(cos, sin, 0).
struct Incline {
    World world;
    BodyId slab = 0, box = 0;
    Vec3 down;
    Incline(double theta, double staticFriction, double kineticFriction) : world(WorldSettings{1e-3, Vec3(0, -kG, 0), {}, 0.25, 4096, 8}) {
        const Eigen::Quaterniond tilt(Eigen::AngleAxisd(theta, Vec3::UnitZ()));
        const Vec3 up = tilt * Vec3::UnitY();
        down = -(tilt * Vec3::UnitX());
        slab = world.add(buildPartModel(makeBox(Vec3(30, 1, 5), 1)), rigidPart(), withFriction({}, staticFriction, kineticFriction),
                         Pose{tilt, -1.0 * up});
        box = world.add(cube(0.5), rigidPart(), withFriction(dynamicBody(), staticFriction, kineticFriction),
                        Pose{tilt, (0.5 + 1e-6) * up});
    }
    double alongSlope() const { return world.centreOfMass(box).dot(down); }
    double speedDownSlope() const { return world.body(box).linearVelocity.dot(down); }
};

double kineticEnergy(const World& world, std::initializer_list<BodyId> ids) {
    double e = 0.0;
    for (BodyId id : ids) {
        const RigidBody& b = world.body(id);
        const Eigen::Matrix3d r = world.part(id).pose().rotation.toRotationMatrix();
        const Eigen::Matrix3d inertia = (r * b.inverseInertia * r.transpose()).inverse();
        e += 0.5 * b.mass * b.linearVelocity.squaredNorm() + 0.5 * b.angularVelocity.dot(inertia * b.angularVelocity);
    }
    return e;
}

// Linear momentum and angular momentum about the origin.
std::pair<Vec3, Vec3> momentum(const World& world, std::initializer_list<BodyId> ids) {
    Vec3 p = Vec3::Zero(), l = Vec3::Zero();
    for (BodyId id : ids) {
        const RigidBody& b = world.body(id);
        const Eigen::Matrix3d r = world.part(id).pose().rotation.toRotationMatrix();
        const Eigen::Matrix3d inertia = (r * b.inverseInertia * r.transpose()).inverse();
        p += b.mass * b.linearVelocity;
        l += world.centreOfMass(id).cross(b.mass * b.linearVelocity) + inertia * b.angularVelocity;
    }
    return {p, l};
}

}  // namespace

TEST(ContactSolver, CombiningRules) {
    EXPECT_DOUBLE_EQ(detail::combinedFriction(0.4, 0.9), 0.6);
    EXPECT_EQ(detail::combinedFriction(0.0, 0.9), 0.0);
    EXPECT_EQ(detail::combinedRestitution(0.2, 0.7), 0.7);
}

TEST(ContactSolver, WellInsideTheConeOnlyWhereHypotSaysInside) {
    // Cones a few ulps either side of hypot(x, y), at scales from 1e-160 to 1e300: wherever
    // the shortcut answers "well inside", hypot must not exceed the cone (else the friction
    // step would skip a clamp it makes without the shortcut).
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), exponent(-160.0, 300.0);  // squares overflow above ~1e154
    int inside = 0;
    for (int i = 0; i < 400000; ++i) {
        const double scale = std::pow(10.0, exponent(rng));
        const double x = unit(rng) * scale, y = (i % 7 == 0 ? 0.0 : unit(rng)) * scale;
        const double edge = std::hypot(x, y);
        double cone = edge;
        const int ulps = int(i % 13) - 6;  // -6..6 ulps from the edge
        for (int k = 0; k < std::abs(ulps); ++k) cone = std::nextafter(cone, ulps < 0 ? 0.0 : HUGE_VAL);
        if (i % 5 == 0) cone *= 1.0 + 1e-9 * (i % 3);  // and a little further in
        if (!detail::wellInsideCone(x, y, cone)) continue;
        ++inside;
        ASSERT_FALSE(std::hypot(x, y) > cone) << x << " " << y << " " << cone;
    }
    EXPECT_GT(inside, 1000);  // the shortcut is taken
    EXPECT_TRUE(detail::wellInsideCone(0.3, 0.4, 0.6));
    EXPECT_FALSE(detail::wellInsideCone(0.3, 0.4, 0.5));
    EXPECT_FALSE(detail::wellInsideCone(0.0, 0.0, 0.0));  // no cone: hypot decides
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    for (const double cone : {nan, -1.0, -inf})
        EXPECT_FALSE(detail::wellInsideCone(0.3, 0.4, cone)) << cone;  // hypot decides (and clamps as before)
    EXPECT_FALSE(detail::wellInsideCone(nan, 0.4, 1.0));
    EXPECT_FALSE(detail::wellInsideCone(inf, 0.4, 1.0));
    EXPECT_TRUE(detail::wellInsideCone(0.3, 0.4, inf));  // hypot 0.5 > inf is false too
    EXPECT_FALSE(detail::wellInsideCone(1e200, 1e200, 1e201));  // the squares overflow: hypot decides
    EXPECT_TRUE(detail::wellInsideCone(1e153, 1e153, 1e160));   // cone^2 overflows, the squares do not: hypot is finite
}

TEST(ContactSolver, BoxOnAnInclineSticksBelowTheFrictionAngle) {
    // tan 20 deg = 0.36 < mu_s = 0.5: static friction holds the box.
    Incline incline(20.0 * M_PI / 180.0, 0.5, 0.4);
    const double start = incline.alongSlope();
    for (int i = 0; i < 2000; ++i) incline.world.step();
    EXPECT_LT(std::abs(incline.alongSlope() - start), 1e-3);
    EXPECT_LT(incline.world.body(incline.box).linearVelocity.norm(), 1e-3);
}

TEST(ContactSolver, BoxOnAnInclineSlidesWithTheKineticAcceleration) {
    // tan 30 deg = 0.58 > mu_s = 0.3: it slides, with a = g (sin - mu_k cos).
    const double theta = 30.0 * M_PI / 180.0, muK = 0.2;
    Incline incline(theta, 0.3, muK);
    for (int i = 0; i < 200; ++i) incline.world.step();
    const double v1 = incline.speedDownSlope(), t1 = incline.world.time();
    for (int i = 0; i < 600; ++i) incline.world.step();
    const double a = (incline.speedDownSlope() - v1) / (incline.world.time() - t1);
    const double expected = kG * (std::sin(theta) - muK * std::cos(theta));
    EXPECT_NEAR(a / expected, 1.0, 0.02) << "a = " << a << ", expected " << expected;
    // Frictionless, the same box slides with g sin theta.
    Incline ice(theta, 0.0, 0.0);
    for (int i = 0; i < 200; ++i) ice.world.step();
    const double w1 = ice.speedDownSlope();
    for (int i = 0; i < 600; ++i) ice.world.step();
    EXPECT_NEAR((ice.speedDownSlope() - w1) / 0.6 / (kG * std::sin(theta)), 1.0, 0.02);
}

TEST(ContactSolver, SlidingToRestCoversTheAnalyticDistance) {
    // v0^2 / (2 mu_k g) on level ground.
    const double v0 = 2.0, mu = 0.3;
    Incline flat(0.0, mu, mu);
    World& world = flat.world;
    world.setVelocity(flat.box, Vec3(v0, 0, 0), Vec3::Zero());
    const double start = world.centreOfMass(flat.box).x();
    for (int i = 0; i < 1500; ++i) world.step();
    EXPECT_LT(world.body(flat.box).linearVelocity.norm(), 1e-6);
    const double distance = world.centreOfMass(flat.box).x() - start;
    EXPECT_NEAR(distance / (v0 * v0 / (2.0 * mu * kG)), 1.0, 0.02) << distance;
}

TEST(ContactSolver, CollisionsConserveMomentumAndNeverGainEnergy) {
    // Two cubes (isotropic inertia: no gyroscopic drift) meet off-centre in free space, with
    // friction, inelastic and elastic. They close by less than the contact slop per step, so no
    // move is cut short (a cut move loses its remainder, and with it momentum: README).
    for (double restitution : {0.0, 1.0}) {
        SCOPED_TRACE(restitution);
        WorldSettings settings;
        settings.gravity = Vec3::Zero();
        World world(settings);
        const BodyId a = world.add(cube(0.5), rigidPart(), withFriction(dynamicBody(Vec3(2, 0, 0)), 0.4, 0.3, restitution),
                                   at(Vec3(-1.2, 0.3, 0)));
        BodySettings heavy = withFriction(dynamicBody(Vec3(-0.5, 0.25, 0)), 0.4, 0.3, restitution);
        heavy.density = 2.5;
        const BodyId b = world.add(cube(0.5), rigidPart(), heavy, rotatedAbout(Vec3(0, 0, 1), 0.3, Vec3(0.2, -0.1, 0.1)));
        const auto [p0, l0] = momentum(world, {a, b});
        double energy = kineticEnergy(world, {a, b});
        const double e0 = energy;
        bool touched = false;
        for (int i = 0; i < 900; ++i) {
            world.step();
            touched = touched || !world.contacts().empty();
            const double e = kineticEnergy(world, {a, b});
            EXPECT_LE(e, energy * (1.0 + 1e-9)) << "step " << i;
            energy = e;
        }
        ASSERT_TRUE(touched);
        const auto [p1, l1] = momentum(world, {a, b});
        EXPECT_LT((p1 - p0).norm(), 1e-9 * p0.norm());
        EXPECT_LT((l1 - l0).norm(), 1e-9 * l0.norm());
        if (restitution == 0.0) {
            EXPECT_LT(energy, 0.9 * e0);  // the collision took energy
        }
    }
}

TEST(ContactSolver, BounceKeepsRestitutionSquaredOfTheHeight) {
    // A cube dropped flat from 1 unit: it rises to e^2 of its fall, both measured from the
    // height where it turned (the contact's depth, up to the slop, is not part of either).
    for (double e : {0.5, 0.8}) {
        SCOPED_TRACE(e);
        World world(WorldSettings{1e-3, Vec3(0, -kG, 0), {}, 0.25, 4096, 8});
        world.add(buildPartModel(makeBox(Vec3(5, 1, 5), 1)), rigidPart(), withFriction({}, 0, 0, e), at(Vec3(0, -1, 0)));
        const BodyId box = world.add(cube(0.5), rigidPart(), withFriction(dynamicBody(), 0, 0, e), at(Vec3(0, 1.5, 0)));
        const double start = world.centreOfMass(box).y();
        double lowest = start, apex = -1.0;
        bool rising = false;
        for (int i = 0; i < 3000; ++i) {
            world.step();
            const double y = world.centreOfMass(box).y(), vy = world.body(box).linearVelocity.y();
            if (!rising) lowest = std::min(lowest, y);
            if (vy > 0.0) rising = true;
            if (rising && vy <= 0.0) break;
            if (rising) apex = y;
        }
        ASSERT_TRUE(rising);
        EXPECT_NEAR((apex - lowest) / (start - lowest), e * e, 0.02 * e * e) << "apex " << apex << ", lowest " << lowest;
    }
}

namespace {

// A static floor (its top at y = 0) and dynamic cubes on it, all with friction 0.5: cube k of
// half extent cubes[k].first with its centre at height cubes[k].second. Returns the cubes.
std::vector<BodyId> cubesOnAFloor(World& world, std::initializer_list<std::pair<double, double>> cubes) {
    world.add(buildPartModel(makeBox(Vec3(5, 1, 5), 1)), rigidPart(), withFriction({}, 0.5, 0.5), at(Vec3(0, -1, 0)));
    std::vector<BodyId> ids;
    for (const auto& [half, height] : cubes)
        ids.push_back(world.add(cube(half), rigidPart(), withFriction(dynamicBody(), 0.5, 0.5), at(Vec3(0, height, 0))));
    return ids;
}

// Three cubes, each smaller than the one below (half extents 0.6, 0.45, 0.3), each 1e-6 above
// where it rests.
std::vector<BodyId> smallerOnLarger(World& world) {
    return cubesOnAFloor(world, {{0.6, 0.6 + 1e-6}, {0.45, 1.65 + 1e-6}, {0.3, 2.4 + 1e-6}});
}

// How far the bodies move and turn over `steps` steps.
PoseDrift driftOver(World& world, const std::vector<BodyId>& ids, int steps) {
    PoseDrift drift(world, ids);
    for (int i = 0; i < steps; ++i) {
        world.step();
        drift.record(world);
    }
    return drift;
}

}  // namespace

TEST(ContactSolver, AStackStaysAtRest) {
    // Three cubes, each smaller than the one below, on a floor for 5 s: no jitter, no creep.
    World world(WorldSettings{1e-3, Vec3(0, -kG, 0), {}, 0.25, 4096, 8});
    const std::vector<BodyId> boxes = smallerOnLarger(world);
    for (int i = 0; i < 200; ++i) world.step();  // settle into the contacts
#if defined(__SANITIZE_ADDRESS__)
    constexpr int kSteps = 1000;  // ~20x slower there: the Release build checks all 5 s
#else
    constexpr int kSteps = 5000;
#endif
    const PoseDrift drift = driftOver(world, boxes, kSteps);
    EXPECT_LT(drift.translation, 1e-3);
    EXPECT_LT(drift.rotation, 1e-3);
}

TEST(ContactSolver, AStackOfEqualCubesStandsFlush) {
    // Three equal cubes (half extent 0.45) stacked face on face: each face's rim lies on the
    // other's side faces, so every triangle crossing lies on a coincident edge. Read two-sided,
    // those crossings gave depth 0 sideways and the cubes sank into each other (stack.toml with
    // three such cubes: 0.073 each in 3 s); read as faces of solids (FaceSides) they push the
    // cubes apart. Each stands at its analytic height (the floor's top at 0, centres at 0.45,
    // 1.35, 2.25) within the contact slop, and holds still in the third second (warm starting).
    World world(WorldSettings{1e-3, Vec3(0, -kG, 0), {}, 0.25, 4096, 8});
    const std::vector<BodyId> cubes = cubesOnAFloor(world, {{0.45, 0.4501}, {0.45, 1.3502}, {0.45, 2.2503}});
    for (int i = 0; i < 2000; ++i) world.step();
    const PoseDrift drift = driftOver(world, cubes, 1000);
    const double slop = world.settings().contactSlop * 0.9;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(world.centreOfMass(cubes[std::size_t(k)]).y(), 0.45 + 0.9 * k, slop) << "cube " << k;
    EXPECT_LT(drift.translation, 1e-9);
    EXPECT_LT(drift.rotation, 1e-9);
}

TEST(ContactSolver, WarmStartedContactsHoldAStackStill) {
    // The stack of AStackStaysAtRest, for 1 s after it settled: its points start each sub-step
    // from the impulses they ended the last with (warm starting), so the load is carried from
    // the first iteration and nothing creeps. With each point started from zero (e42a3eb) the
    // boxes wandered by 3.4e-5 in this second (1.75e-4 over 5 s); now by less than 1e-9.
    World world(WorldSettings{1e-3, Vec3(0, -kG, 0), {}, 0.25, 4096, 8});
    const std::vector<BodyId> boxes = smallerOnLarger(world);
    for (int i = 0; i < 200; ++i) world.step();
    const PoseDrift drift = driftOver(world, boxes, 1000);
    EXPECT_LT(drift.translation, 1e-9);
    EXPECT_LT(drift.rotation, 1e-9);
}

TEST(ContactSolver, ADeformingDynamicBodyLandsOnARigidFloor) {
    // A rigid-deformable ball falls on a rigid floor: its rigid motion stops there like a rigid
    // body's (no fall through, no speed piling up while held), and the floor deforms it.
    World world(WorldSettings{1e-3, Vec3(0, -kG, 0), {}, 0.25, 4096, 8});
    world.add(buildPartModel(makeBox(Vec3(5, 1, 5), 1)), rigidPart(), withFriction({}, 0.5, 0.5), at(Vec3(0, -1, 0)));
    const BodyId ball = world.add(buildPartModel(makeIcoSphere(1.0, 3)), PartSettings{}, withFriction(dynamicBody(), 0.5, 0.5), at(Vec3(0, 1.5, 0)));
    double lowest = 10.0;
    for (int i = 0; i < 2000; ++i) {
        world.step();
        lowest = std::min(lowest, world.centreOfMass(ball).y());
    }
    EXPECT_GT(lowest, 0.9);
    EXPECT_LT(std::abs(world.body(ball).linearVelocity.y()), 0.05);  // 2 s of fall would be 19.6
    EXPECT_NEAR(world.centreOfMass(ball).y(), 1.0, 0.05);
    EXPECT_GT(world.part(ball).movingMasses().size(), 0u);
}

TEST(ContactSolver, ADeformingBallRestsOnADynamicBox) {
    // A rigid-deformable ball on a dynamic rigid box on a static floor: the ball's rigid motion
    // meets the box as a rigid body's would (impulses on both), so it neither sinks through nor
    // piles up speed, and the box stays on the floor.
    World world(WorldSettings{1e-3, Vec3(0, -kG, 0), {}, 0.25, 4096, 8});
    world.add(buildPartModel(makeBox(Vec3(5, 1, 5), 1)), rigidPart(), withFriction({}, 0.5, 0.5), at(Vec3(0, -1, 0)));
    const BodyId box = world.add(cube(1.0), rigidPart(), withFriction(dynamicBody(), 0.5, 0.5), at(Vec3(0, 1.0 + 1e-6, 0)));
    const BodyId ball = world.add(buildPartModel(makeIcoSphere(0.5, 3)), PartSettings{}, withFriction(dynamicBody(), 0.5, 0.5),
                                  at(Vec3(0, 3.0, 0)));
    for (int i = 0; i < 2000; ++i) world.step();
    EXPECT_NEAR(world.centreOfMass(ball).y(), 2.5, 0.05);
    EXPECT_NEAR(world.centreOfMass(box).y(), 1.0, 0.01);
    EXPECT_LT(std::abs(world.body(ball).linearVelocity.y()), 0.05);  // 2 s of fall would be 19.6
}

TEST(ContactSolver, BodiesMovingTogetherDoNotHoldEachOtherBack) {
    // Two touching cubes sliding together in free space: each moves its whole way every step
    // (conservative advancement checks every body at the end of every move).
    WorldSettings settings;
    settings.gravity = Vec3::Zero();
    World world(settings);
    const BodyId a = world.add(cube(0.5), rigidPart(), dynamicBody(Vec3(10, 0, 0)), at(Vec3(0, 0, 0)));
    const BodyId b = world.add(cube(0.5), rigidPart(), dynamicBody(Vec3(10, 0, 0)), at(Vec3(1.0 + 1e-9, 0, 0)));
    for (int i = 0; i < 100; ++i) world.step();
    EXPECT_EQ(world.profile().cutMoves, 0u);
    EXPECT_NEAR(world.centreOfMass(a).x(), 1.0, 1e-9);
    EXPECT_NEAR(world.centreOfMass(b).x(), 2.0 + 1e-9, 1e-9);
}
