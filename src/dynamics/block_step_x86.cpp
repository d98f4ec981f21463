// AVX2 and AVX-512 kernels of the spring-block step (full_step.hpp), compiled by function target
// attributes so that the library itself stays built for baseline x86-64; stepSpringBlocks calls
// them only on CPUs that have the instructions.
//
// A block's 8 springs: first ends are masses a0..a0+7, whose positions are 24 contiguous doubles
// x0 y0 z0 x1 ... z7; second ends the same at a0 + offset. The kernels load them as they lie and
// subtract. AVX-512 keeps the products d d and w d in that layout and transposes only their
// per-mass sums to 8 lanes; AVX2 transposes d and w to 4 lanes and back. Each lane evaluates the
// spring force with the operations of detail::springForce in its order (mul, add, sqrt, div:
// each correctly rounded, so a lane equals the scalar result), and the forces are added in the
// order spring_blocks.hpp fixes. Offset-1 blocks (rows) add g_i and subtract g_{i-1} in one pass
// over their 9 masses, carrying g_7 into the next block of the row: two separate passes would
// make the second one's loads wait on the first one's overlapping stores.
//
// Known limit: the kernels' speed depends on where the state's arrays lie (split loads, 4K
// aliasing between positions and forces): up to ~20% between placements on the heart.
#include "full_step.hpp"

#if defined(FLEXFIT_X86_KERNELS)

#include <algorithm>
#include <array>
#include <cstdint>
#include <immintrin.h>

// GCC 12's AVX-512 intrinsics seed results with _mm512_undefined_pd() (`__m512d __Y = __Y;`),
// which -W(maybe-)uninitialized reports at inlined calls: a known false positive.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"

namespace flexfit::detail {
namespace {

constexpr std::size_t W = SpringBlocks::kWidth;

#define FLEXFIT_AVX512 __attribute__((target("avx512f")))
#define FLEXFIT_AVX2 __attribute__((target("avx2")))

// ---------------------------------------------------------------- AVX-512: a block per vector

// vpermt2pd indices: component c of 8 masses from their 24 doubles in 3 vectors, in two steps
// (rows 2c: vectors 0-1, rows 2c+1: then vector 2).
struct Deinterleave512 {
    alignas(64) std::array<std::array<std::int64_t, 8>, 6> rows{};
};

constexpr Deinterleave512 makeDeinterleave512() {
    Deinterleave512 t;
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < 8; ++i) {
            const int flat = 3 * i + c;
            t.rows[2 * c][i] = flat < 16 ? flat : 0;
            t.rows[2 * c + 1][i] = flat < 16 ? i : 8 + (flat - 16);
        }
    return t;
}

constexpr Deinterleave512 kDeinterleave512 = makeDeinterleave512();

// vpermpd indices: a per-mass value spread over the 24 doubles of 8 masses (lane l of vector j is
// mass (8j+l)/3).
constexpr std::array<std::array<std::int64_t, 8>, 3> kSpread512 = {
    {{0, 0, 0, 1, 1, 1, 2, 2}, {2, 3, 3, 3, 4, 4, 4, 5}, {5, 5, 6, 6, 6, 7, 7, 7}}};

FLEXFIT_AVX512 inline __m512d spread8(__m512d perMass, int j) {
    return _mm512_permutexvar_pd(_mm512_loadu_si512(kSpread512[j].data()), perMass);
}

// 24 doubles of 8 masses (x0 y0 z0 x1 ... z7) in 3 vectors.
struct Flat24 {
    __m512d v[3];
};

FLEXFIT_AVX512 inline __m512d component8(const Flat24& flat, int c) {
    const auto& t = kDeinterleave512.rows;
    return _mm512_permutex2var_pd(_mm512_permutex2var_pd(flat.v[0], _mm512_load_si512(t[2 * c].data()), flat.v[1]),
                                  _mm512_load_si512(t[2 * c + 1].data()), flat.v[2]);
}

// (x + y) + z per mass, as 8 lanes: the order of detail::springForce's dot products.
FLEXFIT_AVX512 inline __m512d sumPerMass8(const Flat24& flat) {
    return _mm512_add_pd(_mm512_add_pd(component8(flat, 0), component8(flat, 1)), component8(flat, 2));
}

FLEXFIT_AVX512 inline Flat24 difference24(const double* p, const double* q) {
    Flat24 d;
    for (int j = 0; j < 3; ++j) d.v[j] = _mm512_sub_pd(_mm512_loadu_pd(p + 8 * j), _mm512_loadu_pd(q + 8 * j));
    return d;
}

FLEXFIT_AVX512 inline Flat24 product24(const Flat24& a, const Flat24& b) {
    return {{_mm512_mul_pd(a.v[0], b.v[0]), _mm512_mul_pd(a.v[1], b.v[1]), _mm512_mul_pd(a.v[2], b.v[2])}};
}

// The factor s of g = s d per spring, from |d|^2 and (v_a - v_b).d, as detail::springForce.
FLEXFIT_AVX512 inline __m512d springScale8(__m512d r2, __m512d dot, __m512d k, __m512d c, __m512d restLength) {
    const __m512d length = _mm512_sqrt_pd(r2);
    const __m512d inverse = _mm512_maskz_div_pd(_mm512_cmp_pd_mask(length, _mm512_setzero_pd(), _CMP_GT_OQ),
                                                _mm512_set1_pd(1.0), length);
    const __m512d magnitude =
        _mm512_add_pd(_mm512_mul_pd(k, _mm512_sub_pd(length, restLength)), _mm512_mul_pd(_mm512_mul_pd(c, dot), inverse));
    const __m512i sign = _mm512_set1_epi64(std::int64_t(0x8000000000000000ULL));
    return _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(_mm512_mul_pd(magnitude, inverse)), sign));
}

// [low5 low6 low7 high0 .. high4]: the 8 doubles one mass (3 doubles) earlier in low, high.
FLEXFIT_AVX512 inline __m512d oneMassEarlier(__m512d low, __m512d high) {
    return _mm512_castsi512_pd(_mm512_alignr_epi64(_mm512_castpd_si512(high), _mm512_castpd_si512(low), 5));
}

// The 24 doubles shifted up by one mass: previous's last mass first.
FLEXFIT_AVX512 inline Flat24 shiftOneMass(const Flat24& g, __m512d previous) {
    return {{oneMassEarlier(previous, g.v[0]), oneMassEarlier(g.v[0], g.v[1]), oneMassEarlier(g.v[1], g.v[2])}};
}

// The mass after a row block's 8 (its last second end): f -= g_7, lanes 5-7 of `lastVector`.
FLEXFIT_AVX512 inline void subtractLastSpring8(__m512d lastVector, double* f) {
    alignas(64) double last[8];
    _mm512_store_pd(last, lastVector);
    for (int c = 0; c < 3; ++c) f[c] -= last[5 + c];
}

