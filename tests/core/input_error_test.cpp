// InputError's message format: "source:line: problem", or "source: problem" without a line.
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
