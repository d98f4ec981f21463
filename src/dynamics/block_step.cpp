// The spring-block full step: dispatch, the scalar kernel and the shared scalar passes.
#include "full_step.hpp"

#include <optional>

namespace flexfit::detail {
namespace {

constexpr std::size_t W = SpringBlocks::kWidth;

std::optional<BlockKernel> chosenKernel;  // ScopedBlockKernel

void blockForcesScalar(const SpringBlocks& blocks, const double* x, const double* v, double* f) {
    double carry[3] = {0.0, 0.0, 0.0};  // g_7 of the previous offset-1 block
    for (std::size_t q = 0; q < blocks.blockCount(); ++q) {
        const std::size_t a0 = blocks.first[q], offset = blocks.offset[q];
        double g[W][3];
        for (std::size_t i = 0; i < W; ++i) {
            const std::size_t a = 3 * (a0 + i), b = 3 * (a0 + i + offset), lane = W * q + i;
            springForce(blocks.stiffness[lane], blocks.damping[lane], blocks.restLength[lane], x + a, x + b, v + a,
                        v + b, g[i]);
        }
        if (offset == 1) {
            const bool continues = blocks.continuesRow(q);
            for (std::size_t i = 0; i < W; ++i)
                for (std::size_t c = 0; c < 3; ++c) {
                    const double previous = i > 0 ? g[i - 1][c] : continues ? carry[c] : 0.0;
                    double& fm = f[3 * (a0 + i) + c];
                    fm = (fm + g[i][c]) - previous;
                }
            for (std::size_t c = 0; c < 3; ++c) carry[c] = g[W - 1][c];
            if (q + 1 == blocks.blockCount() || !blocks.continuesRow(q + 1))
                for (std::size_t c = 0; c < 3; ++c) f[3 * (a0 + W) + c] -= g[W - 1][c];
            continue;
        }
        for (std::size_t i = 0; i < W; ++i)
            for (std::size_t c = 0; c < 3; ++c) f[3 * (a0 + i) + c] += g[i][c];
        for (std::size_t i = 0; i < W; ++i)
            for (std::size_t c = 0; c < 3; ++c) f[3 * (a0 + offset + i) + c] -= g[i][c];
    }
}

// Masses [begin, n) whose cover count is 0 back to rest, velocity zero: by selection, without a
// branch per mass (the region's edge is irregular).
void holdAtRestFrom(const PartModel& model, const std::uint16_t* cover, PartState& state, std::size_t begin) {
    const double* rest = model.restPositions.data()->data();
    double* __restrict x = state.positions.data()->data();
    double* __restrict v = state.velocities.data()->data();
    for (std::size_t m = begin; m < model.massCount(); ++m) {
        const bool moves = cover[m] != 0;
        for (std::size_t c = 0; c < 3; ++c) {
            x[3 * m + c] = moves ? x[3 * m + c] : rest[3 * m + c];
            v[3 * m + c] = moves ? v[3 * m + c] : 0.0;
        }
    }
}

void integrateScalar(const PartModel& model, const MassUpdate& p, PartState& state, std::size_t begin) {
    for (std::size_t i = begin; i < model.massCount(); ++i) integrateMass(model, p, state, i);
}

bool cpuHas(BlockKernel kernel) {
#if defined(FLEXFIT_X86_KERNELS)
    if (kernel == BlockKernel::Avx2) return __builtin_cpu_supports("avx2");
    if (kernel == BlockKernel::Avx512) return __builtin_cpu_supports("avx512f");
#endif
    return kernel == BlockKernel::Scalar;
}

}  // namespace

bool blockKernelAvailable(BlockKernel kernel) {
    return cpuHas(kernel);
}

BlockKernel fastestBlockKernel() {
    static const BlockKernel best = cpuHas(BlockKernel::Avx512) ? BlockKernel::Avx512
                                    : cpuHas(BlockKernel::Avx2) ? BlockKernel::Avx2
                                                                : BlockKernel::Scalar;
    return best;
}

BlockKernel fullStepKernel() { return chosenKernel.value_or(fastestBlockKernel()); }

ScopedBlockKernel::ScopedBlockKernel(BlockKernel kernel) { chosenKernel = kernel; }
ScopedBlockKernel::~ScopedBlockKernel() { chosenKernel.reset(); }

const char* toString(BlockKernel kernel) {
    switch (kernel) {
        case BlockKernel::Scalar: return "scalar";
        case BlockKernel::Avx2: return "avx2";
        case BlockKernel::Avx512: return "avx512";
    }
    return "?";
}

void blockForces(const SpringBlocks& blocks, const double* x, const double* v, double* f, BlockKernel kernel) {
    switch (kernel) {
#if defined(FLEXFIT_X86_KERNELS)
        case BlockKernel::Avx512: blockForcesAvx512(blocks, x, v, f); return;
        case BlockKernel::Avx2: blockForcesAvx2(blocks, x, v, f); return;
#endif
        default: blockForcesScalar(blocks, x, v, f); return;
    }
}

void regionBlockForces(const SpringBlocks& blocks, std::span<const Index> vectorBlocks, const std::uint16_t* cover,
                       const double* x, const double* v, double* f, BlockKernel kernel) {
#if defined(FLEXFIT_X86_KERNELS)
    if (kernel == BlockKernel::Avx512) return regionBlockForcesAvx512(blocks, vectorBlocks, cover, x, v, f);
    if (kernel == BlockKernel::Avx2) return regionBlockForcesAvx2(blocks, vectorBlocks, cover, x, v, f);
#endif
    (void)kernel;
    for (const Index q : vectorBlocks) {
        const std::size_t a0 = blocks.first[q], b0 = a0 + blocks.offset[q];
        double g[W][3];
        for (std::size_t i = 0; i < W; ++i) {
            const std::size_t lane = W * q + i;
            springForce(blocks.stiffness[lane], blocks.damping[lane], blocks.restLength[lane], x + 3 * (a0 + i),
                        x + 3 * (b0 + i), v + 3 * (a0 + i), v + 3 * (b0 + i), g[i]);
        }
        for (std::size_t i = 0; i < W; ++i)
            if (cover[a0 + i] != 0)
                for (std::size_t c = 0; c < 3; ++c) f[3 * (a0 + i) + c] += g[i][c];
        for (std::size_t i = 0; i < W; ++i)
            if (cover[b0 + i] != 0)
                for (std::size_t c = 0; c < 3; ++c) f[3 * (b0 + i) + c] -= g[i][c];
    }
}

void listedSpringForces(const SpringList& springs, const std::uint16_t* cover, const double* x, const double* v,
                        double* f, BlockKernel kernel) {
#if defined(FLEXFIT_X86_KERNELS)
    if (kernel == BlockKernel::Avx512) return listedSpringForcesAvx512(springs, cover, x, v, f);
    if (kernel == BlockKernel::Avx2) return listedSpringForcesAvx2(springs, cover, x, v, f);
#endif
    (void)kernel;
    for (std::size_t i = 0; i < springs.size(); ++i) {
        const std::size_t a = springs.springA[i], b = springs.springB[i];
        double g[3];
        springForce(springs.stiffness[i], springs.damping[i], springs.restLength[i], x + 3 * a, x + 3 * b, v + 3 * a,
                    v + 3 * b, g);
        if (cover == nullptr || cover[a] != 0)
            for (std::size_t c = 0; c < 3; ++c) f[3 * a + c] += g[c];
        if (cover == nullptr || cover[b] != 0)
            for (std::size_t c = 0; c < 3; ++c) f[3 * b + c] -= g[c];
    }
}

void integrateOctets(const PartModel& model, const MassUpdate& update, std::span<const Index> octets,
                     const std::uint16_t* held, PartState& state, BlockKernel kernel, PositionCheck* check) {
#if defined(FLEXFIT_X86_KERNELS)
    if (kernel == BlockKernel::Avx512) return integrateOctetsAvx512(model, update, octets, held, state, check);
    if (kernel == BlockKernel::Avx2) return integrateOctetsAvx2(model, update, octets, held, state, check);
#endif
    (void)check;
    (void)kernel;
    for (const Index octet : octets)
        for (std::size_t i = 8 * std::size_t(octet); i < 8 * std::size_t(octet) + 8; ++i) {
            if (held == nullptr || held[i] != 0) {
                integrateMass(model, update, state, i);
                continue;
            }
            state.positions[i] = model.restPositions[i];
            state.velocities[i] = Vec3::Zero();
            state.forces[i] = Vec3::Zero();
        }
}

void integrateListed(const PartModel& model, const MassUpdate& update, std::span<const Index> masses, PartState& state,
                     BlockKernel kernel, PositionCheck* check) {
#if defined(FLEXFIT_X86_KERNELS)
    if (kernel == BlockKernel::Avx512) return integrateListedAvx512(model, update, masses, state, check);
#endif
    (void)kernel;
    for (const Index i : masses) {
        integrateMass(model, update, state, i);
        if (check != nullptr) check->add(state, i);
    }
}

void holdAtRest(const PartModel& model, std::span<const std::uint16_t> cover, PartState& state, BlockKernel kernel) {
    std::size_t done = 0;
#if defined(FLEXFIT_X86_KERNELS)
    if (kernel == BlockKernel::Avx512) done = holdAtRestAvx512(model, cover.data(), state);
#endif
    (void)kernel;
    holdAtRestFrom(model, cover.data(), state, done);
}

void stepSpringBlocks(const PartModel& model, const MassUpdate& update, PartState& state, BlockKernel kernel,
                      const std::uint16_t* held, PositionCheck* check) {
    const double* x = state.positions.data()->data();
    const double* v = state.velocities.data()->data();
    double* f = state.forces.data()->data();
    blockForces(*model.springBlocks, x, v, f, kernel);
    listedSpringForces(model.springBlocks->remainderSprings, nullptr, x, v, f, kernel);
    std::size_t integrated = 0, heldDone = 0;  // what the vector kernels did; the scalar passes finish
#if defined(FLEXFIT_X86_KERNELS)
    if (kernel == BlockKernel::Avx512) heldDone = integrated = integrateAvx512(model, update, state, held, check);
    if (kernel == BlockKernel::Avx2) heldDone = integrated = integrateAvx2(model, update, state, held, check);
#endif
    integrateScalar(model, update, state, integrated);
    if (held != nullptr) holdAtRestFrom(model, held, state, heldDone);
    if (check != nullptr && integrated > 0) {  // the masses after the vector groups, as the kernel checked those
        check->add(state, integrated, model.massCount() - integrated);
        check->covered = true;
    }
}

}  // namespace flexfit::detail