// Products d d and w d stay in the masses' layout; only their per-mass sums are transposed to
// lanes, and the factor s is spread back: 15 permutes a block instead of 18.
FLEXFIT_AVX512 inline Flat24 blockSpringForces(const SpringBlocks& blocks, std::size_t q, const double* x,
                                               const double* v) {
    const std::size_t a = 3 * std::size_t(blocks.first[q]), b = a + 3 * std::size_t(blocks.offset[q]);
    const Flat24 d = difference24(x + a, x + b), w = difference24(v + a, v + b);
    const __m512d s = springScale8(sumPerMass8(product24(d, d)), sumPerMass8(product24(w, d)),
                                   _mm512_loadu_pd(blocks.stiffness.data() + W * q),
                                   _mm512_loadu_pd(blocks.damping.data() + W * q),
                                   _mm512_loadu_pd(blocks.restLength.data() + W * q));
    Flat24 g;
    for (int j = 0; j < 3; ++j) g.v[j] = _mm512_mul_pd(spread8(s, j), d.v[j]);
    return g;
}

FLEXFIT_AVX512 void blockForces512(const SpringBlocks& blocks, const double* x, const double* v, double* f) {
    __m512d carry = _mm512_setzero_pd();  // previous row block's last vector (g_7 in lanes 5-7)
    for (std::size_t q = 0; q < blocks.blockCount(); ++q) {
        const Flat24 g = blockSpringForces(blocks, q, x, v);
        double* fa = f + 3 * std::size_t(blocks.first[q]);
        if (blocks.offset[q] == 1) {
            const Flat24 shifted = shiftOneMass(g, blocks.continuesRow(q) ? carry : _mm512_setzero_pd());
            for (int j = 0; j < 3; ++j)
                _mm512_storeu_pd(fa + 8 * j,
                                 _mm512_sub_pd(_mm512_add_pd(_mm512_loadu_pd(fa + 8 * j), g.v[j]), shifted.v[j]));
            carry = g.v[2];
            if (q + 1 == blocks.blockCount() || !blocks.continuesRow(q + 1)) subtractLastSpring8(g.v[2], fa + 24);
            continue;
        }
        double* fb = fa + 3 * std::size_t(blocks.offset[q]);
        for (int j = 0; j < 3; ++j) _mm512_storeu_pd(fa + 8 * j, _mm512_add_pd(_mm512_loadu_pd(fa + 8 * j), g.v[j]));
        for (int j = 0; j < 3; ++j) _mm512_storeu_pd(fb + 8 * j, _mm512_sub_pd(_mm512_loadu_pd(fb + 8 * j), g.v[j]));
    }
}

// Bit 3i..3i+2 set for each bit i of an 8-bit mass mask: one mask bit per double of 8 masses.
constexpr std::array<std::uint32_t, 256> kSpread3 = [] {
    std::array<std::uint32_t, 256> table{};
    for (unsigned k = 0; k < 256; ++k)
        for (unsigned bit = 0; bit < 8; ++bit)
            if ((k >> bit) & 1u) table[k] |= 7u << (3 * bit);
    return table;
}();

// Bit i set where the 16-bit count i of `counts` is 0 (SSE2: every kernel may use it).
inline unsigned zeroCountBits(__m128i counts) {
    const __m128i zeroCount = _mm_cmpeq_epi16(counts, _mm_setzero_si128());
    return unsigned(_mm_movemask_epi8(_mm_packs_epi16(zeroCount, _mm_setzero_si128())));
}

// Bits of the masses cover[0..7] whose cover count is 0.
inline unsigned heldBits8(const std::uint16_t* cover) {
    return zeroCountBits(_mm_loadu_si128(reinterpret_cast<const __m128i*>(cover)));
}

// Bits of the masses cover[0..3] whose cover count is 0 (reads those 4 counts only).
inline unsigned heldBits4(const std::uint16_t* cover) {
    return zeroCountBits(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(cover))) & 0xfu;
}

// Bits of the masses cover[0..7] that move (cover count non-zero).
inline unsigned movingBits8(const std::uint16_t* cover) { return ~heldBits8(cover) & 0xffu; }

FLEXFIT_AVX512 std::size_t holdAtRest512(const PartModel& model, const std::uint16_t* cover, PartState& state) {
    const std::size_t n = model.massCount() / 8 * 8;
    const double* rest = model.restPositions.data()->data();
    double* x = state.positions.data()->data();
    double* v = state.velocities.data()->data();
    const __m512d zero = _mm512_setzero_pd();
    for (std::size_t i = 0; i < n; i += 8) {
        const unsigned held = heldBits8(cover + i);
        if (held == 0) continue;
        const std::uint32_t lanes = kSpread3[held];
        for (std::size_t j = 0; j < 3; ++j) {
            const auto m = __mmask8((lanes >> (8 * j)) & 0xffu);
            const std::size_t o = 3 * i + 8 * j;
            _mm512_mask_storeu_pd(x + o, m, _mm512_maskz_loadu_pd(m, rest + o));
            _mm512_mask_storeu_pd(v + o, m, zero);
        }
    }
    return n;
}

// A row block (offset 1) of a region: masses a0 .. a0 + 8, each of a0 + 1 .. a0 + 7 both a first
// and a second end. Stored and reloaded as two passes (as below for other offsets), the second
// pass's loads would straddle the first one's stores and wait for them; here both updates are
// made in registers, in the same order per mass (+ g_i, then - g_(i-1), each where the mass
// moves), so the bits are the same.
FLEXFIT_AVX512 inline void regionRowBlock(const Flat24& g, std::size_t a0, const std::uint16_t* cover, double* f) {
    const std::uint32_t movingA = kSpread3[movingBits8(cover + a0)];
    const unsigned secondEnds = movingBits8(cover + a0 + 1);  // mass a0 + 1 + i is lane i's second end
    const std::uint32_t movingB = kSpread3[(secondEnds << 1) & 0xffu];  // as masses a0 + i, lanes 1..7
    const Flat24 shifted = shiftOneMass(g, _mm512_setzero_pd());
    double* fa = f + 3 * a0;
    for (std::size_t j = 0; j < 3; ++j) {
        const __m512d old = _mm512_loadu_pd(fa + 8 * j);
        const __m512d added = _mm512_mask_add_pd(old, __mmask8((movingA >> (8 * j)) & 0xffu), old, g.v[j]);
        _mm512_storeu_pd(fa + 8 * j, _mm512_mask_sub_pd(added, __mmask8((movingB >> (8 * j)) & 0xffu), added, shifted.v[j]));
    }
    if ((secondEnds & 0x80u) != 0) subtractLastSpring8(g.v[2], fa + 24);  // mass a0 + 8
}

FLEXFIT_AVX512 void regionBlocks512(const SpringBlocks& blocks, std::span<const Index> vectorBlocks, const std::uint16_t* cover,
                                    const double* x, const double* v, double* f) {
    for (const Index q : vectorBlocks) {
        const Flat24 g = blockSpringForces(blocks, q, x, v);
        if (blocks.offset[q] == 1) {
            regionRowBlock(g, blocks.first[q], cover, f);
            continue;
        }
        const std::size_t a0 = blocks.first[q], b0 = a0 + blocks.offset[q];
        const std::uint32_t movingA = kSpread3[movingBits8(cover + a0)];
        const std::uint32_t movingB = kSpread3[movingBits8(cover + b0)];
        double* fa = f + 3 * a0;
        for (std::size_t j = 0; j < 3; ++j) {
            const __m512d old = _mm512_loadu_pd(fa + 8 * j);
            _mm512_storeu_pd(fa + 8 * j, _mm512_mask_add_pd(old, __mmask8((movingA >> (8 * j)) & 0xffu), old, g.v[j]));
        }
        double* fb = f + 3 * b0;  // after the first ends' stores: the ranges overlap when offset < 8
        for (std::size_t j = 0; j < 3; ++j) {
            const __m512d old = _mm512_loadu_pd(fb + 8 * j);
            _mm512_storeu_pd(fb + 8 * j, _mm512_mask_sub_pd(old, __mmask8((movingB >> (8 * j)) & 0xffu), old, g.v[j]));
        }
    }
}

