// InputError's message format: "source:line: problem", or "source: problem" without a line; and
// DivergenceError's.
#include "flexfit/core.hpp"

#include <gtest/gtest.h>

TEST(InputError, FormatsSourceLineAndProblem) {
    const flexfit::InputError withLine("part.tri", 12, "index out of range");
    EXPECT_STREQ(withLine.what(), "part.tri:12: index out of range");
    EXPECT_EQ(withLine.source(), "part.tri");
    EXPECT_EQ(withLine.line(), 12u);
    EXPECT_EQ(withLine.problem(), "index out of range");
    const flexfit::InputError noLine("settings", 0, "time step must be > 0");
    EXPECT_STREQ(noLine.what(), "settings: time step must be > 0");
}

// DivergenceError's message format: "body ID ['NAME'] diverged at t = T s: problem", or "part
// diverged ..." without a body.
TEST(DivergenceError, FormatsBodyTimeAndProblem) {
    const flexfit::DivergenceError body(3, 0.012000000000000002, "velocity of mass 7 is not finite (nan, 0, 0)");
    EXPECT_STREQ(body.what(), "body 3 diverged at t = 0.012 s: velocity of mass 7 is not finite (nan, 0, 0)");
    EXPECT_EQ(body.body(), flexfit::BodyId(3));
    EXPECT_EQ(body.time(), 0.012000000000000002);
    EXPECT_EQ(body.problem(), "velocity of mass 7 is not finite (nan, 0, 0)");
    EXPECT_TRUE(body.name().empty());
    const flexfit::DivergenceError named(0, 1.5, "x", "rim");
    EXPECT_STREQ(named.what(), "body 0 'rim' diverged at t = 1.5 s: x");
    EXPECT_EQ(named.name(), "rim");
    const flexfit::DivergenceError part(std::nullopt, 0.0, "y");
    EXPECT_STREQ(part.what(), "part diverged at t = 0 s: y");
    EXPECT_FALSE(part.body());
}
