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
            if (q + 1 == blocks.blockCount() || !blocks.continuesRow(q + 1)) {
                alignas(64) double last[8];
                _mm512_store_pd(last, g.v[2]);
                for (int c = 0; c < 3; ++c) fa[24 + c] -= last[5 + c];
            }
            continue;
        }
        double* fb = fa + 3 * std::size_t(blocks.offset[q]);
        for (int j = 0; j < 3; ++j) _mm512_storeu_pd(fa + 8 * j, _mm512_add_pd(_mm512_loadu_pd(fa + 8 * j), g.v[j]));
        for (int j = 0; j < 3; ++j) _mm512_storeu_pd(fb + 8 * j, _mm512_sub_pd(_mm512_loadu_pd(fb + 8 * j), g.v[j]));
    }
}

// Remainder springs 8 at a time: ends gathered (they follow no pattern), forces in vectors, then
// added one spring after another in ascending order, as the scalar remainder pass does.
// Components x, y, z of p[a] - p[b] as 8 lanes each.
FLEXFIT_AVX512 inline Flat24 gatherDifference8(__m256i a, __m256i b, const double* p) {
    return {{_mm512_sub_pd(_mm512_i32gather_pd(a, p, 8), _mm512_i32gather_pd(b, p, 8)),
             _mm512_sub_pd(_mm512_i32gather_pd(a, p + 1, 8), _mm512_i32gather_pd(b, p + 1, 8)),
             _mm512_sub_pd(_mm512_i32gather_pd(a, p + 2, 8), _mm512_i32gather_pd(b, p + 2, 8))}};
}

FLEXFIT_AVX512 inline __m512d dot8(const Flat24& a, const Flat24& b) {
    return _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(a.v[0], b.v[0]), _mm512_mul_pd(a.v[1], b.v[1])),
                         _mm512_mul_pd(a.v[2], b.v[2]));
}

FLEXFIT_AVX512 std::size_t remainder512(const PartModel& model, const double* x, const double* v, double* f) {
    const std::vector<Index>& springs = model.springBlocks->remainder;
    if (3 * model.massCount() > std::size_t(INT32_MAX) || model.springCount() > std::size_t(INT32_MAX))
        return 0;  // gather offsets are int32: the scalar pass does them all
    const std::size_t n = springs.size() / 8 * 8;
    for (std::size_t i = 0; i < n; i += 8) {
        alignas(32) std::int32_t e[8], a[8], b[8];
        for (std::size_t l = 0; l < 8; ++l) {
            e[l] = std::int32_t(springs[i + l]);
            a[l] = std::int32_t(3 * model.springA[springs[i + l]]);
            b[l] = std::int32_t(3 * model.springB[springs[i + l]]);
        }
        const __m256i ve = _mm256_load_si256(reinterpret_cast<const __m256i*>(e));
        const __m256i va = _mm256_load_si256(reinterpret_cast<const __m256i*>(a));
        const __m256i vb = _mm256_load_si256(reinterpret_cast<const __m256i*>(b));
        const Flat24 d = gatherDifference8(va, vb, x), w = gatherDifference8(va, vb, v);
        const __m512d s = springScale8(dot8(d, d), dot8(w, d), _mm512_i32gather_pd(ve, model.stiffness.data(), 8),
                                       _mm512_i32gather_pd(ve, model.damping.data(), 8),
                                       _mm512_i32gather_pd(ve, model.restLength.data(), 8));
        alignas(64) double gx[8], gy[8], gz[8];
        _mm512_store_pd(gx, _mm512_mul_pd(s, d.v[0]));
        _mm512_store_pd(gy, _mm512_mul_pd(s, d.v[1]));
        _mm512_store_pd(gz, _mm512_mul_pd(s, d.v[2]));
        for (std::size_t l = 0; l < 8; ++l) {
            double* fa = f + a[l];
            double* fb = f + b[l];
            fa[0] += gx[l], fa[1] += gy[l], fa[2] += gz[l];
            fb[0] -= gx[l], fb[1] -= gy[l], fb[2] -= gz[l];
        }
    }
    return n;
}