// The divergence check's bits (PositionCheck) of 8 coordinates less their origin's, or-ed into acc.
FLEXFIT_AVX512 inline __m512i orBeyondBits8(__m512i acc, __m512d x, __m512d origin, __m512i carry) {
    const __m512i exponent = _mm512_and_si512(_mm512_castpd_si512(_mm512_sub_pd(x, origin)), _mm512_set1_epi64(0x7ff0000000000000LL));
    return _mm512_or_si512(acc, _mm512_add_epi64(exponent, carry));
}

// The check's origin coordinates for the 3 vectors of kLanes masses' 3 * kLanes doubles.
template <std::size_t kLanes>
std::array<double, 3 * kLanes> originPattern(const PositionCheck& check) {
    std::array<double, 3 * kLanes> at{};
    for (std::size_t k = 0; k < at.size(); ++k) at[k] = check.origin[int(k % 3)];
    return at;
}

// A whole model's integration pass with `check`: the first group alone and unchecked, the origin
// (mass 0's new position) fixed from it, its positions checked, then the other groups checked in
// the pass. pass(firstGroup, groups, check) integrates groups [firstGroup, groups).
template <class Pass>
std::size_t checkedWholePass(std::size_t width, std::size_t groups, PartState& state, PositionCheck* check, Pass pass) {
    std::size_t first = 0;
    if (check != nullptr && groups > 0) {
        pass(0, 1, nullptr);
        check->fixOrigin(state);
        check->add(state, 0, width);
        first = 1;
    }
    pass(first, groups, check);
    return width * groups;
}

// MassUpdate's step of one coordinate of 8 masses, as integrateMass takes it for each double:
// the body force ((m g - drag v) - k_a (x - rest), as MassUpdate::bodyForce), the integrator,
// then the restoration constraint. integrate512 and integrateListed512 share it.
struct CoordinateStep8 {
    const MassUpdate& p;
    __m512d h, invH, drag, anchor, constraint;
};
FLEXFIT_AVX512 inline CoordinateStep8 coordinateStep8(const MassUpdate& p) {
    return {p, _mm512_set1_pd(p.h), _mm512_set1_pd(p.invH), _mm512_set1_pd(p.drag), _mm512_set1_pd(p.anchorStiffness),
            _mm512_set1_pd(p.constraint)};
}
// m: the masses, hm: h over them, g: gravity's coordinate; xo, vo, fo, r: position, velocity,
// force and rest (r unread unless anchored or constrained). The new position and velocity.
FLEXFIT_AVX512 inline void stepCoordinate8(const CoordinateStep8& s, __m512d m, __m512d hm, __m512d g, __m512d xo, __m512d vo,
                                           __m512d fo, __m512d r, __m512d& xn, __m512d& vn) {
    __m512d body = _mm512_sub_pd(_mm512_mul_pd(m, g), _mm512_mul_pd(s.drag, vo));
    if (s.p.anchorStiffness != 0.0) body = _mm512_sub_pd(body, _mm512_mul_pd(s.anchor, _mm512_sub_pd(xo, r)));
    const __m512d total = _mm512_add_pd(fo, body);
    if (s.p.semiImplicit) {
        vn = _mm512_add_pd(vo, _mm512_mul_pd(hm, total));
        xn = _mm512_add_pd(xo, _mm512_mul_pd(s.h, vn));
    } else {
        xn = _mm512_add_pd(xo, _mm512_mul_pd(s.h, vo));
        vn = _mm512_add_pd(vo, _mm512_mul_pd(hm, total));
    }
    if (s.p.constraint > 0.0) {
        const __m512d correction = _mm512_mul_pd(s.constraint, _mm512_sub_pd(r, xn));
        xn = _mm512_add_pd(xn, correction);
        vn = _mm512_add_pd(vn, _mm512_mul_pd(s.invH, correction));
    }
}

// Groups firstGroup.. of 8 masses: group g starts at 8 octets[g], or at 8 g without a list. A
// check must have its origin fixed (checkedWholePass).
FLEXFIT_AVX512 void integrate512(const PartModel& model, const MassUpdate& p, PartState& state, const Index* octets,
                                  std::size_t firstGroup, std::size_t groups, const std::uint16_t* held = nullptr,
                                  PositionCheck* check = nullptr) {
    double* x = state.positions.data()->data();
    double* v = state.velocities.data()->data();
    double* f = state.forces.data()->data();
    const double* rest = model.restPositions.data()->data();
    alignas(64) double gravity[24];
    for (int j = 0; j < 24; ++j) gravity[j] = p.gravity[j % 3];
    const CoordinateStep8 step = coordinateStep8(p);
    const bool readsRest = p.readsRest();
    __m512d origin[3] = {};
    if (check != nullptr) {
        const auto at = originPattern<8>(*check);
        for (int j = 0; j < 3; ++j) origin[j] = _mm512_loadu_pd(at.data() + 8 * j);
    }
    __m512i beyond = _mm512_setzero_si512();
    const __m512i carry = _mm512_set1_epi64(check != nullptr ? std::int64_t(check->carry) : 0);
    for (std::size_t g = firstGroup; g < groups; ++g) {
        const std::size_t i = 8 * (octets != nullptr ? std::size_t(octets[g]) : g);
        const unsigned heldMasses = held != nullptr ? heldBits8(held + i) : 0u;
        if (heldMasses == 0xffu) {  // none moves: at rest already (stepSpringBlocks), only its forces zeroed
            for (int j = 0; j < 3; ++j) {
                const std::size_t o = 3 * i + 8 * std::size_t(j);
                if (check != nullptr) beyond = orBeyondBits8(beyond, _mm512_loadu_pd(x + o), origin[j], carry);
                _mm512_storeu_pd(f + o, _mm512_setzero_pd());
            }
            continue;
        }
        const __m512d mass = _mm512_loadu_pd(model.mass.data() + i);
        const __m512d hOverMass = _mm512_mul_pd(step.h, _mm512_loadu_pd(model.inverseMass.data() + i));
        const std::uint32_t heldLanes = kSpread3[heldMasses];
        for (int j = 0; j < 3; ++j) {
            const std::size_t o = 3 * i + 8 * std::size_t(j);
            const __m512d m = spread8(mass, j), hm = spread8(hOverMass, j);
            const __m512d xo = _mm512_loadu_pd(x + o), vo = _mm512_loadu_pd(v + o);
            const __m512d r = readsRest ? _mm512_loadu_pd(rest + o) : _mm512_setzero_pd();
            __m512d xn, vn;
            stepCoordinate8(step, m, hm, _mm512_load_pd(gravity + 8 * j), xo, vo, _mm512_loadu_pd(f + o), r, xn, vn);
            if (heldLanes != 0) {  // masses no zone covers: back to rest, as holdAtRest puts them
                const auto atRest = __mmask8((heldLanes >> (8 * j)) & 0xffu);
                xn = _mm512_mask_loadu_pd(xn, atRest, rest + o);
                vn = _mm512_mask_mov_pd(vn, atRest, _mm512_setzero_pd());
            }
            if (check != nullptr) beyond = orBeyondBits8(beyond, xn, origin[j], carry);
            _mm512_storeu_pd(x + o, xn);
            _mm512_storeu_pd(v + o, vn);
            _mm512_storeu_pd(f + o, _mm512_setzero_pd());
        }
    }
    if (check != nullptr) check->bits |= std::uint64_t(_mm512_reduce_or_epi64(beyond));
}

