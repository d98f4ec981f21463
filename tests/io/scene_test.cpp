// Scene data (src/io/scene.cpp): parts found by name.
#include "flexfit/scene.hpp"

#include <gtest/gtest.h>

using namespace flexfit;

TEST(Scene, FindsPartsByNameAndNothingElse) {
    Scene scene;
    scene.parts.resize(3);
    scene.parts[0].name = "torus";
    scene.parts[1].name = "ball";
    scene.parts[2].name = "ball 2";
    EXPECT_EQ(scene.find("ball"), BodyId(1));
    EXPECT_EQ(scene.find("ball 2"), BodyId(2));
    EXPECT_EQ(scene.find("torus"), BodyId(0));
    EXPECT_EQ(scene.find("Ball"), std::nullopt);
    EXPECT_EQ(scene.find(""), std::nullopt);
}
