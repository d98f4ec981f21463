// ActiveRegion (src/dynamics/active_region.cpp) against brute force: after random covers and
// uncovers, the moving masses are the covered ones and the computed springs are exactly the
// springs with a moving end (bending springs too), each listed once; the counts are the covers.
#include "flexfit/flexfit.hpp"
#include "model/spring_blocks.hpp"

#include "shuffled_mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <set>

using namespace flexfit;

namespace {

void expectCoveredMassesAndTheirSprings(const std::shared_ptr<const PartModel>& model) {
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

}  // namespace

TEST(ActiveRegion, IsTheCoveredMassesAndEverySpringTouchingThem) { expectCoveredMassesAndTheirSprings(buildPartModel(makeTorus1())); }

// Bending springs join masses that share no edge: they are computed all the same.
TEST(ActiveRegion, BendingSpringsAreComputedWithTheirMasses) {
    PartModelSettings settings;
    settings.shell = ShellMaterial{2e9, 0.35, 1e-3, 1200.0, 0.1, true};
    const auto model = buildPartModel(makeTorus(0.1, 0.025, 24, 24), settings);
    ASSERT_GT(model->bendingSpringCount, 0u);
    expectCoveredMassesAndTheirSprings(model);
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

namespace {

// Covers (or uncovers, where covered) a run of up to maxLength consecutive masses from a random
// start, keeping `covers` as the brute-force count.
void coverRun(ActiveRegion& region, std::vector<int>& covers, std::mt19937& rng, Index maxLength, bool add) {
    const auto masses = Index(covers.size());
    const Index start = Index(rng() % masses), length = Index(1 + rng() % maxLength);
    for (Index m = start; m < std::min<Index>(start + length, masses); ++m) {
        if (add) {
            region.cover(m);
            ++covers[m];
        } else if (covers[m] > 0) {
            region.uncover(m);
            --covers[m];
        }
    }
}

// The loose springs' list (what the region step reads) holds, slot for slot, the ends and
// constants of the springs looseSprings() lists, read from the model.
void expectListedSlotForSlot(const PartModel& model, const ActiveRegion& region) {
    const SpringList& list = region.looseSpringList();
    ASSERT_EQ(list.size(), region.looseSprings().size());
    for (std::size_t s = 0; s < list.size(); ++s) {
        const Index e = region.looseSprings()[s];
        ASSERT_EQ(list.springA[s], model.springA[e]) << "slot " << s;
        ASSERT_EQ(list.springB[s], model.springB[e]) << "slot " << s;
        ASSERT_EQ(list.restLength[s], model.restLength[e]) << "slot " << s;
        ASSERT_EQ(list.stiffness[s], model.stiffness[e]) << "slot " << s;
        ASSERT_EQ(list.damping[s], model.damping[e]) << "slot " << s;
    }
}

}  // namespace

// The region step's layout on a model with spring blocks, against brute force over the blocks'
// lanes: the vector blocks are those with at least kMinimumBlockSprings of their 8 springs
// computed, the loose springs are the computed springs in none of them, each listed once.
// Covers sweep whole rows so blocks fill, and break up as masses leave.
TEST(ActiveRegion, VectorBlocksAndLooseSpringsPartitionTheComputedSprings) {
    const auto model = buildPartModel(makeTorus1());
    ASSERT_TRUE(model->hasSpringBlocks());
    const SpringBlocks& blocks = *model->springBlocks;
    ActiveRegion region(*model);
    std::vector<int> covers(model->massCount(), 0);
    std::mt19937 rng(9);
    std::size_t largestVector = 0, partialSeen = 0, fullSeen = 0;
    for (int op = 0; op < 6000; ++op) {
        coverRun(region, covers, rng, 40, rng() % 3 != 0);
        if (op % 50 != 0) continue;
        const std::set<Index> computed(region.springs().members().begin(), region.springs().members().end());
        std::set<Index> vector, loose = computed;
        for (Index q = 0; q < blocks.blockCount(); ++q) {
            std::size_t inRegion = 0;
            for (Index i = 0; i < SpringBlocks::kWidth; ++i) inRegion += computed.count(blocks.laneSpring[SpringBlocks::kWidth * q + i]);
            if (inRegion < ActiveRegion::kMinimumBlockSprings) continue;
            vector.insert(q);
            (inRegion == SpringBlocks::kWidth ? fullSeen : partialSeen) += 1;
            for (Index i = 0; i < SpringBlocks::kWidth; ++i) loose.erase(blocks.laneSpring[SpringBlocks::kWidth * q + i]);
        }
        const auto vectorMembers = region.vectorBlocks().members(), looseMembers = region.looseSprings().members();
        EXPECT_EQ(std::set<Index>(vectorMembers.begin(), vectorMembers.end()), vector) << "op " << op;
        EXPECT_EQ(vectorMembers.size(), vector.size());
        EXPECT_EQ(std::set<Index>(looseMembers.begin(), looseMembers.end()), loose) << "op " << op;
        EXPECT_EQ(looseMembers.size(), loose.size());
        expectListedSlotForSlot(*model, region);
        largestVector = std::max(largestVector, vector.size());
    }
    EXPECT_GT(largestVector, 20u);  // the test saw vector blocks come and go
    EXPECT_GT(partialSeen, 20u);    // with some springs computed
    EXPECT_GT(fullSeen, 20u);       // and with all 8
}

// The octets, against brute force: vector octets are those with at least kMinimumOctetMasses
// of their 8 masses moving; loose masses are the moving masses in none (the last V mod 8 masses
// are always loose). A mesh whose mass count is not a multiple of 8, covered and uncovered in
// runs so octets form and break up.
TEST(ActiveRegion, VectorOctetsAndLooseMassesPartitionTheMovingMasses) {
    const auto model = buildPartModel(makeIcoSphere(1.0, 2));  // 162 masses: 20 octets and 2 more
    ActiveRegion region(*model);
    std::vector<int> covers(model->massCount(), 0);
    std::mt19937 rng(21);
    std::size_t largestWhole = 0;
    for (int op = 0; op < 4000; ++op) {
        coverRun(region, covers, rng, 20, rng() % 2 == 0);
        std::set<Index> whole, loose;
        for (Index m = 0; m < model->massCount(); ++m)
            if (covers[m] > 0) loose.insert(m);
        for (Index o = 0; o < model->massCount() / 8; ++o) {
            std::size_t moving = 0;
            for (Index m = 8 * o; m < 8 * o + 8; ++m) moving += covers[m] > 0;
            if (moving < ActiveRegion::kMinimumOctetMasses) continue;
            whole.insert(o);
            for (Index m = 8 * o; m < 8 * o + 8; ++m) loose.erase(m);
        }
        const auto w = region.vectorOctets().members(), l = region.looseMasses().members();
        ASSERT_EQ(std::set<Index>(w.begin(), w.end()), whole) << "op " << op;
        ASSERT_EQ(w.size(), whole.size());
        ASSERT_EQ(std::set<Index>(l.begin(), l.end()), loose) << "op " << op;
        ASSERT_EQ(l.size(), loose.size());
        largestWhole = std::max(largestWhole, whole.size());
    }
    EXPECT_GT(largestWhole, 5u);
}

TEST(ActiveRegion, WithoutBlocksEveryComputedSpringIsLoose) {
    const auto model = buildPartModel(flexfit::testing::shuffledVertices(makeIcoSphere(1.0, 2), 3));
    ASSERT_FALSE(model->hasSpringBlocks());
    ActiveRegion region(*model);
    for (Index m = 0; m < 30; ++m) region.cover(m);
    EXPECT_TRUE(region.vectorBlocks().empty());
    EXPECT_EQ(std::vector<Index>(region.looseSprings().members().begin(), region.looseSprings().members().end()),
              std::vector<Index>(region.springs().members().begin(), region.springs().members().end()));
    expectListedSlotForSlot(*model, region);
    for (Index m = 0; m < 30; m += 3) region.uncover(m);  // swap-removes
    EXPECT_EQ(std::vector<Index>(region.looseSprings().members().begin(), region.looseSprings().members().end()),
              std::vector<Index>(region.springs().members().begin(), region.springs().members().end()));
    expectListedSlotForSlot(*model, region);
}

namespace {

// Every list of the region, in order: equal lists mean the region steps alike.
void expectSameLists(const ActiveRegion& x, const ActiveRegion& y, const char* when) {
    auto same = [&](const IndexSet& a, const IndexSet& b, const char* what) {
        EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << what << " " << when;
    };
    same(x.masses(), y.masses(), "masses");
    same(x.springs(), y.springs(), "springs");
    same(x.vectorBlocks(), y.vectorBlocks(), "vector blocks");
    same(x.looseSprings(), y.looseSprings(), "loose springs");
    same(x.vectorOctets(), y.vectorOctets(), "vector octets");
    same(x.looseMasses(), y.looseMasses(), "loose masses");
    EXPECT_TRUE(std::ranges::equal(x.coverCounts(), y.coverCounts())) << "cover counts " << when;
    EXPECT_TRUE(std::ranges::equal(x.looseSpringList().springA, y.looseSpringList().springA)) << "loose list " << when;
}

// Zones as runs of masses, some overlapping, in random order.
std::vector<std::vector<Index>> randomZones(const PartModel& model, std::mt19937& rng, int count) {
    std::vector<std::vector<Index>> zones(std::size_t(count), std::vector<Index>{});
    for (auto& zone : zones) {
        const Index start = Index(rng() % model.massCount()), length = Index(8 + rng() % 60);
        for (Index m = start; m < std::min<Index>(start + length, model.massCount()); ++m) zone.push_back(m);
    }
    return zones;
}

}  // namespace

// A batch of zones retiring: uncoverUnlessLast for each zone's masses, then uncover of the
// masses whose last zone went, in that order, makes exactly the lists that uncovering each
// zone's masses at once makes (the reference); when every zone goes, clear() leaves a region
// that then fills exactly as one emptied mass by mass does.
TEST(ActiveRegion, ADeferredBatchOfUncoversMakesTheSameListsAsUncoveringAtOnce) {
    for (const auto& model : {buildPartModel(makeTorus1()), buildPartModel(makeTorus2())}) {
        std::mt19937 rng(17);
        for (int trial = 0; trial < 20; ++trial) {
            const auto zones = randomZones(*model, rng, 12);
            ActiveRegion atOnce(*model), deferred(*model);
            for (const auto& zone : zones)
                for (Index m : zone) atOnce.cover(m), deferred.cover(m);
            // Retire all zones but every third (trial even) or every zone (odd), in random order.
            std::vector<std::size_t> order(zones.size());
            std::iota(order.begin(), order.end(), 0);
            std::shuffle(order.begin(), order.end(), rng);
            const bool all = trial % 2 == 1;
            std::vector<Index> retiring;
            for (std::size_t z : order) {
                if (!all && z % 3 == 0) continue;
                for (Index m : zones[z]) {
                    atOnce.uncover(m);
                    if (deferred.uncoverUnlessLast(m)) retiring.push_back(m);
                }
            }
            if (all) {
                EXPECT_EQ(retiring.size(), deferred.masses().size());
                deferred.clear();
                EXPECT_TRUE(deferred.empty());
                EXPECT_TRUE(deferred.springs().empty());
            } else {
                for (Index m : retiring) deferred.uncover(m);
            }
            expectSameLists(atOnce, deferred, "after the batch");
            // New zones after: the same lists again.
            for (const auto& zone : randomZones(*model, rng, 4))
                for (Index m : zone) atOnce.cover(m), deferred.cover(m);
            expectSameLists(atOnce, deferred, "after new zones");
        }
    }
}

TEST(ActiveRegion, CoveringAMassOutOfRangeOrUncoveringOneNotCoveredIsAnError) {
    const auto model = buildPartModel(makeIcoSphere(1.0, 1));
    ActiveRegion region(*model);
    EXPECT_THROW((void)region.cover(Index(model->massCount())), InputError);
    EXPECT_THROW((void)region.uncover(3), InputError);  // covered by no zone
    EXPECT_TRUE(region.cover(3));
    EXPECT_TRUE(region.uncover(3));
    EXPECT_TRUE(region.empty());
    // 65,535 zones on one mass fill its 16-bit count: one more is refused, not wrapped to 0.
    for (int k = 0; k < 65535; ++k) (void)region.cover(5);
    EXPECT_THROW((void)region.cover(5), InputError);
    EXPECT_TRUE(region.moves(5));
}
