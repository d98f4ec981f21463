// The collision world: the broad phase against brute-force sphere pairs, refit against
// rebuild, and the contact response of a rigid torus pressed into a rigid-deformable torus
// and withdrawn, checked against the analytic torus.
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <random>
#include <set>

using namespace flexfit;

namespace {

// Signed distance to a torus of radii (R, r) around its own y axis (negative inside).
double torusDistance(const Vec3& p, double R, double r) {
    const double ring = std::hypot(p.x(), p.z()) - R;
    return std::hypot(ring, p.y()) - r;
}

PartSettings deformableSettings() {
    PartSettings s;
    s.simulation.timeStep = 1e-3;
    s.simulation.globalDamping = 0.5;
    s.simulation.restoration = {RestorationMethod::Constraint, 0.0, 0.0, 2e-3};
    s.zones.contactLevel = 3;
    s.zones.restSpeed = 1e-2;
    return s;
}

}  // namespace

TEST(CollisionWorld, BroadPhaseEqualsBruteForceAndRefitEqualsRebuild) {
    std::mt19937 rng(20);
    std::uniform_real_distribution<double> u(-12, 12);
    const auto model = buildPartModel(makeIcoSphere(2.0, 1));
    std::vector<std::unique_ptr<Part>> parts;
    CollisionWorld refit(CollisionSettings{ExactTest::TriangleTriangle, BroadPhaseUpdate::Refit}),
        rebuild(CollisionSettings{ExactTest::TriangleTriangle, BroadPhaseUpdate::Rebuild});
    for (int i = 0; i < 40; ++i) {
        parts.push_back(std::make_unique<Part>(model));
        parts.back()->translate(Vec3(u(rng), u(rng), u(rng)));
        refit.add(*parts.back());
        rebuild.add(*parts.back());
    }
    for (int round = 0; round < 5; ++round) {
        for (auto& p : parts) p->translate(Vec3(u(rng), u(rng), u(rng)) * 0.2);
        refit.update();
        rebuild.update();
        std::set<std::pair<std::uint32_t, std::uint32_t>> expected;
        for (std::uint32_t i = 0; i < parts.size(); ++i)
            for (std::uint32_t j = i + 1; j < parts.size(); ++j) {
                const Sphere a = refit.collider(i).worldSphere(*parts[i]), b = refit.collider(j).worldSphere(*parts[j]);
                if ((a.centre - b.centre).norm() <= a.radius + b.radius) expected.insert({i, j});
            }
        using PairSet = std::set<std::pair<std::uint32_t, std::uint32_t>>;
        const auto& got = refit.candidatePairs();
        EXPECT_EQ(PairSet(got.begin(), got.end()), expected);
        EXPECT_EQ(refit.candidatePairs(), rebuild.candidatePairs());
        EXPECT_FALSE(expected.empty());
    }
}

TEST(CollisionWorld, RigidTorusPressedIntoDeformableTorusAndWithdrawn) {
    const auto model = buildPartModel(makeTorus1(), {Material::rigid(), 1.0, {}, {}});
    PartSettings rigidSettings;
    rigidSettings.mode = PartMode::Rigid;
    Part rigid(model, rigidSettings), soft(model, deformableSettings());
    // The rigid torus stands upright (axis z, its ring in the xy plane) beside the soft one and
    // moves along -x into its outer rim.
    rigid.setPose(Pose{Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX())), Vec3(25.5, 0, 0)});
    CollisionWorld world;
    const auto idRigid = world.add(rigid, BoundingVolumeKind::Aabb);
    const auto idSoft = world.add(soft, BoundingVolumeKind::Aabb);
    double deepestAfterResponse = 0.0;
    std::size_t maxMoving = 0;
    const int pressSteps = 2000, holdSteps = 500, withdrawSteps = 2000;
    for (int step = 0; step < pressSteps + holdSteps + withdrawSteps + 30000; ++step) {
        if (step < pressSteps) rigid.translate(Vec3(-1e-3, 0, 0));  // 2 units in 2 s: 1.5 units of overlap
        else if (step >= pressSteps + holdSteps && step < pressSteps + holdSteps + withdrawSteps) rigid.translate(Vec3(2e-3, 0, 0));
        const auto& contacts = world.findContacts();
        for (const Contact& c : contacts) {
            EXPECT_EQ(c.partA, idRigid);  // the rigid part presses
            EXPECT_EQ(c.partB, idSoft);
        }
        world.respond(contacts);
        // After the response, no soft mass is inside the rigid torus beyond the tolerance.
        for (Index m : soft.movingMasses()) {
            const double d = torusDistance(rigid.pose().applyInverse(soft.worldPosition(m)), 10.0, 2.5);
            deepestAfterResponse = std::max(deepestAfterResponse, -d);
        }
        maxMoving = std::max(maxMoving, soft.movingMasses().size());
        soft.step();
        if (step > pressSteps + holdSteps + withdrawSteps && soft.zoneCount() == 0) break;
    }
    EXPECT_GT(maxMoving, 10u);       // the press deformed the soft torus locally...
    EXPECT_LT(maxMoving, 576u / 2);  // ...and only locally
    // Tolerance: the mesh's chord error against the analytic torus (flat faces cut inside the
    // round tube by up to r (1 - cos(pi/24)) = 0.021, more across the wider outer faces).
    EXPECT_LT(deepestAfterResponse, 0.15);
    EXPECT_EQ(soft.zoneCount(), 0u);
    EXPECT_EQ(countActiveSprings(*model, soft.state().positions, 0.01), 0u);
    EXPECT_EQ(soft.state().positions, model->restPositions);
}

TEST(CollisionWorld, BothDeformablePartsShareThePenetrationByStiffness) {
    const auto soft = buildPartModel(makeIcoSphere(2.0, 2), {Material{0.1, 0.01}, 1.0, {}, {}});
    const auto hard = buildPartModel(makeIcoSphere(2.0, 2), {Material{3.0, 0.3}, 1.0, {}, {}});
    PartSettings settings = deformableSettings();
    settings.simulation.restoration = {RestorationMethod::AnchorSprings, 1.0, 0.1, 0.0};
    Part a(soft, settings), b(hard, settings);
    b.translate(Vec3(3.7, 0, 0));
    CollisionWorld world;
    world.add(a);
    world.add(b);
    const auto& contacts = world.findContacts();
    ASSERT_FALSE(contacts.empty());
    world.respond(contacts);
    double moveA = 0.0, moveB = 0.0;
    for (Index m : a.movingMasses()) moveA = std::max(moveA, (a.state().positions[m] - soft->restPositions[m]).norm());
    for (Index m : b.movingMasses()) moveB = std::max(moveB, (b.state().positions[m] - hard->restPositions[m]).norm());
    const double ka = world.effectiveStiffness(0), kb = world.effectiveStiffness(1);
    EXPECT_NEAR(ka, 0.1 + 1.0, 1e-12);
    EXPECT_NEAR(kb, 3.0 + 1.0, 1e-12);
    ASSERT_GT(moveA, 0.0);
    ASSERT_GT(moveB, 0.0);
    EXPECT_GT(moveA, moveB);  // the softer part gives way more
    EXPECT_NEAR(moveA / moveB, kb / ka, 0.35 * kb / ka);
}
