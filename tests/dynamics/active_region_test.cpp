// ActiveRegion (src/dynamics/active_region.cpp) against brute force: after random covers and
// uncovers, the moving masses are the covered ones and the computed springs are exactly the
// springs with a moving end, each listed once; the counts are the covers.
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <random>
#include <set>

using namespace flexfit;

TEST(ActiveRegion, IsTheCoveredMassesAndEverySpringTouchingThem) {
    const auto model = buildPartModel(makeTorus1());
    ActiveRegion region(*model);
    std::vector<int> covers(model->massCount(), 0);
    std::mt19937 rng(5);
    for (int op = 0; op < 20000; ++op) {
        const Index m = Index(rng() % 40) * 7 % Index(model->massCount());  // a few masses, often neighbours' neighbours
        const bool add = covers[m] == 0 || rng() % 2 == 0;
        if (add) {
            EXPECT_EQ(region.cover(m), covers[m] == 0);
            ++covers[m];
        } else {
            EXPECT_EQ(region.uncover(m), covers[m] == 1);
            --covers[m];
        }
        if (op % 97 != 0) continue;
        std::set<Index> masses, springs;
        for (Index i = 0; i < model->massCount(); ++i) {
            ASSERT_EQ(region.coverCounts()[i], covers[i]);
            ASSERT_EQ(region.moves(i), covers[i] > 0);
            if (covers[i] > 0) masses.insert(i);
        }
        for (Index e = 0; e < model->springCount(); ++e)
            if (covers[model->springA[e]] > 0 || covers[model->springB[e]] > 0) springs.insert(e);
        ASSERT_EQ(std::set<Index>(region.masses().begin(), region.masses().end()), masses);
        ASSERT_EQ(std::set<Index>(region.springs().begin(), region.springs().end()), springs);
        ASSERT_EQ(region.masses().size(), masses.size());    // each once
        ASSERT_EQ(region.springs().size(), springs.size());
        ASSERT_EQ(region.empty(), masses.empty());
    }
}

TEST(ActiveRegion, CoveringEveryMassComputesEverySpring) {
    const auto model = buildPartModel(makeIcoSphere(1.0, 2));
    ActiveRegion region(*model);
    for (Index m = 0; m < model->massCount(); ++m) {
        EXPECT_FALSE(region.coversEveryMass());
        region.cover(m);
    }
    EXPECT_TRUE(region.coversEveryMass());
    EXPECT_EQ(region.springs().size(), model->springCount());
    for (Index m = 0; m < model->massCount(); ++m) region.uncover(m);
    EXPECT_TRUE(region.empty());
    EXPECT_TRUE(region.springs().empty());
}