// A mass's x y z as one vector, lane 3 zero: masked, as the last mass has nothing after it.
FLEXFIT_AVX2 inline __m256d loadMass(const double* p) {
    return _mm256_maskload_pd(p, _mm256_setr_epi64x(-1, -1, -1, 0));
}

// A spring's first end's x y z as one vector, lane 3 the next mass's x (which the transposes
// drop): unmasked, as a first end always has a mass after it (springA < springB).
FLEXFIT_AVX2 inline __m256d loadFirstEnd(const double* p) { return _mm256_loadu_pd(p); }

// Listed springs 8 at a time (the AVX2 kernel's method, below, in 8 lanes): the 8 springs'
// (x y z _) rows paired into 4 vectors as (0 2) (1 3) (4 6) (5 7), whose in-lane unpacks and
// 128-bit shuffles give x, y, z in lane order 0..7. On this machine 8 % faster than 4 lanes.
FLEXFIT_AVX512 inline __m512d pair(__m256d low, __m256d high) {
    return _mm512_insertf64x4(_mm512_castpd256_pd512(low), high, 1);
}

FLEXFIT_AVX512 inline void transposeRows8(const __m256d r[8], __m512d& x, __m512d& y, __m512d& z) {
    const __m512d r02 = pair(r[0], r[2]), r13 = pair(r[1], r[3]), r46 = pair(r[4], r[6]), r57 = pair(r[5], r[7]);
    const __m512d xz0123 = _mm512_unpacklo_pd(r02, r13), y0123 = _mm512_unpackhi_pd(r02, r13);
    const __m512d xz4567 = _mm512_unpacklo_pd(r46, r57), y4567 = _mm512_unpackhi_pd(r46, r57);
    x = _mm512_shuffle_f64x2(xz0123, xz4567, 0x88);
    y = _mm512_shuffle_f64x2(y0123, y4567, 0x88);
    z = _mm512_shuffle_f64x2(xz0123, xz4567, 0xDD);
}

// values[i .. i + count), the lanes from `count` on repeating values[i + count - 1].
FLEXFIT_AVX512 inline __m512d lanesAt8(const std::vector<double>& values, std::size_t i, std::size_t count) {
    if (count == 8) return _mm512_loadu_pd(values.data() + i);
    return _mm512_mask_loadu_pd(_mm512_set1_pd(values[i + count - 1]), __mmask8((1u << count) - 1), values.data() + i);
}

// Forces on the first ends of springs [first, first + n) of the list into gx, gy, gz (from 0),
// in groups of 8; a last group of fewer repeats its last spring in the lanes past the list.
FLEXFIT_AVX512 void listedForces512(const SpringList& springs, std::size_t first, std::size_t n, const double* x,
                                    const double* v, double* gx, double* gy, double* gz) {
    for (std::size_t k = 0; k < n; k += 8) {
        const std::size_t i = first + k, count = std::min<std::size_t>(8, n - k);
        __m256d d[8], w[8];
        for (std::size_t l = 0; l < 8; ++l) {
            const std::size_t e = i + std::min(l, count - 1);
            const std::size_t a = 3 * std::size_t(springs.springA[e]), b = 3 * std::size_t(springs.springB[e]);
            d[l] = _mm256_sub_pd(loadFirstEnd(x + a), loadMass(x + b));
            w[l] = _mm256_sub_pd(loadFirstEnd(v + a), loadMass(v + b));
        }
        __m512d dx, dy, dz, wx, wy, wz;
        transposeRows8(d, dx, dy, dz);
        transposeRows8(w, wx, wy, wz);
        const __m512d r2 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)), _mm512_mul_pd(dz, dz));
        const __m512d dot = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(wx, dx), _mm512_mul_pd(wy, dy)), _mm512_mul_pd(wz, dz));
        const __m512d s = springScale8(r2, dot, lanesAt8(springs.stiffness, i, count), lanesAt8(springs.damping, i, count),
                                       lanesAt8(springs.restLength, i, count));
        _mm512_storeu_pd(gx + k, _mm512_mul_pd(s, dx));
        _mm512_storeu_pd(gy + k, _mm512_mul_pd(s, dy));
        _mm512_storeu_pd(gz + k, _mm512_mul_pd(s, dz));
    }
}

// Listed masses 8 at a time (the region's loose masses): each mass's x y z rows turned to lanes
// (transposeRows8), integrated coordinate by coordinate as integrate512 integrates each double,
// and written back mass by mass; a last group of fewer repeats its last mass (the same values
// written twice). The same bits as integrateMass. With `check` (its origin fixed), the new
// positions' beyond-bits or-ed into it.
FLEXFIT_AVX512 void integrateListed512(const PartModel& model, const MassUpdate& p, std::span<const Index> masses,
                                        PartState& state, PositionCheck* check) {
    double* x = state.positions.data()->data();
    double* v = state.velocities.data()->data();
    double* f = state.forces.data()->data();
    const double* rest = model.restPositions.data()->data();
    const CoordinateStep8 step = coordinateStep8(p);
    const bool readsRest = p.readsRest();
    const __m512i carry = _mm512_set1_epi64(check != nullptr ? std::int64_t(check->carry) : 0);
    __m512i beyond = _mm512_setzero_si512();
    for (std::size_t k = 0; k < masses.size(); k += 8) {
        const std::size_t count = std::min<std::size_t>(8, masses.size() - k);
        std::size_t at[8];
        __m256d xr[8], vr[8], fr[8], rr[8];
        alignas(64) double massLanes[8], inverseLanes[8];
        for (std::size_t l = 0; l < 8; ++l) {
            const std::size_t m = masses[k + std::min(l, count - 1)];
            at[l] = 3 * m;
            xr[l] = loadMass(x + at[l]);
            vr[l] = loadMass(v + at[l]);
            fr[l] = loadMass(f + at[l]);
            rr[l] = readsRest ? loadMass(rest + at[l]) : _mm256_setzero_pd();
            massLanes[l] = model.mass[m];
            inverseLanes[l] = model.inverseMass[m];
        }
        __m512d xo[3], vo[3], fo[3], r[3];
        transposeRows8(xr, xo[0], xo[1], xo[2]);
        transposeRows8(vr, vo[0], vo[1], vo[2]);
        transposeRows8(fr, fo[0], fo[1], fo[2]);
        transposeRows8(rr, r[0], r[1], r[2]);
        const __m512d mass = _mm512_load_pd(massLanes), hm = _mm512_mul_pd(step.h, _mm512_load_pd(inverseLanes));
        alignas(64) double xn[3][8], vn[3][8];
        for (int j = 0; j < 3; ++j) {
            __m512d xj, vj;
            stepCoordinate8(step, mass, hm, _mm512_set1_pd(p.gravity[j]), xo[j], vo[j], fo[j], r[j], xj, vj);
            if (check != nullptr) beyond = orBeyondBits8(beyond, xj, _mm512_set1_pd(check->origin[j]), carry);
            _mm512_store_pd(xn[j], xj);
            _mm512_store_pd(vn[j], vj);
        }
        for (std::size_t l = 0; l < count; ++l) {
            double* xm = x + at[l];
            double* vm = v + at[l];
            double* fm = f + at[l];
            for (int j = 0; j < 3; ++j) xm[j] = xn[j][l], vm[j] = vn[j][l], fm[j] = 0.0;
        }
    }
    if (check != nullptr) check->bits |= std::uint64_t(_mm512_reduce_or_epi64(beyond));
}

