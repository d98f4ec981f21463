// buildSpringBlocks against brute force: every spring in exactly one place, each lane the spring
// it claims to be, blocks only where the vertex order gives them.
#include "flexfit/flexfit.hpp"
#include "model/spring_blocks.hpp"
#include "shuffled_mesh.hpp"
#include "unit_cube.hpp"

#include <gtest/gtest.h>

#include <cstdint>
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
        ASSERT_LE(blocks.first[q] + SpringBlocks::kWidth + blocks.offset[q], model.massCount()) << "block " << q;
        std::size_t springs = 0;
        for (std::size_t i = 0; i < SpringBlocks::kWidth; ++i) {
            const Index a = blocks.first[q] + Index(i), b = a + blocks.offset[q];
            const std::size_t lane = SpringBlocks::kWidth * q + i;
            const auto found = ends.find({a, b});
            if (found == ends.end()) {  // an empty lane: zero constants, no spring
                EXPECT_EQ(blocks.laneSpring[lane], SpringBlocks::kNoLane) << "block " << q << " lane " << i;
                EXPECT_EQ(blocks.restLength[lane], 0.0);
                EXPECT_EQ(blocks.stiffness[lane], 0.0);
                EXPECT_EQ(blocks.damping[lane], 0.0);
                continue;
            }
            const std::size_t e = found->second;
            ++springs;
            ++seen[e];
            EXPECT_EQ(blocks.laneSpring[lane], e);
            EXPECT_EQ(blocks.laneOfSpring[e], lane);
            EXPECT_EQ(blocks.restLength[lane], model.restLength[e]);
            EXPECT_EQ(blocks.stiffness[lane], model.stiffness[e]);
            EXPECT_EQ(blocks.damping[lane], model.damping[e]);
        }
        EXPECT_GE(springs, SpringBlocks::kMinimumLanes) << "block " << q;
    }
    EXPECT_TRUE(std::is_sorted(blocks.remainder.begin(), blocks.remainder.end()));
    for (Index e : blocks.remainder) {
        ++seen[e];
        EXPECT_EQ(blocks.laneOfSpring[e], SpringBlocks::kNoLane);
    }
    for (std::size_t e = 0; e < seen.size(); ++e) EXPECT_EQ(seen[e], 1) << "spring " << e;
    EXPECT_EQ(blocks.blockedSprings(), model.springCount() - blocks.remainder.size());
}

}  // namespace

