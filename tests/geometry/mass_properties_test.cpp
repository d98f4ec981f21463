// Mass properties against analytic solids: a box (exact), a sphere and a torus (converging
// with the mesh resolution), and a shifted, rotated box (parallel axis and rotation rules).
#include "flexfit/flexfit.hpp"
#include "flexfit/mass_properties.hpp"

#include <gtest/gtest.h>

using namespace flexfit;

namespace {

TriMesh box(const Vec3& half) {
    TriMesh m;
    for (int i = 0; i < 8; ++i)
        m.vertices.emplace_back(i & 1 ? half.x() : -half.x(), i & 2 ? half.y() : -half.y(), i & 4 ? half.z() : -half.z());
    // Outward quads, each split in two.
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) {
        m.faces.push_back({Index(q[0]), Index(q[1]), Index(q[2])});
        m.faces.push_back({Index(q[0]), Index(q[2]), Index(q[3])});
    }
    return m;
}

}  // namespace

TEST(MassProperties, BoxIsExact) {
    const Vec3 half(1.0, 2.0, 0.5);
    const MassProperties p = computeMassProperties(box(half));
    const double m = 8 * half.prod();
    EXPECT_NEAR(p.volume, m, 1e-12);
    EXPECT_LT(p.centroid.norm(), 1e-12);
    const Vec3 size = 2 * half;
    EXPECT_NEAR(p.inertia(0, 0), m / 12 * (size.y() * size.y() + size.z() * size.z()), 1e-12);
    EXPECT_NEAR(p.inertia(1, 1), m / 12 * (size.x() * size.x() + size.z() * size.z()), 1e-12);
    EXPECT_NEAR(p.inertia(2, 2), m / 12 * (size.x() * size.x() + size.y() * size.y()), 1e-12);
    EXPECT_NEAR(p.inertia(0, 1), 0.0, 1e-12);
}

TEST(MassProperties, MovedBoxFollowsTranslationAndRotation) {
    TriMesh m = box({1.0, 2.0, 0.5});
    const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    const Vec3 shift(3, -1, 2);
    const MassProperties before = computeMassProperties(m);
    for (Vec3& v : m.vertices) v = r * v + shift;
    const MassProperties after = computeMassProperties(m);
    EXPECT_NEAR(after.volume, before.volume, 1e-10);
    EXPECT_LT((after.centroid - shift).norm(), 1e-10);
    EXPECT_LT((after.inertia - r * before.inertia * r.transpose()).norm(), 1e-9);
}

TEST(MassProperties, SphereAndTorusConvergeToAnalytic) {
    const double r = 2.0;
    const MassProperties s = computeMassProperties(makeIcoSphere(r, 5));
    const double volume = 4.0 / 3.0 * M_PI * r * r * r;
    EXPECT_NEAR(s.volume / volume, 1.0, 2e-3);
    EXPECT_NEAR(s.inertia(0, 0) / (0.4 * volume * r * r), 1.0, 5e-3);
    EXPECT_NEAR(s.inertia(1, 1) / s.inertia(2, 2), 1.0, 1e-3);

    // The inscribed polyhedral torus converges to the analytic one at second order in the
    // segment angle: doubling the resolution must cut the error about four times.
    const double R = 10.0, a = 2.5;
    const double tv = 2 * M_PI * M_PI * R * a * a;
    const double axial = tv * (R * R + 0.75 * a * a), diametral = tv * (0.5 * R * R + 0.625 * a * a);
    double previous[3] = {0, 0, 0};
    for (int n : {64, 128, 256}) {
        const MassProperties t = computeMassProperties(makeTorus(R, a, 2 * n, n));
        const double errors[3] = {std::abs(t.volume / tv - 1), std::abs(t.inertia(1, 1) / axial - 1),
                                  std::abs(t.inertia(0, 0) / diametral - 1)};
        for (int k = 0; k < 3; ++k) {
            EXPECT_LT(errors[k], 0.01) << n;
            if (previous[k] > 0) {
                EXPECT_NEAR(previous[k] / errors[k], 4.0, 0.5) << "order of convergence, n = " << n;
            }
            previous[k] = errors[k];
        }
    }
}

TEST(MassProperties, OpenOrInsideOutMeshIsRejected) {
    TriMesh m = box({1, 1, 1});
    for (Face& f : m.faces) std::swap(f[1], f[2]);  // inside out
    EXPECT_THROW(computeMassProperties(m, "inside-out box"), InputError);
    TriMesh open;
    open.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    open.faces = {{0, 1, 2}};
    EXPECT_THROW(computeMassProperties(open), InputError);
}