// Bit 3i..3i+2 set for each bit i of an 8-bit mass mask: one mask bit per double of 8 masses.
constexpr std::array<std::uint32_t, 256> kSpread3 = [] {
    std::array<std::uint32_t, 256> table{};
    for (unsigned k = 0; k < 256; ++k)
        for (unsigned bit = 0; bit < 8; ++bit)
            if ((k >> bit) & 1u) table[k] |= 7u << (3 * bit);
    return table;
}();

// Bits of the masses cover[0..7] whose cover count is 0.
FLEXFIT_AVX512 inline unsigned heldBits8(const std::uint16_t* cover) {
    const __m128i zeroCount = _mm_cmpeq_epi16(_mm_loadu_si128(reinterpret_cast<const __m128i*>(cover)), _mm_setzero_si128());
    return unsigned(_mm_movemask_epi8(_mm_packs_epi16(zeroCount, _mm_setzero_si128())));
}

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

FLEXFIT_AVX512 void regionBlocks512(const SpringBlocks& blocks, std::span<const Index> fullBlocks, const std::uint16_t* cover,
                                    const double* x, const double* v, double* f) {
    for (const Index q : fullBlocks) {
        const Flat24 g = blockSpringForces(blocks, q, x, v);
        const std::size_t a0 = blocks.first[q], b0 = a0 + blocks.offset[q];
        const std::uint32_t movingA = kSpread3[~heldBits8(cover + a0) & 0xffu];
        const std::uint32_t movingB = kSpread3[~heldBits8(cover + b0) & 0xffu];
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

// Groups of 8 masses: group g starts at 8 octets[g], or at 8 g without a list.
FLEXFIT_AVX512 std::size_t integrate512(const PartModel& model, const MassUpdate& p, PartState& state,
                                        const Index* octets, std::size_t groups) {
    double* x = state.positions.data()->data();
    double* v = state.velocities.data()->data();
    double* f = state.forces.data()->data();
    const double* rest = model.restPositions.data()->data();
    alignas(64) double gravity[24];
    for (int j = 0; j < 24; ++j) gravity[j] = p.gravity[j % 3];
    const __m512d h = _mm512_set1_pd(p.h), invH = _mm512_set1_pd(p.invH), drag = _mm512_set1_pd(p.drag);
    const __m512d anchor = _mm512_set1_pd(p.anchorStiffness), constraint = _mm512_set1_pd(p.constraint);
    const bool anchored = p.anchorStiffness != 0.0, readsRest = p.readsRest();
    for (std::size_t g = 0; g < groups; ++g) {
        const std::size_t i = 8 * (octets != nullptr ? std::size_t(octets[g]) : g);
        const __m512d mass = _mm512_loadu_pd(model.mass.data() + i);
        const __m512d hOverMass = _mm512_mul_pd(h, _mm512_loadu_pd(model.inverseMass.data() + i));
        for (int j = 0; j < 3; ++j) {
            const std::size_t o = 3 * i + 8 * std::size_t(j);
            const __m512d m = spread8(mass, j), hm = spread8(hOverMass, j);
            const __m512d xo = _mm512_loadu_pd(x + o), vo = _mm512_loadu_pd(v + o);
            const __m512d r = readsRest ? _mm512_loadu_pd(rest + o) : _mm512_setzero_pd();
            // total = f + ((m g - drag v) - k_a (x - rest)), as MassUpdate::bodyForce
            __m512d body = _mm512_sub_pd(_mm512_mul_pd(m, _mm512_load_pd(gravity + 8 * j)), _mm512_mul_pd(drag, vo));
            if (anchored) body = _mm512_sub_pd(body, _mm512_mul_pd(anchor, _mm512_sub_pd(xo, r)));
            const __m512d total = _mm512_add_pd(_mm512_loadu_pd(f + o), body);
            __m512d xn, vn;
            if (p.semiImplicit) {
                vn = _mm512_add_pd(vo, _mm512_mul_pd(hm, total));
                xn = _mm512_add_pd(xo, _mm512_mul_pd(h, vn));
            } else {
                xn = _mm512_add_pd(xo, _mm512_mul_pd(h, vo));
                vn = _mm512_add_pd(vo, _mm512_mul_pd(hm, total));
            }
            if (p.constraint > 0.0) {
                const __m512d correction = _mm512_mul_pd(constraint, _mm512_sub_pd(r, xn));
                xn = _mm512_add_pd(xn, correction);
                vn = _mm512_add_pd(vn, _mm512_mul_pd(invH, correction));
            }
            _mm512_storeu_pd(x + o, xn);
            _mm512_storeu_pd(v + o, vn);
            _mm512_storeu_pd(f + o, _mm512_setzero_pd());
        }
    }
    return 8 * groups;
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

FLEXFIT_AVX2 inline Lanes4 springForces4(const Lanes4& d, const Lanes4& w, const double* k, const double* c,
                                         const double* restLength) {
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
        _mm256_add_pd(_mm256_mul_pd(_mm256_loadu_pd(k), _mm256_sub_pd(length, _mm256_loadu_pd(restLength))),
                      _mm256_mul_pd(_mm256_mul_pd(_mm256_loadu_pd(c), dot), inverse));
    const __m256d s = _mm256_xor_pd(_mm256_mul_pd(magnitude, inverse), _mm256_set1_pd(-0.0));
    return {_mm256_mul_pd(s, d.x), _mm256_mul_pd(s, d.y), _mm256_mul_pd(s, d.z)};
}

// [a1 a2 a3 b0]: the 4 doubles one mass (3 doubles) earlier in the flat sequence ... a, b.
FLEXFIT_AVX2 inline __m256d shiftOneMass4(__m256d a, __m256d b) {
    return _mm256_shuffle_pd(a, _mm256_permute2f128_pd(a, b, 0x21), 0b0101);
}

FLEXFIT_AVX2 void blockForces256(const SpringBlocks& blocks, const double* x, const double* v, double* f) {
    __m256d carry = _mm256_setzero_pd();  // previous row block's last vector (g_7 in lanes 1-3)
    for (std::size_t q = 0; q < blocks.blockCount(); ++q) {
        const std::size_t a = 3 * std::size_t(blocks.first[q]), b = a + 3 * std::size_t(blocks.offset[q]);
        __m256d g[6];  // the block's 24 doubles
        for (std::size_t half = 0; half < 2; ++half) {
            const std::size_t o = 12 * half, lane = W * q + 4 * half;
            const Lanes4 forces = springForces4(difference4(x + a + o, x + b + o), difference4(v + a + o, v + b + o),
                                                blocks.stiffness.data() + lane, blocks.damping.data() + lane,
                                                blocks.restLength.data() + lane);
            interleave4(forces, g + 3 * half);
        }
        double* fa = f + a;
        if (blocks.offset[q] == 1) {
            __m256d previous = blocks.continuesRow(q) ? carry : _mm256_setzero_pd();
            for (int j = 0; j < 6; ++j) {
                const __m256d shifted = shiftOneMass4(previous, g[j]);
                _mm256_storeu_pd(fa + 4 * j, _mm256_sub_pd(_mm256_add_pd(_mm256_loadu_pd(fa + 4 * j), g[j]), shifted));
                previous = g[j];
            }
            carry = g[5];
            if (q + 1 == blocks.blockCount() || !blocks.continuesRow(q + 1)) {
                alignas(32) double last[4];
                _mm256_store_pd(last, g[5]);
                for (int c = 0; c < 3; ++c) fa[24 + c] -= last[1 + c];
            }
            continue;
        }
        double* fb = f + b;
        for (int j = 0; j < 6; ++j) _mm256_storeu_pd(fa + 4 * j, _mm256_add_pd(_mm256_loadu_pd(fa + 4 * j), g[j]));
        for (int j = 0; j < 6; ++j) _mm256_storeu_pd(fb + 4 * j, _mm256_sub_pd(_mm256_loadu_pd(fb + 4 * j), g[j]));
    }
}

FLEXFIT_AVX2 inline __m256d spread4(__m256d values, int j) {
    switch (j) {  // lane l of vector j is mass (4j+l)/3
        case 0: return _mm256_permute4x64_pd(values, 0x40);  // 0 0 0 1
        case 1: return _mm256_permute4x64_pd(values, 0xA5);  // 1 1 2 2
        default: return _mm256_permute4x64_pd(values, 0xFE);  // 2 3 3 3
    }
}

// Groups of 4 masses: group g starts at 4 g, or with an octet list at 8 octets[g / 2] + 4 (g % 2).
FLEXFIT_AVX2 std::size_t integrate256(const PartModel& model, const MassUpdate& p, PartState& state, const Index* octets,
                                      std::size_t groups) {
    double* x = state.positions.data()->data();
    double* v = state.velocities.data()->data();
    double* f = state.forces.data()->data();
    const double* rest = model.restPositions.data()->data();
    alignas(32) double gravity[12];
    for (int j = 0; j < 12; ++j) gravity[j] = p.gravity[j % 3];
    const __m256d h = _mm256_set1_pd(p.h), invH = _mm256_set1_pd(p.invH), drag = _mm256_set1_pd(p.drag);
    const __m256d anchor = _mm256_set1_pd(p.anchorStiffness), constraint = _mm256_set1_pd(p.constraint);
    const bool anchored = p.anchorStiffness != 0.0, readsRest = p.readsRest();
    for (std::size_t g = 0; g < groups; ++g) {
        const std::size_t i = octets != nullptr ? 8 * std::size_t(octets[g / 2]) + 4 * (g % 2) : 4 * g;
        const __m256d mass = _mm256_loadu_pd(model.mass.data() + i);
        const __m256d hOverMass = _mm256_mul_pd(h, _mm256_loadu_pd(model.inverseMass.data() + i));
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
            _mm256_storeu_pd(x + o, xn);
            _mm256_storeu_pd(v + o, vn);
            _mm256_storeu_pd(f + o, _mm256_setzero_pd());
        }
    }
    return 4 * groups;
}

}  // namespace

void blockForcesAvx2(const SpringBlocks& blocks, const double* x, const double* v, double* f) {
    blockForces256(blocks, x, v, f);
}
void blockForcesAvx512(const SpringBlocks& blocks, const double* x, const double* v, double* f) {
    blockForces512(blocks, x, v, f);
}
std::size_t remainderForcesAvx512(const PartModel& model, const double* x, const double* v, double* f) {
    return remainder512(model, x, v, f);
}
std::size_t integrateAvx2(const PartModel& model, const MassUpdate& update, PartState& state) {
    return integrate256(model, update, state, nullptr, model.massCount() / 4);
}
std::size_t integrateAvx512(const PartModel& model, const MassUpdate& update, PartState& state) {
    return integrate512(model, update, state, nullptr, model.massCount() / 8);
}
void integrateOctetsAvx2(const PartModel& model, const MassUpdate& update, std::span<const Index> octets, PartState& state) {
    integrate256(model, update, state, octets.data(), 2 * octets.size());
}
void integrateOctetsAvx512(const PartModel& model, const MassUpdate& update, std::span<const Index> octets, PartState& state) {
    integrate512(model, update, state, octets.data(), octets.size());
}
void regionBlockForcesAvx512(const SpringBlocks& blocks, std::span<const Index> fullBlocks, const std::uint16_t* cover,
                             const double* x, const double* v, double* f) {
    regionBlocks512(blocks, fullBlocks, cover, x, v, f);
}
std::size_t holdAtRestAvx512(const PartModel& model, const std::uint16_t* cover, PartState& state) {
    return holdAtRest512(model, cover, state);
}

}  // namespace flexfit::detail

#endif  // FLEXFIT_X86_KERNELS
