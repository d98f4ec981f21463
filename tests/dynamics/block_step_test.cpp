// The spring-block full step (src/dynamics/block_step*.cpp): its kernels against each other bit
// for bit, and each against the thesis-style naive implementation and the same springs listed.
#include "dynamics/flush_denormals.hpp"
#include "dynamics/full_step.hpp"
#include "flexfit/flexfit.hpp"
#include "model/spring_blocks.hpp"
#include "golden.hpp"
#include "naive_from_mesh.hpp"
#include "shuffled_mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <numeric>
#include <random>
#include <utility>

using namespace flexfit;
using detail::BlockKernel;

namespace {

const std::vector<BlockKernel> kAllKernels = {BlockKernel::Scalar, BlockKernel::Avx2, BlockKernel::Avx512};

// Random velocities, and two springs squeezed to zero length: one in a block, one in the remainder.
PartState kickedState(const PartModel& model, unsigned seed) {
    PartState state = PartState::atRest(model);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> kick(-1.0, 1.0);
    for (Vec3& v : state.velocities) v = Vec3(kick(rng), kick(rng), kick(rng));
    const SpringBlocks& blocks = *model.springBlocks;
    if (!blocks.empty()) {
        const Index a = blocks.first[0] + 3;
        state.positions[a + blocks.offset[0]] = state.positions[a];
    }
    if (!blocks.remainder.empty()) {  // the first: in the vector kernels' first group of 4
        const Index e = blocks.remainder.front();
        state.positions[model.springB[e]] = state.positions[model.springA[e]];
    }
    return state;
}

PartState runBlocks(const PartModel& model, const SimulationSettings& settings, BlockKernel kernel, int steps) {
    const detail::FlushDenormals flush;
    const detail::MassUpdate update = detail::MassUpdate::from(settings);
    PartState state = kickedState(model, 5);
    for (int step = 0; step < steps; ++step) {
        state.forces[7] += Vec3(0.5, -0.25, 1.0);  // a pending external load every step
        detail::stepSpringBlocks(model, update, state, kernel);
    }
    return state;
}

// Bit for bit (memcmp: +0 and -0 differ, equal NaNs match).
bool sameBits(std::span<const Vec3> a, std::span<const Vec3> b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

bool sameBits(const PartState& a, const PartState& b) {
    return sameBits(a.positions, b.positions) && sameBits(a.velocities, b.velocities) && sameBits(a.forces, b.forces);
}

// The force order spring_blocks.hpp documents, written from its text.
void documentedBlockForces(const SpringBlocks& blocks, const std::vector<Vec3>& x, const std::vector<Vec3>& v,
                           std::vector<Vec3>& f) {
    constexpr Index W = SpringBlocks::kWidth;
    auto force = [&](std::size_t q, Index i) {
        const Index a = blocks.first[q] + i, b = a + blocks.offset[q];
        const std::size_t lane = W * q + i;
        if (!blocks.laneSpring.empty() && blocks.laneSpring[lane] == SpringBlocks::kNoLane) return Vec3(Vec3::Zero());  // an empty lane
        return detail::springForceOnFirst(blocks.stiffness[lane], blocks.damping[lane], blocks.restLength[lane], x[a],
                                          x[b], v[a], v[b]);
    };
    for (std::size_t q = 0; q < blocks.blockCount(); ++q) {
        const Index a0 = blocks.first[q], offset = blocks.offset[q];
        if (offset == 1) {
            const bool previousInRow = q > 0 && blocks.offset[q - 1] == 1 && blocks.first[q - 1] + W == a0;
            const bool nextInRow = q + 1 < blocks.blockCount() && blocks.offset[q + 1] == 1 && blocks.first[q + 1] == a0 + W;
            for (Index i = 0; i < W; ++i) {
                const Vec3 before = i > 0 ? force(q, i - 1) : previousInRow ? force(q - 1, W - 1) : Vec3::Zero();
                f[a0 + i] = (f[a0 + i] + force(q, i)) - before;
            }
            if (!nextInRow) f[a0 + W] -= force(q, W - 1);
            continue;
        }
        for (Index i = 0; i < W; ++i) f[a0 + i] += force(q, i);
        for (Index i = 0; i < W; ++i) f[a0 + offset + i] -= force(q, i);
    }
}

// Positions about one apart along x (mass m near x = m), random velocities and pending forces:
// the state the hand-made block tests start from.
struct BlockInputs {
    std::vector<Vec3> x, v, f0;
};
BlockInputs randomBlockInputs(std::size_t masses, std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    BlockInputs in{std::vector<Vec3>(masses), std::vector<Vec3>(masses), std::vector<Vec3>(masses)};
    for (std::size_t m = 0; m < masses; ++m) {
        in.x[m] = Vec3(double(m) + 0.3 * u(rng), u(rng), u(rng));
        in.v[m] = Vec3(u(rng), u(rng), u(rng));
        in.f0[m] = Vec3(u(rng), u(rng), u(rng));
    }
    return in;
}

// Each available kernel's block forces added to the pending forces, against `expected` bit for
// bit; how many kernels ran.
int expectEveryKernelGives(const SpringBlocks& blocks, const BlockInputs& in, const std::vector<Vec3>& expected) {
    int kernels = 0;
    for (BlockKernel kernel : kAllKernels) {
        if (!detail::blockKernelAvailable(kernel)) continue;
        std::vector<Vec3> f = in.f0;
        detail::blockForces(blocks, in.x.data()->data(), in.v.data()->data(), f.data()->data(), kernel);
        EXPECT_TRUE(sameBits(f, expected)) << detail::toString(kernel);
        ++kernels;
    }
    return kernels;
}

SimulationSettings settingsFor(RestorationMethod method, Integrator integrator) {
    SimulationSettings s;
    s.gravity = Vec3(0, -9.81, 0);
    s.globalDamping = 0.1;
    s.integrator = integrator;
    s.restoration.method = method;
    s.restoration.constraintFraction = 0.01;
    return s;
}

}  // namespace

// Row meshes (mostly blocks) and a shuffled one (every spring listed).
TEST(BlockStep, EveryKernelGivesTheScalarKernelsBits) {
    int compared = 0;
    for (const TriMesh& mesh : {makeTorus1(), makeTorus2(), makeHeart(), flexfit::testing::shuffledVertices(makeTorus2(), 4)}) {
        const auto model = buildPartModel(mesh);
        for (RestorationMethod method : {RestorationMethod::None, RestorationMethod::AnchorSprings, RestorationMethod::Constraint})
            for (Integrator integrator : {Integrator::SemiImplicitEuler, Integrator::ExplicitEuler}) {
                SCOPED_TRACE(mesh.name + " " + toString(method) + " " + toString(integrator));
                const SimulationSettings settings = settingsFor(method, integrator);
                const PartState scalar = runBlocks(*model, settings, BlockKernel::Scalar, 60);
                for (BlockKernel kernel : kAllKernels) {
                    if (kernel == BlockKernel::Scalar || !detail::blockKernelAvailable(kernel)) continue;
                    EXPECT_TRUE(sameBits(scalar, runBlocks(*model, settings, kernel, 60))) << detail::toString(kernel);
                    ++compared;
                }
                for (const Vec3& x : scalar.positions) ASSERT_TRUE(x.allFinite());
            }
    }
    RecordProperty("vector_kernel_comparisons", compared);
    if (compared == 0) GTEST_SKIP() << "this CPU has neither AVX2 nor AVX-512: only the scalar kernel ran";
}

TEST(BlockStep, EveryKernelMatchesTheNaiveReference) {
    // The naive model (heap objects, its own spring set) shares no code with the library.
    for (const TriMesh& mesh : {makeTorus2(), makeHeart(), flexfit::testing::shuffledVertices(makeTorus2(), 4)}) {
        const Material material = Material::elastic();
        const auto model = buildPartModel(mesh, {material, 1.5, {}, {}, {}, {}});
        for (BlockKernel kernel : kAllKernels) {
            if (!detail::blockKernelAvailable(kernel)) continue;
            SCOPED_TRACE(mesh.name + " " + detail::toString(kernel));
            const auto owned = naive::modelFromMesh(mesh, 1.5, material.stiffness, material.damping);
            naive::Model& reference = *owned;
            SimulationSettings settings = settingsFor(RestorationMethod::None, Integrator::SemiImplicitEuler);
            settings.globalDamping = 0.3;
            const detail::MassUpdate update = detail::MassUpdate::from(settings);
            PartState state = PartState::atRest(*model);
            std::mt19937 rng(11);
            std::uniform_real_distribution<double> kick(-1.0, 1.0);
            for (std::size_t i = 0; i < model->massCount(); ++i) {
                state.velocities[i] = Vec3(kick(rng), kick(rng), kick(rng));
                reference.masses[i]->velocity = {state.velocities[i].x(), state.velocities[i].y(), state.velocities[i].z()};
            }
            for (int step = 0; step < 300; ++step) {
                detail::stepSpringBlocks(*model, update, state, kernel);
                reference.step(1e-3, naive::Vector3D(0, -9.81, 0), 0.3);
            }
            double worst = 0.0;
            for (std::size_t i = 0; i < model->massCount(); ++i) {
                const naive::Vector3D& p = reference.masses[i]->position;
                worst = std::max(worst, (state.positions[i] - Vec3(p.x, p.y, p.z)).norm());
            }
            EXPECT_LT(worst, 1e-9);
        }
    }
}

// The heart's springs by blocks, and the same springs all listed (no blocks), in every kernel.
TEST(BlockStep, AgreesWithTheSameSpringsInNoBlock) {
    const auto model = buildPartModel(makeHeart());
    ASSERT_TRUE(model->hasSpringBlocks());
    auto unblocked = std::make_shared<PartModel>(*model);
    SpringBlocks none;
    none.laneOfSpring.assign(model->springCount(), SpringBlocks::kNoLane);
    for (std::size_t e = 0; e < model->springCount(); ++e) none.remainder.push_back(Index(e));
    none.remainderSprings = springListOf(*model, none.remainder);
    unblocked->springBlocks = std::make_shared<const SpringBlocks>(std::move(none));
    for (const auto kernel : flexfit::testing::availableBlockKernels())
        for (RestorationMethod method : {RestorationMethod::None, RestorationMethod::AnchorSprings, RestorationMethod::Constraint}) {
            const SimulationSettings settings = settingsFor(method, Integrator::SemiImplicitEuler);
            const detail::MassUpdate update = detail::MassUpdate::from(settings);
            PartState blocks = kickedState(*model, 9), listed = blocks;
            for (int step = 0; step < 100; ++step) {
                detail::stepSpringBlocks(*model, update, blocks, kernel);
                detail::stepSpringBlocks(*unblocked, update, listed, kernel);
            }
            double worst = 0.0;
            for (std::size_t i = 0; i < model->massCount(); ++i)
                worst = std::max(worst, (blocks.positions[i] - listed.positions[i]).norm());
            EXPECT_LT(worst, 1e-12) << toString(method) << " " << toString(kernel);  // only the order of the sums differs
        }
}

TEST(BlockStep, StepFullModelTakesBlocksWhenTheModelHasThem) {
    const SimulationSettings settings = settingsFor(RestorationMethod::Constraint, Integrator::SemiImplicitEuler);
    const detail::MassUpdate update = detail::MassUpdate::from(settings);
    // Rows: the fastest block kernel, bit for bit.
    const auto rows = buildPartModel(makeTorus1());
    PartState viaApi = kickedState(*rows, 2), viaBlocks = viaApi;
    StepCounters counters;
    for (int step = 0; step < 20; ++step) {
        stepFullModel(*rows, settings, {}, viaApi, &counters);
        const detail::FlushDenormals flush;
        detail::stepSpringBlocks(*rows, update, viaBlocks, detail::fastestBlockKernel());
    }
    EXPECT_TRUE(sameBits(viaApi, viaBlocks));
    EXPECT_EQ(counters.springsEvaluated, 20 * rows->springCount());
    EXPECT_EQ(counters.massesIntegrated, 20 * rows->massCount());
    // No useful vertex order: every spring listed, the same bits as the scalar kernel's.
    const auto unordered = buildPartModel(flexfit::testing::shuffledVertices(makeTorus1(), 8));
    ASSERT_TRUE(unordered->springBlocks->empty());
    ASSERT_EQ(unordered->springBlocks->remainder.size(), unordered->springCount());
    PartState apiState = kickedState(*unordered, 2), scalarState = apiState;
    for (int step = 0; step < 20; ++step) {
        stepFullModel(*unordered, settings, {}, apiState);
        const detail::FlushDenormals flush;
        detail::stepSpringBlocks(*unordered, update, scalarState, BlockKernel::Scalar);
    }
    EXPECT_TRUE(sameBits(apiState, scalarState));
}

TEST(BlockStep, HandMadeBlocksFollowTheDocumentedOrderInEveryKernel) {
    // Rows that continue and rows that break, offsets 2-7 whose two ends overlap, an offset-1
    // block last in the list, and a zero-length lane; random state with pending forces.
    SpringBlocks blocks;
    const std::vector<std::pair<Index, Index>> layout = {{0, 1},  {8, 1},  {16, 1}, {30, 1}, {0, 2},  {40, 3},
                                                         {52, 4}, {60, 5}, {70, 6}, {84, 7}, {20, 37}, {100, 1}};
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (auto [first, offset] : layout) {
        blocks.first.push_back(first);
        blocks.offset.push_back(offset);
        for (int i = 0; i < SpringBlocks::kWidth; ++i) {
            blocks.restLength.push_back(1.0 + 0.5 * u(rng));
            blocks.stiffness.push_back(2.0 + u(rng));
            blocks.damping.push_back(0.1 + 0.05 * u(rng));
        }
    }
    const std::size_t masses = 110;
    BlockInputs in = randomBlockInputs(masses, rng);
    in.x[44] = in.x[41];  // lane 1 of the offset-3 block at 40: a zero-length spring
    std::vector<Vec3> expected = in.f0;
    documentedBlockForces(blocks, in.x, in.v, expected);
    RecordProperty("kernels", expectEveryKernelGives(blocks, in, expected));
    if (!detail::blockKernelAvailable(BlockKernel::Avx512))
        std::cout << "note: no AVX-512 on this CPU, its kernel was not compared\n";
}

// Blocks with empty lanes, the row block's last one ending at the last mass, over arrays of
// exactly the model's masses (the sanitizers check that no kernel reads or writes past them):
// every kernel gives the springs' forces in the documented order, the empty lanes adding nothing
// to pending forces that are not zero.
TEST(BlockStep, BlocksWithEmptyLanesEndingAtTheLastMassInEveryKernel) {
    std::vector<Index> a, b;
    for (Index first = 4; first <= 10; ++first) a.push_back(first), b.push_back(first + 1);  // row: lanes 4..10, 11 empty
    for (Index first : {0u, 1u, 2u, 3u, 5u}) a.push_back(first), b.push_back(first + 3);    // offset 3: lanes 4, 6, 7 empty
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> rest, k, c;
    for (std::size_t e = 0; e < a.size(); ++e) rest.push_back(1.0 + 0.5 * u(rng)), k.push_back(2.0 + u(rng)), c.push_back(0.1 + 0.05 * u(rng));
    const std::size_t masses = 13;
    const SpringBlocks blocks = buildSpringBlocks(a, b, rest, k, c, masses);
    ASSERT_EQ(blocks.blockCount(), 2u);
    ASSERT_EQ(blocks.first[0] + SpringBlocks::kWidth + blocks.offset[0], masses);  // the row block reaches mass 12
    ASSERT_EQ(std::count(blocks.laneSpring.begin(), blocks.laneSpring.end(), SpringBlocks::kNoLane), 4);
    BlockInputs in = randomBlockInputs(masses, rng);
    std::vector<Vec3> expected = in.f0;
    documentedBlockForces(blocks, in.x, in.v, expected);
    expectEveryKernelGives(blocks, in, expected);
}

// holdAtRest: masses with cover count 0 back to rest with zero velocity, the others untouched,
// in every kernel, against a mass-by-mass reference, on mass counts that are and are not
// multiples of the vector width and on covers from none to all.
TEST(BlockStep, HoldAtRestPutsBackExactlyTheUncoveredMassesInEveryKernel) {
    for (const TriMesh& mesh : {makeIcoSphere(1.0, 2), makeTorus(3.0, 1.0, 9, 7)}) {
        const auto model = buildPartModel(mesh);
        for (const double share : {0.0, 0.1, 0.5, 0.9, 1.0}) {
            std::mt19937 rng(unsigned(share * 100) + unsigned(model->massCount()));
            std::bernoulli_distribution covered(share);
            std::vector<std::uint16_t> cover(model->massCount());
            for (auto& c : cover) c = covered(rng) ? std::uint16_t(1 + rng() % 3) : 0;
            const PartState moved = kickedState(*model, 5);
            PartState expected = moved;
            for (std::size_t m = 0; m < cover.size(); ++m)
                if (cover[m] == 0) {
                    expected.positions[m] = model->restPositions[m];
                    expected.velocities[m] = Vec3::Zero();
                }
            for (BlockKernel kernel : kAllKernels) {
                if (!detail::blockKernelAvailable(kernel)) continue;
                PartState state = moved;
                detail::holdAtRest(*model, cover, state, kernel);
                EXPECT_EQ(state.positions, expected.positions) << detail::toString(kernel) << ", share " << share;
                EXPECT_EQ(state.velocities, expected.velocities) << detail::toString(kernel) << ", share " << share;
            }
        }
    }
}

// The region step's vector blocks: every kernel gives the bits of a spring-by-spring reference
// that applies each force to the moving ends only, blocks in the listed order (first ends, then
// second ends), rows (offset 1) among them. The forces start non-zero, so a kernel that summed
// a mass's two terms in another order would show; compared bit for bit (+0 against -0 too).
// Two covers: a third of the masses held at random (most blocks partly moving), and long runs of
// moving masses between held stripes, so blocks whose ends all move (which the vector kernels sum
// without masks) and partly moving ones both come, rows and other offsets alike.
TEST(BlockStep, RegionBlocksReachOnlyMovingEndsInEveryKernel) {
    const auto model = buildPartModel(makeTorus2());
    const SpringBlocks& blocks = *model->springBlocks;
    ASSERT_FALSE(blocks.empty());
    PartState moved = kickedState(*model, 8);
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> pending(-1e-3, 1e-3);
    for (Vec3& f : moved.forces) f = Vec3(pending(rng), pending(rng), pending(rng));
    std::vector<Index> listed;
    for (Index q = 0; q < blocks.blockCount(); q += 1 + rng() % 3) listed.push_back(q);
    std::shuffle(listed.begin(), listed.end(), rng);
    ASSERT_TRUE(std::any_of(listed.begin(), listed.end(), [&](Index q) { return blocks.offset[q] == 1; }));
    ASSERT_TRUE(std::any_of(listed.begin(), listed.end(), [&](Index q) { return blocks.offset[q] > 1; }));
    ASSERT_TRUE(std::any_of(listed.begin(), listed.end(), [&](Index q) {  // a block with empty lanes
        return std::count(blocks.laneSpring.begin() + 8 * q, blocks.laneSpring.begin() + 8 * q + 8, SpringBlocks::kNoLane) > 0;
    }));
    std::vector<std::uint16_t> randomCover(model->massCount()), stripedCover(model->massCount());
    for (auto& c : randomCover) c = rng() % 3 == 0 ? 0 : 1;
    for (std::size_t m = 0; m < stripedCover.size(); ++m) stripedCover[m] = (m / 40) % 4 == 0 ? 0 : 1;
    // Whether every end of block q moves: masses a0 .. a0 + 7 and a0 + offset .. a0 + offset + 7.
    auto allEndsMove = [&](const std::vector<std::uint16_t>& cover, Index q) {
        for (Index i = 0; i < SpringBlocks::kWidth; ++i)
            if (cover[blocks.first[q] + i] == 0 || cover[blocks.first[q] + blocks.offset[q] + i] == 0) return false;
        return true;
    };
    for (const auto& [name, cover] : {std::pair{"random", &randomCover}, std::pair{"striped", &stripedCover}}) {
        SCOPED_TRACE(name);
        const bool striped = cover == &stripedCover;
        for (const bool row : {true, false})
            for (const bool all : {true, false}) {
                const bool present = std::any_of(listed.begin(), listed.end(), [&](Index q) {
                    return (blocks.offset[q] == 1) == row && allEndsMove(*cover, q) == all;
                });
                if (striped) {
                    EXPECT_TRUE(present) << (row ? "row" : "other") << " blocks with " << (all ? "all" : "not all") << " ends moving";
                }
            }
        PartState expected = moved;  // the blocks' springs one by one; empty lanes add nothing
        for (Index q : listed) {
            const std::span<const Index> lanes(blocks.laneSpring.data() + SpringBlocks::kWidth * q, SpringBlocks::kWidth);
            Vec3 g[SpringBlocks::kWidth];
            for (Index i = 0; i < SpringBlocks::kWidth; ++i) {
                const Index e = lanes[i];
                if (e == SpringBlocks::kNoLane) continue;
                g[i] = detail::springForceOnFirst(model->stiffness[e], model->damping[e], model->restLength[e], moved.positions[model->springA[e]],
                                                  moved.positions[model->springB[e]], moved.velocities[model->springA[e]],
                                                  moved.velocities[model->springB[e]]);
            }
            for (Index i = 0; i < SpringBlocks::kWidth; ++i)
                if (lanes[i] != SpringBlocks::kNoLane && (*cover)[model->springA[lanes[i]]] != 0)
                    expected.forces[model->springA[lanes[i]]] += g[i];
            for (Index i = 0; i < SpringBlocks::kWidth; ++i)
                if (lanes[i] != SpringBlocks::kNoLane && (*cover)[model->springB[lanes[i]]] != 0)
                    expected.forces[model->springB[lanes[i]]] -= g[i];
        }
        for (BlockKernel kernel : kAllKernels) {
            if (!detail::blockKernelAvailable(kernel)) continue;
            PartState state = moved;
            detail::regionBlockForces(blocks, listed, cover->data(), state.positions.data()->data(), state.velocities.data()->data(),
                                      state.forces.data()->data(), kernel);
            EXPECT_EQ(std::memcmp(state.forces.data(), expected.forces.data(), state.forces.size() * sizeof(Vec3)), 0)
                << detail::toString(kernel);
        }
    }
}

// Listed springs (the remainder, a region's loose springs): a shuffled list with runs of
// consecutive springs in order and out of order, each spring's force from springForceOnFirst
// applied in list order, to both ends or only to covered ones; the lists' lengths leave 0-3
// springs for the scalar tail. Every kernel gives these exact bits.
TEST(BlockStep, ListedSpringsFollowTheListInEveryKernel) {
    const auto model = buildPartModel(flexfit::testing::shuffledVertices(makeTorus2(), 6));
    const PartState moved = kickedState(*model, 12);
    std::mt19937 rng(9);
    std::vector<std::uint16_t> cover(model->massCount());
    for (auto& c : cover) c = rng() % 3 == 0 ? 0 : 1;
    std::vector<Index> runs;  // groups of 4 consecutive springs: in order, reversed, middle swapped
    for (Index e = 0; e + 4 <= model->springCount(); e += 4) runs.push_back(e);
    std::shuffle(runs.begin(), runs.end(), rng);
    const Index orders[3][4] = {{0, 1, 2, 3}, {3, 2, 1, 0}, {0, 2, 1, 3}};
    std::vector<Index> list;
    for (std::size_t r = 0; r < runs.size() / 3; ++r)
        for (Index i : orders[r % 3]) list.push_back(runs[r] + i);
    for (std::size_t r = runs.size() / 3; r < runs.size() / 2; ++r) list.push_back(runs[r] + Index(rng() % 4));
    ASSERT_GT(list.size(), 2 * detail::kListChunk);  // several chunks
    for (std::size_t tail = 0; tail < 8; ++tail) {  // every length of the last group of 8 (AVX-512) or 4
        const std::span<const Index> springs(list.data(), list.size() - tail);
        for (const bool covered : {false, true}) {
            PartState expected = moved;
            for (const Index e : springs) {
                const Index a = model->springA[e], b = model->springB[e];
                const Vec3 g = detail::springForceOnFirst(model->stiffness[e], model->damping[e], model->restLength[e],
                                                          moved.positions[a], moved.positions[b], moved.velocities[a],
                                                          moved.velocities[b]);
                if (!covered || cover[a] != 0) expected.forces[a] += g;
                if (!covered || cover[b] != 0) expected.forces[b] -= g;
            }
            for (BlockKernel kernel : kAllKernels) {
                if (!detail::blockKernelAvailable(kernel)) continue;
                PartState state = moved;
                detail::listedSpringForces(springListOf(*model, springs), covered ? cover.data() : nullptr,
                                           state.positions.data()->data(), state.velocities.data()->data(),
                                           state.forces.data()->data(), kernel);
                EXPECT_TRUE(sameBits(state.forces, expected.forces))
                    << detail::toString(kernel) << " tail " << tail << " covered " << covered;
            }
        }
    }
}

// A list of masses integrated by each kernel against integrateMass mass by mass, with every
// restoration and integrator, at every length of the last group of 8 (the AVX-512 kernel repeats
// its last mass there), the last mass of the model included (its rows are read masked); and the
// check's bits against beyondBits of each new position.
TEST(BlockStep, ListedMassesIntegrateAsIntegrateMassInEveryKernel) {
    const auto model = buildPartModel(flexfit::testing::shuffledVertices(makeTorus2(), 4));
    const PartState moved = kickedState(*model, 5);
    std::mt19937 rng(17);
    std::vector<Index> all(model->massCount());
    std::iota(all.begin(), all.end(), Index(0));
    std::shuffle(all.begin(), all.end(), rng);
    all.insert(all.begin() + 5, Index(model->massCount() - 1));
    all.erase(std::find(all.begin() + 6, all.end(), Index(model->massCount() - 1)));
    PartState spoiled = moved;  // the tenth listed mass beyond the bound: the check must see it
    spoiled.positions[all[9]].y() += 3.0 * model->positionBound;
    for (RestorationMethod method : {RestorationMethod::None, RestorationMethod::AnchorSprings, RestorationMethod::Constraint})
        for (Integrator integrator : {Integrator::SemiImplicitEuler, Integrator::ExplicitEuler}) {
            const detail::MassUpdate update = detail::MassUpdate::from(settingsFor(method, integrator));
            for (std::size_t n : {std::size_t(0), std::size_t(1), std::size_t(7), std::size_t(8), std::size_t(13), std::size_t(30)}) {
                const std::span<const Index> masses(all.data(), n);
                PartState expected = spoiled;
                detail::PositionCheck reference(model->positionBound);
                reference.origin = moved.positions[3];
                for (const Index m : masses) {
                    detail::integrateMass(*model, update, expected, m);
                    reference.add(expected, m);
                }
                EXPECT_EQ(detail::noneBeyond(reference.bits), n < 10) << n;
                for (BlockKernel kernel : kAllKernels) {
                    if (!detail::blockKernelAvailable(kernel)) continue;
                    PartState state = spoiled;
                    detail::PositionCheck check(model->positionBound);
                    check.origin = reference.origin;
                    detail::integrateListed(*model, update, masses, state, kernel, &check);
                    EXPECT_TRUE(sameBits(state, expected)) << detail::toString(kernel) << " " << n << " masses";
                    EXPECT_EQ(check.bits, reference.bits) << detail::toString(kernel) << " " << n << " masses";
                }
            }
        }
}

// The divergence check the vector integration makes as it writes the positions (PositionCheck)
// against the separate pass over the positions it replaces (detail::beyondBits, measured from
// mass 0's new position): the same or-ed bits exactly, whether the culprit is in the first
// group (mass 0 itself, which moves the origin), a later one or the scalar tail, whatever it
// is (not finite, beyond the bound, a hair within it), with and without held masses and with
// an infinite bound. A torus of 35 masses: 4 groups of 8 and 3 masses after them (8 groups of
// 4 and 3 for AVX2). The scalar kernel checks nothing (not covered: the caller checks).
TEST(BlockStep, TheIntegrationPassChecksThePositionsAsTheSeparatePassWould) {
    auto model = std::const_pointer_cast<PartModel>(buildPartModel(makeTorus(10.0, 2.5, 7, 5)));
    ASSERT_EQ(model->massCount(), 35u);
    const double bound = model->positionBound;
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    // Position offsets that stay beyond, or within, the bound after one step's small moves.
    const std::vector<std::pair<const char*, Vec3>> spoils = {
        {"nothing", Vec3::Zero()},           {"nan", Vec3(nan, 0, 0)},          {"inf", Vec3(0, -inf, 0)},
        {"3 bounds", Vec3(0, 0, 3.0 * bound)}, {"half a bound", Vec3(0.5 * bound, 0, 0)}};
    std::vector<std::uint16_t> cover(35, 1);  // the masses checked above
    std::fill(cover.begin() + 10, cover.begin() + 20, std::uint16_t(0));  // held: at rest, and left there by the pass
    for (const BlockKernel kernel : kAllKernels) {
        if (!detail::blockKernelAvailable(kernel)) continue;
        for (const double modelBound : {bound, inf}) {
            model->positionBound = modelBound;
            for (const std::uint16_t* held : std::vector<const std::uint16_t*>{nullptr, cover.data()})
                for (const Index mass : {Index(0), Index(5), Index(13), Index(21), Index(33)})
                    for (const auto& [name, offset] : spoils) {
                        if (held != nullptr && cover[mass] == 0) continue;  // a held mass is at rest (stepSpringBlocks)
                        PartState state = kickedState(*model, 3);
                        if (held != nullptr) detail::holdAtRest(*model, cover, state, BlockKernel::Scalar);
                        state.positions[mass] += offset;
                        detail::PositionCheck check(model->positionBound);
                        detail::stepSpringBlocks(*model, detail::MassUpdate::from(SimulationSettings{}), state, kernel, held, &check);
                        const std::string where = std::string(detail::toString(kernel)) + ", mass " + std::to_string(mass) + " " + name +
                                                  (held != nullptr ? ", held" : "") + (std::isinf(modelBound) ? ", no bound" : "");
                        if (kernel == BlockKernel::Scalar) {
                            EXPECT_FALSE(check.covered) << where;
                            continue;
                        }
                        ASSERT_TRUE(check.covered) << where;
                        const Vec3 origin = std::isinf(modelBound) ? Vec3::Zero() : state.positions[0];
                        EXPECT_EQ(check.bits, detail::beyondBits(state.positions, origin, detail::carryBeyond(modelBound))) << where;
                        const bool bad = std::string(name) == "nan" || std::string(name) == "inf" ||
                                         (std::string(name) == "3 bounds" && !std::isinf(modelBound));
                        EXPECT_EQ(check.passed(), !bad) << where;
                    }
        }
    }
}
