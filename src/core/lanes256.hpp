// Internal: 3-vectors four at a time with AVX2 (x86-64, GCC or Clang), by the same operations in
// the same order as the Eigen 3.4 expressions they replace, so each lane gives the same bits as
// the scalar code (the library builds with -ffp-contract=off, and these functions do not enable
// FMA). Off when the build enables FMA (-mfma, -march=native): Eigen's SSE2 packets then fuse
// multiply-adds that these lanes do not.
// Eigen's orders, measured bit for bit on 300,000 random inputs: a 3-vector's dot product and
// squared norm (a0 b0 + a1 b1) + a2 b2; a 3x3 matrix times a vector, rows 0 and 1
// (m0 v0 + m1 v1) + m2 v2 but row 2 m0 v0 + (m1 v1 + m2 v2) (rows 0-1 form one SSE2 packet);
// cross products and Quaternion::_transformVector as written in Eigen's source. Callers check
// lanesEnabled() and keep a test that compares with the scalar code bitwise.
#pragma once

namespace flexfit::detail {

// True when the paths built on these lanes run: compiled in, the CPU has AVX2, and no
// ScopedScalarLanes is alive (lanes256.cpp). The paths: the contact response's frictionless
// reactions, Part::displaceMasses, the point shell's contacts and its moving masses' skip test,
// intersectTriangles' separating-axis loop.
bool lanesEnabled();

// While at least one scope is alive (on any thread), those paths run one at a time: for tests.
class ScopedScalarLanes {
public:
    ScopedScalarLanes();
    ~ScopedScalarLanes();
    ScopedScalarLanes(const ScopedScalarLanes&) = delete;
    ScopedScalarLanes& operator=(const ScopedScalarLanes&) = delete;
};

}  // namespace flexfit::detail

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__FMA__)
#define FLEXFIT_LANES256 1

#include "flexfit/core.hpp"

#include <Eigen/Geometry>
#include <immintrin.h>

#define FLEXFIT_AVX2_LANES __attribute__((target("avx2")))

namespace flexfit::detail::lanes {

// Four 3-vectors, one coordinate a register.
struct Lanes3 {
    __m256d x, y, z;
};

FLEXFIT_AVX2_LANES inline Lanes3 broadcast(const Vec3& v) { return {_mm256_set1_pd(v.x()), _mm256_set1_pd(v.y()), _mm256_set1_pd(v.z())}; }
FLEXFIT_AVX2_LANES inline Lanes3 add(const Lanes3& a, const Lanes3& b) { return {_mm256_add_pd(a.x, b.x), _mm256_add_pd(a.y, b.y), _mm256_add_pd(a.z, b.z)}; }
FLEXFIT_AVX2_LANES inline Lanes3 sub(const Lanes3& a, const Lanes3& b) { return {_mm256_sub_pd(a.x, b.x), _mm256_sub_pd(a.y, b.y), _mm256_sub_pd(a.z, b.z)}; }
FLEXFIT_AVX2_LANES inline Lanes3 scale(__m256d s, const Lanes3& v) { return {_mm256_mul_pd(s, v.x), _mm256_mul_pd(s, v.y), _mm256_mul_pd(s, v.z)}; }
FLEXFIT_AVX2_LANES inline Lanes3 divide(const Lanes3& v, __m256d d) { return {_mm256_div_pd(v.x, d), _mm256_div_pd(v.y, d), _mm256_div_pd(v.z, d)}; }
FLEXFIT_AVX2_LANES inline Lanes3 negate(const Lanes3& v) {
    const __m256d sign = _mm256_set1_pd(-0.0);
    return {_mm256_xor_pd(v.x, sign), _mm256_xor_pd(v.y, sign), _mm256_xor_pd(v.z, sign)};
}

// Eigen's cross.
FLEXFIT_AVX2_LANES inline Lanes3 cross(const Lanes3& l, const Lanes3& r) {
    return {_mm256_sub_pd(_mm256_mul_pd(l.y, r.z), _mm256_mul_pd(l.z, r.y)), _mm256_sub_pd(_mm256_mul_pd(l.z, r.x), _mm256_mul_pd(l.x, r.z)),
            _mm256_sub_pd(_mm256_mul_pd(l.x, r.y), _mm256_mul_pd(l.y, r.x))};
}

// Eigen's dot (and squaredNorm, as dot(v, v)).
FLEXFIT_AVX2_LANES inline __m256d dot(const Lanes3& a, const Lanes3& b) {
    return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(a.x, b.x), _mm256_mul_pd(a.y, b.y)), _mm256_mul_pd(a.z, b.z));
}

// q v, as Eigen's Quaternion::_transformVector: uv = q.vec x v, doubled; v + w uv + q.vec x uv.
struct QuaternionLanes {
    Lanes3 vec;
    __m256d w;
};
FLEXFIT_AVX2_LANES inline QuaternionLanes broadcast(const Eigen::Quaterniond& q) { return {broadcast(Vec3(q.vec())), _mm256_set1_pd(q.w())}; }
FLEXFIT_AVX2_LANES inline Lanes3 rotate(const QuaternionLanes& q, const Lanes3& v) {
    Lanes3 uv = cross(q.vec, v);
    uv = add(uv, uv);
    return add(add(v, scale(q.w, uv)), cross(q.vec, uv));
}

// m v, as Eigen's Matrix3d * Vector3d (the rows' orders above).
FLEXFIT_AVX2_LANES inline __m256d packetRow(const Eigen::Matrix3d& m, int i, const Lanes3& v) {
    return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(m(i, 0)), v.x), _mm256_mul_pd(_mm256_set1_pd(m(i, 1)), v.y)),
                         _mm256_mul_pd(_mm256_set1_pd(m(i, 2)), v.z));
}
FLEXFIT_AVX2_LANES inline Lanes3 times(const Eigen::Matrix3d& m, const Lanes3& v) {
    const __m256d last = _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(m(2, 0)), v.x),
                                       _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(m(2, 1)), v.y), _mm256_mul_pd(_mm256_set1_pd(m(2, 2)), v.z)));
    return {packetRow(m, 0, v), packetRow(m, 1, v), last};
}

// The lanes of four vectors (any indexable 3-vectors) and back.
// Set lane by lane in registers: a vector load from four scalar stores would stall on the
// stores (no forwarding).
template <class Get>
FLEXFIT_AVX2_LANES inline Lanes3 gather(Get get) {
    const Vec3 &a = get(0), &b = get(1), &c = get(2), &d = get(3);
    return {_mm256_set_pd(d.x(), c.x(), b.x(), a.x()), _mm256_set_pd(d.y(), c.y(), b.y(), a.y()), _mm256_set_pd(d.z(), c.z(), b.z(), a.z())};
}
struct Stored3 {
    alignas(32) double c[3][4];
    Vec3 operator[](int j) const { return {c[0][j], c[1][j], c[2][j]}; }
};
FLEXFIT_AVX2_LANES inline Stored3 store(const Lanes3& v) {
    Stored3 s;
    _mm256_store_pd(s.c[0], v.x);
    _mm256_store_pd(s.c[1], v.y);
    _mm256_store_pd(s.c[2], v.z);
    return s;
}

}  // namespace flexfit::detail::lanes

#endif