// ---------------------------------------------------------------- AVX2: a block as two halves

struct Lanes4 {
    __m256d x, y, z;
};

// 4 masses' 12 doubles (a = x0 y0 z0 x1, b = y1 z1 x2 y2, c = z2 x3 y3 z3) as 4 lanes each.
FLEXFIT_AVX2 inline Lanes4 deinterleave4(__m256d a, __m256d b, __m256d c) {
    const __m256d p = _mm256_permute2f128_pd(a, c, 0x30);  // x0 y0 y3 z3
    const __m256d q = _mm256_permute2f128_pd(a, c, 0x21);  // z0 x1 z2 x3
    return {_mm256_blend_pd(_mm256_blend_pd(p, q, 0b1010), b, 0b0100),
            _mm256_permute_pd(_mm256_blend_pd(p, b, 0b1001), 0b0101),
            _mm256_blend_pd(_mm256_blend_pd(q, b, 0b0010), p, 0b1000)};
}

FLEXFIT_AVX2 inline void interleave4(const Lanes4& g, __m256d out[3]) {
    const __m256d ys = _mm256_permute_pd(g.y, 0b0101);                                    // y1 y0 y3 y2
    const __m256d p = _mm256_blend_pd(_mm256_blend_pd(g.x, ys, 0b0110), g.z, 0b1000);     // x0 y0 y3 z3
    const __m256d q = _mm256_blend_pd(g.z, g.x, 0b1010);                                  // z0 x1 z2 x3
    out[1] = _mm256_blend_pd(_mm256_blend_pd(ys, g.z, 0b0010), g.x, 0b0100);             // y1 z1 x2 y2
    out[0] = _mm256_permute2f128_pd(p, q, 0x20);
    out[2] = _mm256_permute2f128_pd(q, p, 0x31);
}

FLEXFIT_AVX2 inline Lanes4 difference4(const double* p, const double* q) {
    return deinterleave4(_mm256_sub_pd(_mm256_loadu_pd(p), _mm256_loadu_pd(q)),
                         _mm256_sub_pd(_mm256_loadu_pd(p + 4), _mm256_loadu_pd(q + 4)),
                         _mm256_sub_pd(_mm256_loadu_pd(p + 8), _mm256_loadu_pd(q + 8)));
}

FLEXFIT_AVX2 inline Lanes4 springForces4(const Lanes4& d, const Lanes4& w, __m256d k, __m256d c, __m256d restLength) {
    const __m256d zero = _mm256_setzero_pd();
    const __m256d r2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d.x, d.x), _mm256_mul_pd(d.y, d.y)),
                                     _mm256_mul_pd(d.z, d.z));
    const __m256d length = _mm256_sqrt_pd(r2);
    const __m256d positive = _mm256_cmp_pd(length, zero, _CMP_GT_OQ);  // no 1/0: it would raise FE_DIVBYZERO
    const __m256d inverse = _mm256_and_pd(
        positive, _mm256_div_pd(_mm256_set1_pd(1.0), _mm256_blendv_pd(_mm256_set1_pd(1.0), length, positive)));
    const __m256d dot = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(w.x, d.x), _mm256_mul_pd(w.y, d.y)),
                                      _mm256_mul_pd(w.z, d.z));
    const __m256d magnitude =
        _mm256_add_pd(_mm256_mul_pd(k, _mm256_sub_pd(length, restLength)), _mm256_mul_pd(_mm256_mul_pd(c, dot), inverse));
    const __m256d s = _mm256_xor_pd(_mm256_mul_pd(magnitude, inverse), _mm256_set1_pd(-0.0));
    return {_mm256_mul_pd(s, d.x), _mm256_mul_pd(s, d.y), _mm256_mul_pd(s, d.z)};
}

// [a1 a2 a3 b0]: the 4 doubles one mass (3 doubles) earlier in the flat sequence ... a, b.
FLEXFIT_AVX2 inline __m256d shiftOneMass4(__m256d a, __m256d b) {
    return _mm256_shuffle_pd(a, _mm256_permute2f128_pd(a, b, 0x21), 0b0101);
}

// The mass after a row block's 8 (its last second end): f -= g_7, lanes 1-3 of `lastVector`.
FLEXFIT_AVX2 inline void subtractLastSpring4(__m256d lastVector, double* f) {
    alignas(32) double last[4];
    _mm256_store_pd(last, lastVector);
    for (int c = 0; c < 3; ++c) f[c] -= last[1 + c];
}

// Block q's forces g_i on its first ends as the 24 doubles of 8 masses, in g[0..5].
FLEXFIT_AVX2 inline void blockSpringForces256(const SpringBlocks& blocks, std::size_t q, const double* x, const double* v,
                                              __m256d g[6]) {
    const std::size_t a = 3 * std::size_t(blocks.first[q]), b = a + 3 * std::size_t(blocks.offset[q]);
    for (std::size_t half = 0; half < 2; ++half) {
        const std::size_t o = 12 * half, lane = W * q + 4 * half;
        const Lanes4 forces = springForces4(difference4(x + a + o, x + b + o), difference4(v + a + o, v + b + o),
                                            _mm256_loadu_pd(blocks.stiffness.data() + lane),
                                            _mm256_loadu_pd(blocks.damping.data() + lane),
                                            _mm256_loadu_pd(blocks.restLength.data() + lane));
        interleave4(forces, g + 3 * half);
    }
}

// A row block's forces on its first 8 masses, unmasked: f[a0 + i] += g_i - g_(i-1), where
// `previous` holds g_(-1) in lanes 1-3 (the previous row block's g_7, or zero). The mass after
// the 8 (g_7's second end) is left to the caller.
FLEXFIT_AVX2 inline void addRowForces256(const __m256d g[6], __m256d previous, double* fa) {
    for (int j = 0; j < 6; ++j) {
        const __m256d shifted = shiftOneMass4(previous, g[j]);
        _mm256_storeu_pd(fa + 4 * j, _mm256_sub_pd(_mm256_add_pd(_mm256_loadu_pd(fa + 4 * j), g[j]), shifted));
        previous = g[j];
    }
}

