// The lane helpers (src/core/lanes256.hpp) against the Eigen expressions they stand for, lane by
// lane and bit for bit, on random inputs: an Eigen upgrade that changes an operation order
// fails here before any scene does.
#include "core/lanes256.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#if defined(FLEXFIT_LANES256)

using namespace flexfit;
using namespace flexfit::detail::lanes;

namespace {

struct Random {
    std::mt19937 rng{11};
    std::uniform_real_distribution<double> u{-1.0, 1.0};
    Vec3 vector() { return {3.0 * u(rng), u(rng), 7.0 * u(rng)}; }
    Eigen::Quaterniond rotation() { return Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized(); }
};

// Lane j of each helper beside Eigen's value.
FLEXFIT_AVX2_LANES void compareFour(const Vec3 (&a)[4], const Vec3 (&b)[4], const Eigen::Quaterniond& q, const Eigen::Matrix3d& m) {
    const Lanes3 la = gather([&](int j) -> const Vec3& { return a[j]; }), lb = gather([&](int j) -> const Vec3& { return b[j]; });
    const Stored3 crossed = store(cross(la, lb)), turned = store(rotate(broadcast(q), la)), timed = store(times(m, la));
    alignas(32) double dots[4];
    _mm256_store_pd(dots, dot(la, lb));
    for (int j = 0; j < 4; ++j) {
        EXPECT_EQ(crossed[j], a[j].cross(b[j]));
        EXPECT_EQ(turned[j], q * a[j]);
        EXPECT_EQ(timed[j], m * a[j]);
        EXPECT_EQ(dots[j], a[j].dot(b[j]));
    }
    // Lane 3 has b = a: dot(v, v) is Eigen's squared norm, and its root the norm.
    EXPECT_EQ(dots[3], a[3].squaredNorm());
    EXPECT_EQ(std::sqrt(dots[3]), a[3].norm());
}

}  // namespace

TEST(Lanes256, EveryHelperEqualsEigenBitForBit) {
    if (!detail::lanesEnabled()) GTEST_SKIP() << "no AVX2 on this CPU";
    Random r;
    for (int i = 0; i < 20000; ++i) {
        Vec3 a[4], b[4];
        for (int j = 0; j < 4; ++j) {
            a[j] = r.vector();
            b[j] = j == 3 ? a[j] : r.vector();  // lane 3: dot(a, a), the squared norm
        }
        const Eigen::Quaterniond q = r.rotation();
        compareFour(a, b, q, (r.rotation() * q).toRotationMatrix());
    }
}

#endif

TEST(Lanes256, AScopeTurnsTheLanesOff) {
    const bool before = detail::lanesEnabled();
    {
        const detail::ScopedScalarLanes scalar;
        EXPECT_FALSE(detail::lanesEnabled());
    }
    EXPECT_EQ(detail::lanesEnabled(), before);
}
