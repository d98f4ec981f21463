// IndexSet (include/flexfit/index_set.hpp) against a plain vector kept the same way by hand
// (push_back, swap-remove, real clear), over random operations.
#include "flexfit/index_set.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <vector>

using namespace flexfit;

TEST(IndexSet, InsertEraseContainsAndClear) {
    IndexSet set(6);
    EXPECT_TRUE(set.empty());
    EXPECT_TRUE(set.insert(4));
    EXPECT_TRUE(set.insert(1));
    EXPECT_FALSE(set.insert(4));
    EXPECT_TRUE(set.contains(4));
    EXPECT_FALSE(set.contains(0));
    EXPECT_EQ(std::vector<Index>(set.begin(), set.end()), (std::vector<Index>{4, 1}));
    EXPECT_EQ(set.slotOf(1), 1u);
    EXPECT_TRUE(set.erase(4));  // the last member takes its slot
    EXPECT_FALSE(set.erase(4));
    EXPECT_EQ(std::vector<Index>(set.begin(), set.end()), (std::vector<Index>{1}));
    EXPECT_EQ(set.slotOf(1), 0u);
    set.clear();
    EXPECT_TRUE(set.empty());
    EXPECT_FALSE(set.contains(1));
    EXPECT_TRUE(set.insert(1));  // after a clear, stale slots never make a false member
    EXPECT_EQ(set.size(), 1u);
}

TEST(IndexSet, MatchesAHandKeptListOverRandomOperations) {
    std::mt19937 rng(11);
    IndexSet set;
    std::vector<Index> reference;  // the members in the order the set must keep them
    std::size_t capacity = 12;
    set.reset(capacity);
    for (int op = 0; op < 50000; ++op) {
        const Index i = Index(rng() % capacity);
        const auto at = std::find(reference.begin(), reference.end(), i);
        switch (rng() % 12) {
            case 0:
                set.clear();
                reference.clear();
                break;
            case 1:
                capacity += rng() % 4;
                set.growTo(capacity);
                break;
            case 2:
                set.sort();
                std::sort(reference.begin(), reference.end());
                break;
            case 3: case 4: case 5: case 6:
                ASSERT_EQ(set.insert(i), at == reference.end());
                if (at == reference.end()) reference.push_back(i);
                break;
            default:
                ASSERT_EQ(set.erase(i), at != reference.end());
                if (at != reference.end()) {
                    *at = reference.back();
                    reference.pop_back();
                }
        }
        ASSERT_EQ(std::vector<Index>(set.begin(), set.end()), reference) << "operation " << op;
        for (Index k = 0; k < capacity; ++k) {
            const bool member = std::find(reference.begin(), reference.end(), k) != reference.end();
            ASSERT_EQ(set.contains(k), member) << "index " << k << ", operation " << op;
            if (!member) continue;
            ASSERT_EQ(set[set.slotOf(k)], k);
        }
    }
}

TEST(IndexSet, GrowingKeepsMembersAndAddsNone) {
    IndexSet set(2);
    set.insert(1);
    set.growTo(10);
    EXPECT_TRUE(set.contains(1));
    for (Index i = 2; i < 10; ++i) EXPECT_FALSE(set.contains(i));
    set.growTo(4);  // never shrinks
    EXPECT_EQ(set.capacity(), 10u);
    set.reset(3);
    EXPECT_TRUE(set.empty());
    EXPECT_EQ(set.capacity(), 3u);
    EXPECT_FALSE(set.contains(1));
}