// Another block's forces, unmasked: its 8 first ends += g, then its 8 second ends -= g (after the
// first ends' stores: the ranges overlap when the offset is below 8).
FLEXFIT_AVX2 inline void addBlockForces256(const __m256d g[6], double* fa, double* fb) {
    for (int j = 0; j < 6; ++j) _mm256_storeu_pd(fa + 4 * j, _mm256_add_pd(_mm256_loadu_pd(fa + 4 * j), g[j]));
    for (int j = 0; j < 6; ++j) _mm256_storeu_pd(fb + 4 * j, _mm256_sub_pd(_mm256_loadu_pd(fb + 4 * j), g[j]));
}

FLEXFIT_AVX2 void blockForces256(const SpringBlocks& blocks, const double* x, const double* v, double* f) {
    __m256d carry = _mm256_setzero_pd();  // previous row block's last vector (g_7 in lanes 1-3)
    for (std::size_t q = 0; q < blocks.blockCount(); ++q) {
        const std::size_t a = 3 * std::size_t(blocks.first[q]);
        __m256d g[6];  // the block's 24 doubles
        blockSpringForces256(blocks, q, x, v, g);
        double* fa = f + a;
        if (blocks.offset[q] == 1) {
            addRowForces256(g, blocks.continuesRow(q) ? carry : _mm256_setzero_pd(), fa);
            carry = g[5];
            if (q + 1 == blocks.blockCount() || !blocks.continuesRow(q + 1)) subtractLastSpring4(g[5], fa + 24);
            continue;
        }
        addBlockForces256(g, fa, f + a + 3 * std::size_t(blocks.offset[q]));
    }
}

// All-ones 64-bit lanes for the bits of k (bit l: lane l), for the 16 values of k.
alignas(32) constexpr std::array<std::array<std::int64_t, 4>, 16> kLaneMasks4 = [] {
    std::array<std::array<std::int64_t, 4>, 16> table{};
    for (unsigned k = 0; k < 16; ++k)
        for (unsigned l = 0; l < 4; ++l) table[k][l] = (k >> l) & 1u ? -1 : 0;
    return table;
}();

// Vector j (doubles 4j..4j+3 of 8 masses) of the lane mask whose bits kSpread3 gives.
FLEXFIT_AVX2 inline __m256d laneMask4(std::uint32_t lanes, int j) {
    return _mm256_load_pd(reinterpret_cast<const double*>(kLaneMasks4[(lanes >> (4 * j)) & 0xfu].data()));
}

// regionRowBlock (AVX-512) with 4-double vectors; when all 9 masses move, the full kernel's
// unmasked sums (the same bits: a blend under an all-ones mask is the sum, and lane 0's
// subtraction of the zero `previous` leaves old + g as it is).
FLEXFIT_AVX2 inline void regionRowBlock256(const __m256d g[6], std::size_t a0, const std::uint16_t* cover, double* f) {
    const unsigned firstEnds = movingBits8(cover + a0);
    const unsigned secondEnds = movingBits8(cover + a0 + 1);  // mass a0 + 1 + i is lane i's second end
    double* fa = f + 3 * a0;
    if ((firstEnds & secondEnds) == 0xffu) {  // all 9 masses move: the full kernel's sums, unmasked
        addRowForces256(g, _mm256_setzero_pd(), fa);
        subtractLastSpring4(g[5], fa + 24);
        return;
    }
    __m256d previous = _mm256_setzero_pd();
    const std::uint32_t movingA = kSpread3[firstEnds];
    const std::uint32_t movingB = kSpread3[(secondEnds << 1) & 0xffu];  // as masses a0 + i, lanes 1..7
    for (int j = 0; j < 6; ++j) {
        const __m256d old = _mm256_loadu_pd(fa + 4 * j);
        const __m256d added = _mm256_blendv_pd(old, _mm256_add_pd(old, g[j]), laneMask4(movingA, j));
        const __m256d shifted = shiftOneMass4(previous, g[j]);
        _mm256_storeu_pd(fa + 4 * j, _mm256_blendv_pd(added, _mm256_sub_pd(added, shifted), laneMask4(movingB, j)));
        previous = g[j];
    }
    if ((secondEnds & 0x80u) != 0) subtractLastSpring4(g[5], fa + 24);  // mass a0 + 8
}

// The AVX-512 region kernel's method (regionBlocks512) with 4-double vectors: each sum is made
// in every lane and kept only where the mass moves (a blend), so a lane equals the scalar
// conditional sum; row blocks update their 9 masses in registers. A block whose ends all move
// (the inside of a large zone) skips the masks: blends cost AVX2 a quarter more per block (the
// AVX-512 kernel's masks are free and it has no such path).
FLEXFIT_AVX2 void regionBlocks256(const SpringBlocks& blocks, std::span<const Index> vectorBlocks, const std::uint16_t* cover,
                                  const double* x, const double* v, double* f) {
    for (const Index q : vectorBlocks) {
        __m256d g[6];
        blockSpringForces256(blocks, q, x, v, g);
        if (blocks.offset[q] == 1) {
            regionRowBlock256(g, blocks.first[q], cover, f);
            continue;
        }
        const std::size_t a0 = blocks.first[q], b0 = a0 + blocks.offset[q];
        const unsigned firstEnds = movingBits8(cover + a0), secondEnds = movingBits8(cover + b0);
        double* fa = f + 3 * a0;
        double* fb = f + 3 * b0;  // after the first ends' stores: the ranges overlap when offset < 8
        if ((firstEnds & secondEnds) == 0xffu) {  // all 16 ends move: the full kernel's sums, unmasked
            addBlockForces256(g, fa, fb);
            continue;
        }
        const std::uint32_t movingA = kSpread3[firstEnds], movingB = kSpread3[secondEnds];
        for (int j = 0; j < 6; ++j) {
            const __m256d old = _mm256_loadu_pd(fa + 4 * j);
            _mm256_storeu_pd(fa + 4 * j, _mm256_blendv_pd(old, _mm256_add_pd(old, g[j]), laneMask4(movingA, j)));
        }
        for (int j = 0; j < 6; ++j) {
            const __m256d old = _mm256_loadu_pd(fb + 4 * j);
            _mm256_storeu_pd(fb + 4 * j, _mm256_blendv_pd(old, _mm256_sub_pd(old, g[j]), laneMask4(movingB, j)));
        }
    }
}

// ---------------------------------------------------------------- AVX2: listed springs

// Springs in no block (any vertex order): each end's x y z loaded as one vector, the 4 springs'
// differences transposed to lanes, the forces stored per spring; then added to the masses one
// spring after another in list order, as the scalar pass does. Gathers (8 loads per vector, 12
// vectors per 8 springs) cost more than these 16 vector loads and 14 shuffles per 4 springs.

