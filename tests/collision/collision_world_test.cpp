// The collision world's registry (collision_world.cpp): one id per body, in the world's order,
// and the exact test switched with every hierarchy rebuilt for it.
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <stdexcept>

using namespace flexfit;

TEST(CollisionWorld, BodiesAreRegisteredUnderTheWorldsIdsInOrder) {
    const auto model = buildPartModel(makeIcoSphere(1.0, 1));
    Part a(model), b(model);
    CollisionWorld world;
    world.add(0, a);
    EXPECT_THROW(world.add(2, b), std::invalid_argument);  // ids cannot skip
    EXPECT_THROW(world.add(0, b), std::invalid_argument);  // nor repeat
    EXPECT_EQ(world.bodyCount(), 1u);
    world.add(1, b, BoundingVolumeKind::Sphere);
    EXPECT_EQ(world.bodyCount(), 2u);
    EXPECT_NE(world.collider(1).spheres(), nullptr);
    EXPECT_NE(world.collider(0).boxes(), nullptr);
}

TEST(CollisionWorld, SwitchingTheExactTestRebuildsEveryHierarchyAndKeepsTheContacts) {
    // Two overlapping spheres: the same contact pairs under either test's hierarchies, and the
    // colliders report the test they were built for.
    const auto model = buildPartModel(makeIcoSphere(1.0, 2));
    Part a(model), b(model);
    b.translate(Vec3(1.6, 0.1, 0.0));
    CollisionWorld world;
    world.add(0, a);
    world.add(1, b);
    const std::size_t triangles = world.findContacts().size();
    world.setExactTest(ExactTest::SphereTriangle);
    EXPECT_EQ(world.collider(0).exactTest(), ExactTest::SphereTriangle);
    EXPECT_EQ(world.collider(1).exactTest(), ExactTest::SphereTriangle);
    EXPECT_GT(triangles, 0u);
    EXPECT_GT(world.findContacts().size(), 0u);
}

TEST(CollisionWorld, ContactsOfABodyNotAddedIsAnError) {
    CollisionWorld world;
    Part ball(buildPartModel(makeIcoSphere(1.0, 1)));
    world.add(0, ball);
    EXPECT_TRUE(world.contactsOf(0).empty());
    EXPECT_THROW((void)world.contactsOf(7), std::invalid_argument);
}
