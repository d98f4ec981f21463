// Bodies (src/world/bodies.cpp): mass properties from the mesh against the analytic sphere,
// the thickness and radius the no-tunnelling bound uses, bad settings refused, and the world's
// mass numbering.
#include "flexfit/flexfit.hpp"
#include "world/bodies.hpp"

#include <gtest/gtest.h>

using namespace flexfit;

TEST(Bodies, MassAndInertiaComeFromTheMesh) {
    BodySettings b;
    b.motion = MotionType::Dynamic;
    b.density = 2.0;
    const RigidBody body = makeRigidBody(*buildPartModel(makeIcoSphere(3.0, 4)), b);
    const double volume = 4.0 / 3.0 * M_PI * 27.0;
    EXPECT_NEAR(body.mass / (2.0 * volume), 1.0, 5e-3);
    EXPECT_NEAR(1.0 / body.inverseInertia(0, 0) / (0.4 * 2.0 * volume * 9.0), 1.0, 1e-2);
    EXPECT_NEAR(body.inverseMass * body.mass, 1.0, 1e-15);
}

TEST(Bodies, ThicknessAndBoundingRadius) {
    // A 2 x 4 x 6 box: thickness half its smallest side unless given; radius from its centre
    // to a corner.
    TriMesh box = makeIcoSphere(1.0, 0);
    for (Vec3& v : box.vertices) v = v.cwiseProduct(Vec3(1, 2, 3));
    const auto model = buildPartModel(box);
    const RigidBody fixed = makeRigidBody(*model, BodySettings{});
    const Eigen::AlignedBox3d bounds = boundingBox(model->mesh);
    EXPECT_NEAR(fixed.thickness, 0.5 * bounds.sizes().minCoeff(), 1e-12);
    double farthest = 0.0;
    for (const Vec3& p : model->restPositions) farthest = std::max(farthest, (p - bounds.center()).norm());
    EXPECT_NEAR(fixed.boundingRadius, farthest, 1e-12);
    EXPECT_EQ(fixed.mass, 0.0);  // static: no mass properties needed
    BodySettings thin;
    thin.thickness = 0.05;
    EXPECT_EQ(makeRigidBody(*model, thin).thickness, 0.05);
}

TEST(Bodies, BadSettingsAreRefused) {
    const auto model = buildPartModel(makeIcoSphere(1.0, 1));
    BodySettings b;
    b.density = 0.0;
    EXPECT_THROW(makeRigidBody(*model, b), InputError);
    b.density = 1.0;
    b.linearVelocity = Vec3(NAN, 0, 0);
    EXPECT_THROW(makeRigidBody(*model, b), InputError);
    b.linearVelocity = Vec3::Zero();
    b.thickness = -1.0;
    EXPECT_THROW(makeRigidBody(*model, b), InputError);
    BodySettings open;
    open.motion = MotionType::Dynamic;  // a dynamic body needs a closed mesh for its volume
    TriMesh sheet;
    sheet.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    sheet.faces = {{0, 1, 2}};
    EXPECT_THROW(makeRigidBody(*buildPartModel(sheet), open), InputError);
    // A box with a face missing still encloses a positive "volume" by the divergence theorem:
    // refused as open, not given a mass from it.
    TriMesh box = makeBox(Vec3::Ones(), 1);
    box.faces.pop_back();
    try {
        (void)makeRigidBody(*buildPartModel(box), open);
        ADD_FAILURE() << "an open box made a dynamic body";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("closed"), std::string::npos) << e.what();
    }
    // A density whose mass overflows, or underflows to 0: refused, not a NaN in the first step.
    BodySettings dynamic;
    dynamic.motion = MotionType::Dynamic;
    for (const double density : {1e300, 1e-320}) {
        dynamic.density = density;
        EXPECT_THROW(makeRigidBody(*model, dynamic), InputError) << density;
    }
    dynamic.density = 1e-60;  // tiny, but a finite mass and an invertible inertia: accepted
    EXPECT_GT(makeRigidBody(*model, dynamic).mass, 0.0);
}

TEST(Bodies, WorldMassNumberingFollowsTheBodies) {
    detail::Bodies bodies;
    const auto small = buildPartModel(makeIcoSphere(1.0, 0)), large = buildPartModel(makeTorus1());
    bodies.add(std::make_unique<Part>(small), makeRigidBody(*small, BodySettings{}));
    bodies.add(std::make_unique<Part>(large), makeRigidBody(*large, BodySettings{}));
    EXPECT_EQ(bodies.massCount(), small->massCount() + large->massCount());
    EXPECT_EQ(bodies.worldMass(0, 5), 5u);
    EXPECT_EQ(bodies.worldMass(1, 0), small->massCount());
    EXPECT_EQ(bodies.worldMass(1, 575), small->massCount() + 575);
    EXPECT_EQ(bodies.minimumThickness(), std::min(bodies.rigid[0].thickness, bodies.rigid[1].thickness));
}