// Rows r[l] = (x y z _) of 4 springs as lanes x, y, z.
FLEXFIT_AVX2 inline Lanes4 transposeRows4(const __m256d r[4]) {
    const __m256d xz01 = _mm256_unpacklo_pd(r[0], r[1]), y01 = _mm256_unpackhi_pd(r[0], r[1]);
    const __m256d xz23 = _mm256_unpacklo_pd(r[2], r[3]), y23 = _mm256_unpackhi_pd(r[2], r[3]);
    return {_mm256_permute2f128_pd(xz01, xz23, 0x20), _mm256_permute2f128_pd(y01, y23, 0x20),
            _mm256_permute2f128_pd(xz01, xz23, 0x31)};
}

// values[i .. i + count), the lanes from `count` on repeating values[i + count - 1].
FLEXFIT_AVX2 inline __m256d lanesAt4(const std::vector<double>& values, std::size_t i, std::size_t count) {
    if (count == 4) return _mm256_loadu_pd(values.data() + i);
    const double* p = values.data() + i;
    return _mm256_setr_pd(p[0], p[std::min<std::size_t>(1, count - 1)], p[std::min<std::size_t>(2, count - 1)], p[count - 1]);
}

// Forces on the first ends of springs [first, first + n) into gx, gy, gz (from 0), 4 at a time;
// a last group of fewer repeats its last spring in the lanes past the list.
FLEXFIT_AVX2 void listedForces256(const SpringList& springs, std::size_t first, std::size_t n, const double* x,
                                  const double* v, double* gx, double* gy, double* gz) {
    for (std::size_t k = 0; k < n; k += 4) {
        const std::size_t i = first + k, count = std::min<std::size_t>(4, n - k);
        __m256d d[4], w[4];
        for (std::size_t l = 0; l < 4; ++l) {
            const std::size_t e = i + std::min(l, count - 1);
            const std::size_t a = 3 * std::size_t(springs.springA[e]), b = 3 * std::size_t(springs.springB[e]);
            d[l] = _mm256_sub_pd(loadFirstEnd(x + a), loadMass(x + b));
            w[l] = _mm256_sub_pd(loadFirstEnd(v + a), loadMass(v + b));
        }
        const Lanes4 g = springForces4(transposeRows4(d), transposeRows4(w), lanesAt4(springs.stiffness, i, count),
                                       lanesAt4(springs.damping, i, count), lanesAt4(springs.restLength, i, count));
        _mm256_storeu_pd(gx + k, g.x);
        _mm256_storeu_pd(gy + k, g.y);
        _mm256_storeu_pd(gz + k, g.z);
    }
}

// g_i on the first end, -g_i on the second of listed springs [first, first + n), in list
// order. The first end's force stays in registers while consecutive springs share it (the
// remainder is sorted by first end): the same additions in the same order, without a store and
// reload between them. Safe because a spring's second end is never its first.
inline void addListedForces(const SpringList& springs, std::size_t first, std::size_t n, const double* gx,
                            const double* gy, const double* gz, double* f) {
    const Index* springA = springs.springA.data() + first;
    const Index* springB = springs.springB.data() + first;
    std::size_t i = 0;
    while (i < n) {
        // The run of listed springs that share the first end a, as a loop of known length.
        const Index a = springA[i];
        std::size_t end = i + 1;
        while (end < n && springA[end] == a) ++end;
        double* fa = f + 3 * std::size_t(a);
        double hx = fa[0], hy = fa[1], hz = fa[2];
        for (; i < end; ++i) {
            hx += gx[i], hy += gy[i], hz += gz[i];
            double* fb = f + 3 * std::size_t(springB[i]);
            fb[0] -= gx[i], fb[1] -= gy[i], fb[2] -= gz[i];
        }
        fa[0] = hx, fa[1] = hy, fa[2] = hz;
    }
}

// The same with a cover: only to the ends whose count is non-zero. (Selecting a scratch row
// for an end that does not move, instead of branching, measured no faster.)
inline void addCoveredListedForces(const SpringList& springs, std::size_t first, std::size_t n, const std::uint16_t* cover,
                                   const double* gx, const double* gy, const double* gz, double* f) {
    const Index* springA = springs.springA.data() + first;
    const Index* springB = springs.springB.data() + first;
    for (std::size_t i = 0; i < n; ++i) {
        const Index a = springA[i], b = springB[i];
        if (cover[a] != 0) {
            double* fa = f + 3 * std::size_t(a);
            fa[0] += gx[i], fa[1] += gy[i], fa[2] += gz[i];
        }
        if (cover[b] != 0) {
            double* fb = f + 3 * std::size_t(b);
            fb[0] -= gx[i], fb[1] -= gy[i], fb[2] -= gz[i];
        }
    }
}

// Forces of springs [first, first + n) into gx, gy, gz (n up to kListChunk).
using ListedForces = void (*)(const SpringList& springs, std::size_t first, std::size_t n, const double* x,
                              const double* v, double* gx, double* gy, double* gz);

// The listed springs' forces added in list order, in chunks: to both ends, or with a cover only
// to the ends whose count is non-zero.
void listedSpringForcesBy(ListedForces forces, const SpringList& springs, const std::uint16_t* cover, const double* x,
                          const double* v, double* f) {
    alignas(64) double gx[kListChunk], gy[kListChunk], gz[kListChunk];
    for (std::size_t start = 0; start < springs.size(); start += kListChunk) {
        const std::size_t count = std::min(kListChunk, springs.size() - start);
        forces(springs, start, count, x, v, gx, gy, gz);
        if (cover == nullptr) addListedForces(springs, start, count, gx, gy, gz, f);
        else addCoveredListedForces(springs, start, count, cover, gx, gy, gz, f);
    }
}

FLEXFIT_AVX2 inline __m256d spread4(__m256d values, int j) {
    switch (j) {  // lane l of vector j is mass (4j+l)/3
        case 0: return _mm256_permute4x64_pd(values, 0x40);  // 0 0 0 1
        case 1: return _mm256_permute4x64_pd(values, 0xA5);  // 1 1 2 2
        default: return _mm256_permute4x64_pd(values, 0xFE);  // 2 3 3 3
    }
}

FLEXFIT_AVX2 inline __m256i orBeyondBits4(__m256i acc, __m256d x, __m256d origin, __m256i carry) {
    const __m256i exponent = _mm256_and_si256(_mm256_castpd_si256(_mm256_sub_pd(x, origin)), _mm256_set1_epi64x(0x7ff0000000000000LL));
    return _mm256_or_si256(acc, _mm256_add_epi64(exponent, carry));
}

