// EpochMarks against a plain vector<bool> that is cleared for real, over random operations.
#include "core/epoch_marks.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace flexfit {
namespace {

TEST(EpochMarks, StartsEmptyAndInsertsOnce) {
    EpochMarks marks(5);
    for (std::size_t i = 0; i < 5; ++i) EXPECT_FALSE(marks.contains(i));
    EXPECT_TRUE(marks.insert(3));
    EXPECT_FALSE(marks.insert(3));
    EXPECT_TRUE(marks.contains(3));
    marks.clear();
    EXPECT_FALSE(marks.contains(3));
    EXPECT_TRUE(marks.insert(3));
}

TEST(EpochMarks, MatchesAClearedBitsetOverRandomOperations) {
    std::mt19937 rng(7);
    EpochMarks marks;
    std::vector<bool> reference;
    marks.reset(16);
    reference.assign(16, false);
    for (int op = 0; op < 20000; ++op) {
        const int kind = int(rng() % 10);
        if (kind == 0) {
            marks.clear();
            reference.assign(reference.size(), false);
        } else if (kind == 1) {
            const std::size_t size = reference.size() + rng() % 8;
            marks.growTo(size);
            reference.resize(size, false);
        } else if (kind == 2 && rng() % 50 == 0) {
            const std::size_t size = 1 + rng() % 64;
            marks.reset(size);
            reference.assign(size, false);
        } else {
            const std::size_t i = rng() % reference.size();
            ASSERT_EQ(marks.insert(i), !reference[i]) << "operation " << op;
            reference[i] = true;
        }
        ASSERT_EQ(marks.size(), reference.size());
        for (std::size_t i = 0; i < reference.size(); ++i) ASSERT_EQ(marks.contains(i), bool(reference[i])) << i;
    }
}

TEST(EpochMarks, GrowingKeepsMembersAndAddsNone) {
    EpochMarks marks(2);
    marks.insert(1);
    marks.growTo(10);
    EXPECT_TRUE(marks.contains(1));
    for (std::size_t i = 2; i < 10; ++i) EXPECT_FALSE(marks.contains(i));
    marks.growTo(4);  // never shrinks
    EXPECT_EQ(marks.size(), 10u);
}

}  // namespace
}  // namespace flexfit