TEST(SpringBlocks, RowMeshesPutMostSpringsInBlocksAndEverySpringOnce) {
    for (const TriMesh& mesh : {makeTorus1(), makeTorus2(), makeHeart()}) {
        SCOPED_TRACE(mesh.name);
        const auto model = buildPartModel(mesh);
        ASSERT_FALSE(model->springBlocks->empty());
        const double share = double(model->springBlocks->blockedSprings()) / double(model->springCount());
        EXPECT_GE(share, 0.95);  // torus1 97.7 %, torus2 98.4 %, heart 98.8 % (88 / 94 / 97 % with whole blocks only)
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

TEST(SpringBlocks, BlocksTakeFiveToEightSpringsOfAnOffsetWithFirstMassesInEightConsecutive) {
    // Hand-made springs (a, a + offset) among 40 masses, with the blocks worked out by hand.
    std::vector<Index> a, b;
    const auto add = [&](Index offset, std::initializer_list<Index> firsts) {
        for (Index f : firsts) a.push_back(f), b.push_back(f + offset);
    };
    add(2, {0, 1, 2, 4, 6});            // 5 first masses in 0..7: a block with lanes 3, 5, 7 empty
    add(2, {10, 11, 12, 13});           // 4 in 10..17: listed
    add(1, {20, 21, 22, 23, 24, 25, 26, 27, 28, 29});  // a whole block at 20; 28 and 29 listed
    add(5, {28, 29, 30, 31, 32});       // 5 in 28..35, but lane 7 would end at mass 40: listed
    add(3, {36});                       // alone: listed
    const std::vector<double> constants(a.size(), 1.0);
    const SpringBlocks blocks = buildSpringBlocks(a, b, constants, constants, constants, 40);

    ASSERT_EQ(blocks.blockCount(), 2u);
    EXPECT_EQ(blocks.offset, (std::vector<Index>{1, 2}));  // by offset, then first mass
    EXPECT_EQ(blocks.first, (std::vector<Index>{20, 0}));
    const Index no = SpringBlocks::kNoLane;
    EXPECT_EQ(blocks.laneSpring, (std::vector<Index>{9, 10, 11, 12, 13, 14, 15, 16, 0, 1, 2, no, 3, no, 4, no}));
    EXPECT_EQ(blocks.stiffness[11], 0.0);
    EXPECT_EQ(blocks.stiffness[12], 1.0);
    EXPECT_EQ(blocks.remainder, (std::vector<Index>{5, 6, 7, 8, 17, 18, 19, 20, 21, 22, 23, 24}));
    EXPECT_EQ(blocks.blockedSprings(), 13u);
}

TEST(SpringBlocks, ARowBlockEndsAtTheLastMass) {
    // A row block (offset 1) also adds to mass a0 + 8: it forms only when that mass exists.
    std::vector<Index> a, b;
    for (Index f = 4; f <= 10; ++f) a.push_back(f), b.push_back(f + 1);  // 7 row springs up to mass 11
    const std::vector<double> constants(a.size(), 1.0);
    const SpringBlocks within = buildSpringBlocks(a, b, constants, constants, constants, 13);
    ASSERT_EQ(within.blockCount(), 1u);  // masses 4..12: the empty lane ends at 12
    EXPECT_EQ(within.first[0], 4u);
    EXPECT_TRUE(within.remainder.empty());
    const SpringBlocks past = buildSpringBlocks(a, b, constants, constants, constants, 12);
    EXPECT_TRUE(past.empty());  // lane 7 would end at mass 12, past the last
    EXPECT_EQ(past.remainder.size(), a.size());
}

// The blocks by brute force over a table of which springs exist: per offset, each first mass in
// turn opens a block when its spring is still unplaced and at least 5 springs of that offset
// start in it and the 7 masses after it, all of whose second ends are masses.
namespace {
struct BlockList {
    std::vector<Index> first, offset, laneSpring;
};
BlockList blocksByBruteForce(const PartModel& model) {
    const std::size_t masses = model.massCount();
    std::map<Index, std::vector<Index>> springAt;  // offset -> spring starting at each mass, or kNoLane
    for (std::size_t e = 0; e < model.springCount(); ++e) {
        auto& at = springAt[model.springB[e] - model.springA[e]];
        at.resize(masses, SpringBlocks::kNoLane);
        at[model.springA[e]] = Index(e);
    }
    BlockList list;
    for (auto& [offset, at] : springAt)
        for (std::size_t a = 0; a + 8 + offset <= masses; ++a) {
            if (at[a] == SpringBlocks::kNoLane) continue;
            const auto lanes = std::span(at).subspan(a, 8);
            if (std::count_if(lanes.begin(), lanes.end(), [](Index e) { return e != SpringBlocks::kNoLane; }) < 5) continue;
            list.first.push_back(Index(a));
            list.offset.push_back(offset);
            list.laneSpring.insert(list.laneSpring.end(), lanes.begin(), lanes.end());
            a += 7;
        }
    return list;
}
}  // namespace

TEST(SpringBlocks, BlocksAreThoseABruteForceFinds) {
    PartModelSettings locality;
    locality.vertexOrder = VertexOrder::Locality;
    std::size_t partial = 0;  // blocks with empty lanes, over every model
    const std::shared_ptr<const PartModel> models[] = {
        buildPartModel(makeTorus1()), buildPartModel(makeTorus2()), buildPartModel(makeIcoSphere(1.0, 3)),
        buildPartModel(flexfit::testing::shuffledVertices(makeHeart(), 5), locality)};
    for (const auto& model : models) {
        SCOPED_TRACE(model->mesh.name);
        const BlockList expected = blocksByBruteForce(*model);
        const SpringBlocks& b = *model->springBlocks;
        EXPECT_EQ(b.first, expected.first);
        EXPECT_EQ(b.offset, expected.offset);
        EXPECT_EQ(b.laneSpring, expected.laneSpring);
        expectEverySpringOnceWithItsConstants(*model);
        partial += std::size_t(std::count(b.laneSpring.begin(), b.laneSpring.end(), SpringBlocks::kNoLane));
    }
    EXPECT_GT(partial, 0u);  // the rule's empty lanes were exercised
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

// The block kernels load each block's 8 lanes of constants as one vector: each array starts on
// a cache line, so block q's lanes are one line (PartState's test says why it matters).
TEST(SpringBlocks, EachBlocksConstantsAreOneCacheLine) {
    for (const TriMesh& mesh : {makeTorus1(), makeTorus2(), makeHeart(), makeIcoSphere(1.0, 2)}) {
        const auto model = buildPartModel(mesh);
        const SpringBlocks& blocks = *model->springBlocks;
        ASSERT_GT(blocks.blockCount(), 0u) << mesh.name;
        for (const auto* lanes : {&blocks.restLength, &blocks.stiffness, &blocks.damping})
            EXPECT_EQ(reinterpret_cast<std::uintptr_t>(lanes->data()) % 64, 0u) << mesh.name;
    }
}