// Groups firstGroup.. of 4 masses: group g starts at 4 g, or with an octet list at
// 8 octets[g / 2] + 4 (g % 2). With `held`, the masses whose count is 0 end at rest (as
// holdAtRest puts them: a selection). A check must have its origin fixed (checkedWholePass).
FLEXFIT_AVX2 void integrate256(const PartModel& model, const MassUpdate& p, PartState& state, const Index* octets,
                                std::size_t firstGroup, std::size_t groups, const std::uint16_t* held = nullptr,
                                PositionCheck* check = nullptr) {
    double* x = state.positions.data()->data();
    double* v = state.velocities.data()->data();
    double* f = state.forces.data()->data();
    const double* rest = model.restPositions.data()->data();
    alignas(32) double gravity[12];
    for (int j = 0; j < 12; ++j) gravity[j] = p.gravity[j % 3];
    const __m256d h = _mm256_set1_pd(p.h), invH = _mm256_set1_pd(p.invH), drag = _mm256_set1_pd(p.drag);
    const __m256d anchor = _mm256_set1_pd(p.anchorStiffness), constraint = _mm256_set1_pd(p.constraint);
    const bool anchored = p.anchorStiffness != 0.0, readsRest = p.readsRest();
    __m256d origin[3] = {};
    if (check != nullptr) {
        const auto at = originPattern<4>(*check);
        for (int j = 0; j < 3; ++j) origin[j] = _mm256_loadu_pd(at.data() + 4 * j);
    }
    __m256i beyond = _mm256_setzero_si256();
    const __m256i carry = _mm256_set1_epi64x(check != nullptr ? std::int64_t(check->carry) : 0);
    for (std::size_t g = firstGroup; g < groups; ++g) {
        const std::size_t i = octets != nullptr ? 8 * std::size_t(octets[g / 2]) + 4 * (g % 2) : 4 * g;
        const unsigned heldMasses = held != nullptr ? heldBits4(held + i) : 0u;
        if (heldMasses == 0xfu) {  // none moves: at rest already (stepSpringBlocks), only its forces zeroed
            for (int j = 0; j < 3; ++j) {
                const std::size_t o = 3 * i + 4 * std::size_t(j);
                if (check != nullptr) beyond = orBeyondBits4(beyond, _mm256_loadu_pd(x + o), origin[j], carry);
                _mm256_storeu_pd(f + o, _mm256_setzero_pd());
            }
            continue;
        }
        const __m256d mass = _mm256_loadu_pd(model.mass.data() + i);
        const __m256d hOverMass = _mm256_mul_pd(h, _mm256_loadu_pd(model.inverseMass.data() + i));
        const std::uint32_t heldLanes = kSpread3[heldMasses];
        for (int j = 0; j < 3; ++j) {
            const std::size_t o = 3 * i + 4 * std::size_t(j);
            const __m256d m = spread4(mass, j), hm = spread4(hOverMass, j);
            const __m256d xo = _mm256_loadu_pd(x + o), vo = _mm256_loadu_pd(v + o);
            const __m256d r = readsRest ? _mm256_loadu_pd(rest + o) : _mm256_setzero_pd();
            __m256d body = _mm256_sub_pd(_mm256_mul_pd(m, _mm256_load_pd(gravity + 4 * j)), _mm256_mul_pd(drag, vo));
            if (anchored) body = _mm256_sub_pd(body, _mm256_mul_pd(anchor, _mm256_sub_pd(xo, r)));
            const __m256d total = _mm256_add_pd(_mm256_loadu_pd(f + o), body);
            __m256d xn, vn;
            if (p.semiImplicit) {
                vn = _mm256_add_pd(vo, _mm256_mul_pd(hm, total));
                xn = _mm256_add_pd(xo, _mm256_mul_pd(h, vn));
            } else {
                xn = _mm256_add_pd(xo, _mm256_mul_pd(h, vo));
                vn = _mm256_add_pd(vo, _mm256_mul_pd(hm, total));
            }
            if (p.constraint > 0.0) {
                const __m256d correction = _mm256_mul_pd(constraint, _mm256_sub_pd(r, xn));
                xn = _mm256_add_pd(xn, correction);
                vn = _mm256_add_pd(vn, _mm256_mul_pd(invH, correction));
            }
            if (heldLanes != 0) {  // masses no zone covers: back to rest
                const __m256d atRest = laneMask4(heldLanes, j);
                xn = _mm256_blendv_pd(xn, _mm256_loadu_pd(rest + o), atRest);
                vn = _mm256_andnot_pd(atRest, vn);
            }
            if (check != nullptr) beyond = orBeyondBits4(beyond, xn, origin[j], carry);
            _mm256_storeu_pd(x + o, xn);
            _mm256_storeu_pd(v + o, vn);
            _mm256_storeu_pd(f + o, _mm256_setzero_pd());
        }
    }
    if (check != nullptr) {
        alignas(32) std::uint64_t lanes[4];
        _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), beyond);
        check->bits |= lanes[0] | lanes[1] | lanes[2] | lanes[3];
    }
}

}  // namespace

void blockForcesAvx2(const SpringBlocks& blocks, const double* x, const double* v, double* f) {
    blockForces256(blocks, x, v, f);
}
void blockForcesAvx512(const SpringBlocks& blocks, const double* x, const double* v, double* f) {
    blockForces512(blocks, x, v, f);
}
void listedSpringForcesAvx2(const SpringList& springs, const std::uint16_t* cover, const double* x, const double* v,
                            double* f) {
    listedSpringForcesBy(listedForces256, springs, cover, x, v, f);
}
void listedSpringForcesAvx512(const SpringList& springs, const std::uint16_t* cover, const double* x, const double* v,
                              double* f) {
    listedSpringForcesBy(listedForces512, springs, cover, x, v, f);
}
std::size_t integrateAvx2(const PartModel& model, const MassUpdate& update, PartState& state, const std::uint16_t* held,
                          PositionCheck* check) {
    return checkedWholePass(4, model.massCount() / 4, state, check, [&](std::size_t first, std::size_t groups, PositionCheck* c) {
        integrate256(model, update, state, nullptr, first, groups, held, c);
    });
}
std::size_t integrateAvx512(const PartModel& model, const MassUpdate& update, PartState& state, const std::uint16_t* held,
                            PositionCheck* check) {
    return checkedWholePass(8, model.massCount() / 8, state, check, [&](std::size_t first, std::size_t groups, PositionCheck* c) {
        integrate512(model, update, state, nullptr, first, groups, held, c);
    });
}
void integrateListedAvx512(const PartModel& model, const MassUpdate& update, std::span<const Index> masses,
                           PartState& state, PositionCheck* check) {
    integrateListed512(model, update, masses, state, check);
}
void integrateOctetsAvx2(const PartModel& model, const MassUpdate& update, std::span<const Index> octets,
                         const std::uint16_t* held, PartState& state, PositionCheck* check) {
    integrate256(model, update, state, octets.data(), 0, 2 * octets.size(), held, check);
}
void integrateOctetsAvx512(const PartModel& model, const MassUpdate& update, std::span<const Index> octets,
                           const std::uint16_t* held, PartState& state, PositionCheck* check) {
    integrate512(model, update, state, octets.data(), 0, octets.size(), held, check);
}
void regionBlockForcesAvx2(const SpringBlocks& blocks, std::span<const Index> vectorBlocks, const std::uint16_t* cover,
                           const double* x, const double* v, double* f) {
    regionBlocks256(blocks, vectorBlocks, cover, x, v, f);
}
void regionBlockForcesAvx512(const SpringBlocks& blocks, std::span<const Index> vectorBlocks, const std::uint16_t* cover,
                             const double* x, const double* v, double* f) {
    regionBlocks512(blocks, vectorBlocks, cover, x, v, f);
}
std::size_t holdAtRestAvx512(const PartModel& model, const std::uint16_t* cover, PartState& state) {
    return holdAtRest512(model, cover, state);
}

}  // namespace flexfit::detail

#endif  // FLEXFIT_X86_KERNELS
