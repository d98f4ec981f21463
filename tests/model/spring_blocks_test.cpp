// buildSpringBlocks against brute force: every spring in exactly one place, each lane the spring
// it claims to be, blocks only where the vertex order gives them.
#include "flexfit/flexfit.hpp"
#include "model/spring_blocks.hpp"
#include "shuffled_mesh.hpp"
#include "unit_cube.hpp"

#include <gtest/gtest.h>

#include <numeric>

#include <algorithm>
#include <map>

using namespace flexfit;

namespace {

// Spring index by its end masses, found by scanning the model's springs.
std::map<std::pair<Index, Index>, std::size_t> springsByEnds(const PartModel& model) {
    std::map<std::pair<Index, Index>, std::size_t> ends;
    for (std::size_t e = 0; e < model.springCount(); ++e) ends[{model.springA[e], model.springB[e]}] = e;
    return ends;
}

void expectEverySpringOnceWithItsConstants(const PartModel& model) {
    const SpringBlocks& blocks = *model.springBlocks;
    const auto ends = springsByEnds(model);
    std::vector<int> seen(model.springCount(), 0);
    for (std::size_t q = 0; q < blocks.blockCount(); ++q) {
        ASSERT_GE(blocks.offset[q], 1u);
        for (std::size_t i = 0; i < SpringBlocks::kWidth; ++i) {
            const Index a = blocks.first[q] + Index(i), b = a + blocks.offset[q];
            const auto found = ends.find({a, b});
            ASSERT_NE(found, ends.end()) << "block " << q << " lane " << i << " is no spring";
            const std::size_t e = found->second, lane = SpringBlocks::kWidth * q + i;
            ++seen[e];
            EXPECT_EQ(blocks.restLength[lane], model.restLength[e]);
            EXPECT_EQ(blocks.stiffness[lane], model.stiffness[e]);
            EXPECT_EQ(blocks.damping[lane], model.damping[e]);
        }
    }
    EXPECT_TRUE(std::is_sorted(blocks.remainder.begin(), blocks.remainder.end()));
    for (Index e : blocks.remainder) ++seen[e];
    for (std::size_t e = 0; e < seen.size(); ++e) EXPECT_EQ(seen[e], 1) << "spring " << e;
}

}  // namespace

TEST(SpringBlocks, RowMeshesPutMostSpringsInBlocksAndEverySpringOnce) {
    for (const TriMesh& mesh : {makeTorus1(), makeTorus2(), makeHeart()}) {
        SCOPED_TRACE(mesh.name);
        const auto model = buildPartModel(mesh);
        ASSERT_FALSE(model->springBlocks->empty());
        const double share = double(model->springBlocks->blockCount() * SpringBlocks::kWidth) / double(model->springCount());
        EXPECT_GE(share, 0.85);  // torus1 88 %, torus2 94 %, heart 97 %
        expectEverySpringOnceWithItsConstants(*model);
    }
}

TEST(SpringBlocks, PerSpringConstantsFollowTheirSprings) {
    const TriMesh mesh = makeTorus1();
    PartModelSettings settings;
    const std::size_t springs = buildPartModel(mesh)->springCount();
    for (std::size_t e = 0; e < springs; ++e) settings.springMaterials.push_back({0.1 + 1e-3 * double(e), 0.01 + 1e-5 * double(e)});
    expectEverySpringOnceWithItsConstants(*buildPartModel(mesh, settings));
}

TEST(SpringBlocks, BlocksAreMaximalRunsCutIntoEights) {
    // Count, per offset, the runs of consecutive first masses by brute force: floor(run / 8) blocks each.
    const auto model = buildPartModel(makeTorus2());
    std::map<Index, std::vector<Index>> firstsByOffset;
    for (std::size_t e = 0; e < model->springCount(); ++e)
        firstsByOffset[model->springB[e] - model->springA[e]].push_back(model->springA[e]);
    std::size_t expected = 0;
    for (auto& [offset, firsts] : firstsByOffset) {
        std::sort(firsts.begin(), firsts.end());
        std::size_t run = 1;
        for (std::size_t i = 1; i <= firsts.size(); ++i) {
            if (i < firsts.size() && firsts[i] == firsts[i - 1] + 1) {
                ++run;
                continue;
            }
            expected += run / SpringBlocks::kWidth;
            run = 1;
        }
    }
    EXPECT_EQ(model->springBlocks->blockCount(), expected);
    const SpringBlocks& b = *model->springBlocks;
    for (std::size_t q = 1; q < b.blockCount(); ++q)
        EXPECT_TRUE(b.offset[q - 1] < b.offset[q] || (b.offset[q - 1] == b.offset[q] && b.first[q - 1] < b.first[q]));
}

// No useful vertex order: no blocks, every spring in the remainder (the listed-spring kernel).
TEST(SpringBlocks, ShuffledVerticesAndSmallMeshesListEverySpring) {
    for (const TriMesh& mesh : {flexfit::testing::shuffledVertices(makeTorus1(), 3),
                                flexfit::testing::shuffledVertices(makeHeart(), 4), flexfit::testing::unitCube()}) {
        const auto model = buildPartModel(mesh);
        EXPECT_TRUE(model->springBlocks->empty());
        std::vector<Index> every(model->springCount());
        std::iota(every.begin(), every.end(), Index{0});
        EXPECT_EQ(model->springBlocks->remainder, every);
        EXPECT_EQ(model->springBlocks->laneOfSpring, std::vector<Index>(model->springCount(), SpringBlocks::kNoLane));
    }
}

TEST(SpringBlocks, ContinuesRowOnlyForAdjacentOffsetOneBlocks) {
    SpringBlocks b;
    b.first = {0, 8, 20, 28, 36};
    b.offset = {1, 1, 1, 2, 2};
    EXPECT_FALSE(b.continuesRow(0));
    EXPECT_TRUE(b.continuesRow(1));
    EXPECT_FALSE(b.continuesRow(2));  // a gap
    EXPECT_FALSE(b.continuesRow(3));  // another offset
    EXPECT_FALSE(b.continuesRow(4));  // offset 2 continues no row
}
