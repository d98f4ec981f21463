// Internal to src/dynamics (and the step benchmark): the full step's kernels.
//
// Every model's springs are laid out as spring blocks plus a remainder (spring_blocks.hpp; a
// model in no useful vertex order has no blocks, all its springs in the remainder). The step
// has a scalar kernel and, on x86-64, AVX2 and AVX-512 kernels chosen at run time; all three
// give the same bits (tested), so a run does not depend on the machine's vector unit.
#pragma once

#include "divergence.hpp"
#include "mass_update.hpp"
#include "model/spring_blocks.hpp"

#include <limits>

#if defined(__x86_64__) && defined(__GNUC__)
#define FLEXFIT_X86_KERNELS 1  // block_step_x86.cpp: AVX2 and AVX-512 by function target attributes
#endif

namespace flexfit::detail {

// The public step functions' checks: valid settings, a state of the model's size, a region
// built for the model (when given), loads on existing masses with finite forces; InputError
// naming `what` otherwise, before anything changes. O(1 + loads).
void requireStepInputs(const PartModel& model, const SimulationSettings& settings, const PartState& state,
                       const ActiveRegion* region, std::span<const PointLoad> loads, const char* what);

enum class BlockKernel { Scalar, Avx2, Avx512 };

// Compiled in and supported by this CPU.
bool blockKernelAvailable(BlockKernel kernel);
// The widest available kernel, resolved once.
BlockKernel fastestBlockKernel();
// The kernel stepFullModel uses: the fastest, unless a ScopedBlockKernel chose another.
BlockKernel fullStepKernel();
// Tests: every full step in this scope runs `kernel` (which must be available), so a whole
// scene can be checked with each kernel. Not thread-safe; scopes must not overlap.
class ScopedBlockKernel {
public:
    explicit ScopedBlockKernel(BlockKernel kernel);
    ~ScopedBlockKernel();
    ScopedBlockKernel(const ScopedBlockKernel&) = delete;
    ScopedBlockKernel& operator=(const ScopedBlockKernel&) = delete;
};
const char* toString(BlockKernel kernel);

// The blocks' forces only, added into f (3 doubles per mass) in the order spring_blocks.hpp
// fixes; the kernel must be available.
void blockForces(const SpringBlocks& blocks, const double* x, const double* v, double* f, BlockKernel kernel);

// The divergence check over the new positions (checkAllMassesFinite's, divergence.hpp), made
// by the vector integration as it writes them instead of in a pass of its own (which cost
// about 9 % of the heart's full step): the beyond-bits of x - origin or-ed into `bits`. The
// origin (boundOrigin) is mass 0's new position when the bound is finite, so whoever runs the
// pass integrates mass 0 first and then fixes it; the vector kernels take a check only with its
// origin fixed. `covered` says whether every mass was checked (the scalar kernel checks none:
// the caller then makes the whole check).
struct PositionCheck {
    explicit PositionCheck(double positionBound) : bound(positionBound), carry(carryBeyond(positionBound)) {}
    double bound;
    std::uint64_t carry;
    Vec3 origin = Vec3::Zero();
    std::uint64_t bits = 0;
    bool covered = false;
    // Whether the origin is mass 0's position, to be written before the others are checked.
    bool fromMassZero() const { return bound < std::numeric_limits<double>::infinity(); }
    // Once mass 0's new position is written (or it does not move).
    void fixOrigin(const PartState& state) { origin = boundOrigin(state, bound); }
    // The bits of masses [first, first + count), written already.
    void add(const PartState& state, std::size_t first, std::size_t count) {
        bits |= beyondBits(std::span<const Vec3>(state.positions).subspan(first, count), origin, carry);
    }
    // The bits of one mass (the region step's loose masses: no setup of the many-value pass).
    void add(const PartState& state, std::size_t mass) { bits |= beyondBits(state.positions[mass], origin, carry); }
    bool passed() const { return covered && noneBeyond(bits); }
};

// Springs by blocks, the remainder, then every mass. The kernel must be available. With
// `held` (a cover count per mass), each mass whose count is 0 ends the step at rest instead,
// velocity and force zero (what holdAtRest does after the step, in the integration's pass).
// Those masses must be at rest when the step begins (a Part keeps every mass no zone covers so):
// the vector kernels leave a group of masses none of which moves (8 with AVX-512, 4 with AVX2)
// where it is and only zero its forces, which is the same bits (a held full step at 62 %
// coverage of a large torus went from 1.036 to 0.995 of the whole model's step).
// With `check`, the vector kernels check the new positions as they write them.
void stepSpringBlocks(const PartModel& model, const MassUpdate& update, PartState& state, BlockKernel kernel,
                      const std::uint16_t* held = nullptr, PositionCheck* check = nullptr);

// stepFullModel, or with `held` (cover counts) the full step standing for a region's
// (stepRegionByFullModel): the masses no zone covers end the step at rest.
void stepAllMasses(const PartModel& model, const SimulationSettings& settings, std::span<const PointLoad> loads,
                   const std::uint16_t* held, PartState& state, StepCounters* counters);

// After a full step that stood for a region's (stepRegionByFullModel): every mass whose cover
// count is 0 back to rest, velocity zero (the full step left every force at zero). A pure
// selection, so every kernel gives the same bits.
void holdAtRest(const PartModel& model, std::span<const std::uint16_t> cover, PartState& state, BlockKernel kernel);

// The region step's vector blocks (ActiveRegion::vectorBlocks), in that order: block q's forces
// g_i, then f[a0 + i] += g_i for each first end that moves, then f[a0 + offset + i] -= g_i for
// each second end that moves (cover count non-zero). Scalar, AVX2 or AVX-512: the same bits.
void regionBlockForces(const SpringBlocks& blocks, std::span<const Index> vectorBlocks, const std::uint16_t* cover,
                       const double* x, const double* v, double* f, BlockKernel kernel);

// Listed springs in list order: g on the first end, -g on the second (f[a] += g, f[b] -= g), or
// with a cover only on the ends whose cover count is non-zero. The vector kernels compute the
// forces 8 (AVX-512) or 4 (AVX2) at a time, the last group's lanes past the list repeating its
// last spring, and add them in the same order: the same bits in every kernel.
void listedSpringForces(const SpringList& springs, const std::uint16_t* cover, const double* x, const double* v,
                        double* f, BlockKernel kernel);
// The vector kernels keep the forces of this many listed springs on the stack between passes.
inline constexpr std::size_t kListChunk = 256;

// Integrates the masses of the given octets (masses 8k..8k+7, each once) as integrateScalar
// would, mass by mass: the same bits in every kernel. The masses whose `held` count is 0 are
// put at rest instead (position rest, velocity and force zero: where a region's masses that do
// not move already are). With `check` (its origin fixed), the vector kernels or the new
// positions' beyond-bits into it; the scalar kernel does not.
void integrateOctets(const PartModel& model, const MassUpdate& update, std::span<const Index> octets,
                     const std::uint16_t* held, PartState& state, BlockKernel kernel, PositionCheck* check = nullptr);

// Integrates the listed masses (each once) as integrateMass would, mass by mass: the same bits
// in every kernel (the AVX-512 kernel 8 masses in lanes, the others one at a time). With
// `check` (its origin fixed), every kernel ors the new positions' beyond-bits into it.
void integrateListed(const PartModel& model, const MassUpdate& update, std::span<const Index> masses, PartState& state,
                     BlockKernel kernel, PositionCheck* check = nullptr);

// The vector kernels (block_step_x86.cpp). Forces of all blocks into f (3 doubles per mass).
void blockForcesAvx2(const SpringBlocks& blocks, const double* x, const double* v, double* f);
void blockForcesAvx512(const SpringBlocks& blocks, const double* x, const double* v, double* f);
void listedSpringForcesAvx2(const SpringList& springs, const std::uint16_t* cover, const double* x, const double* v,
                            double* f);
void listedSpringForcesAvx512(const SpringList& springs, const std::uint16_t* cover, const double* x, const double* v,
                              double* f);
// Integrates masses [0, n) for the largest n that is a multiple of the width (4, 8); returns n.
// The masses whose `held` count is 0 (when given) end at rest, as holdAtRest leaves them. With
// `check`, the first group goes first, fixes the origin, and every position is checked.
std::size_t integrateAvx2(const PartModel& model, const MassUpdate& update, PartState& state, const std::uint16_t* held,
                          PositionCheck* check = nullptr);
std::size_t integrateAvx512(const PartModel& model, const MassUpdate& update, PartState& state, const std::uint16_t* held,
                            PositionCheck* check = nullptr);
void regionBlockForcesAvx2(const SpringBlocks& blocks, std::span<const Index> vectorBlocks, const std::uint16_t* cover,
                           const double* x, const double* v, double* f);
void regionBlockForcesAvx512(const SpringBlocks& blocks, std::span<const Index> vectorBlocks, const std::uint16_t* cover,
                             const double* x, const double* v, double* f);
void integrateListedAvx512(const PartModel& model, const MassUpdate& update, std::span<const Index> masses,
                           PartState& state, PositionCheck* check = nullptr);
void integrateOctetsAvx2(const PartModel& model, const MassUpdate& update, std::span<const Index> octets,
                         const std::uint16_t* held, PartState& state, PositionCheck* check = nullptr);
void integrateOctetsAvx512(const PartModel& model, const MassUpdate& update, std::span<const Index> octets,
                           const std::uint16_t* held, PartState& state, PositionCheck* check = nullptr);
// holdAtRest for masses [0, n), n the largest multiple of 8; returns n.
std::size_t holdAtRestAvx512(const PartModel& model, const std::uint16_t* cover, PartState& state);

}  // namespace flexfit::detail
