// The signed distance field against independent references: the analytic distance to a box,
// brute force over every face of a sphere mesh, the stated interpolation error, and the
// pruning bound against dense sampling.
#include "collision/sampling_kernel.hpp"
#include "collision/triangle_queries.hpp"
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include "one_core.hpp"
#include "unit_cube.hpp"

#include <bit>
#include <random>

using namespace flexfit;

namespace {

using flexfit::testing::unitCube;

// Signed distance to the box [0, 1]^3 (negative inside).
double boxDistance(const Vec3& p) {
    const Vec3 q = (p - Vec3::Constant(0.5)).cwiseAbs() - Vec3::Constant(0.5);
    return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

SignedDistanceField fieldOf(const TriMesh& mesh, double cell = 0.0) {
    const auto model = buildPartModel(mesh);
    return SignedDistanceField(model->mesh, model->topology, cell);
}

}  // namespace

TEST(SignedDistanceField, ExactQueryEqualsTheBoxFormula) {
    const SignedDistanceField field = fieldOf(unitCube());
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-0.8, 1.8);
    for (int i = 0; i < 5000; ++i) {
        const Vec3 p(u(rng), u(rng), u(rng));
        const SignedDistanceField::Sample s = field.query(p);
        ASSERT_NEAR(s.distance, boxDistance(p), 1e-12) << p.transpose();
        EXPECT_NEAR(s.normal.norm(), 1.0, 1e-12);
        EXPECT_LT((s.closest + s.distance * s.normal - p).norm(), 1e-12);
    }
}

TEST(SignedDistanceField, ExactQueryEqualsBruteForceOnASphereMesh) {
    const TriMesh mesh = makeIcoSphere(2.0, 2);
    const SignedDistanceField field = fieldOf(mesh);
    double inradius = 1e9;  // nearest face plane to the centre
    for (const Face& f : mesh.faces) {
        const Vec3 n = (mesh.vertices[f[1]] - mesh.vertices[f[0]]).cross(mesh.vertices[f[2]] - mesh.vertices[f[0]]).normalized();
        inradius = std::min(inradius, std::abs(n.dot(mesh.vertices[f[0]])));
    }
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    int inside = 0, outside = 0;
    for (int i = 0; i < 3000; ++i) {
        const Vec3 p(u(rng), u(rng), u(rng));
        double nearest = 1e9;
        for (const Face& f : mesh.faces) {
            const Triangle t{mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]};
            nearest = std::min(nearest, (closestPointOnTriangle(p, t) - p).norm());
        }
        const double d = field.query(p).distance;
        ASSERT_NEAR(std::abs(d), nearest, 1e-12);
        // The mesh lies between the inscribed sphere and the sphere of radius 2.
        if (p.norm() < inradius - 1e-9) {
            EXPECT_LT(d, 0.0);
            ++inside;
        }
        if (p.norm() > 2.0 + 1e-9) {
            EXPECT_GT(d, 0.0);
            ++outside;
        }
    }
    EXPECT_GT(inside, 300);
    EXPECT_GT(outside, 1000);
}

TEST(SignedDistanceField, SampleStaysWithinItsErrorBoundAndIsExactNearFaces) {
    const SignedDistanceField field = fieldOf(unitCube(), 0.05);
    const double bound = std::sqrt(3.0) * field.cellSize();
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-0.1, 1.1), inner(0.3, 0.7), off(-0.04, 0.04);
    double worst = 0.0;
    for (int i = 0; i < 5000; ++i) {
        const Vec3 p(u(rng), u(rng), u(rng));
        const double error = std::abs(field.sample(p).distance - boxDistance(p));
        ASSERT_LE(error, bound) << p.transpose();
        worst = std::max(worst, error);
    }
    EXPECT_GT(worst, 1e-4);  // the rounding at edges and corners is real, and bounded
    // Near the middle of a face the distance is linear, which trilinear interpolation
    // reproduces (to float rounding), with the face normal as gradient.
    for (int i = 0; i < 1000; ++i) {
        const Vec3 p(inner(rng), 1.0 + off(rng), inner(rng));
        const SignedDistanceField::Interpolated s = field.sample(p);
        ASSERT_NEAR(s.distance, p.y() - 1.0, 1e-6);
        EXPECT_LT((s.gradient - Vec3::UnitY()).norm(), 1e-5);
    }
}

TEST(SignedDistanceField, ClearOfNeverHidesASampledContact) {
    const SignedDistanceField field = fieldOf(makeIcoSphere(2.0, 2));
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(-2.8, 2.8), unit(-1.0, 1.0), r(0.01, 1.0);
    int cleared = 0, kept = 0;
    for (int i = 0; i < 2000; ++i) {
        const Vec3 centre(u(rng), u(rng), u(rng));
        const double radius = r(rng);
        if (!field.clearOf(centre, radius)) {
            ++kept;
            continue;
        }
        cleared += field.inGrid(centre);  // balls outside the grid are cleared trivially
        // The ball's point nearest the surface, down the field's gradient, then random ones.
        const Vec3 down = centre - radius * field.sample(centre).gradient.normalized();
        if (field.inGrid(down)) {
            ASSERT_GT(field.sample(down).distance, 0.0) << centre.transpose() << " r " << radius;
        }
        for (int k = 0; k < 100; ++k) {
            Vec3 d(unit(rng), unit(rng), unit(rng));
            if (d.norm() > 1.0) d.normalize();
            const Vec3 p = centre + radius * d;
            if (field.inGrid(p)) {
                ASSERT_GT(field.sample(p).distance, 0.0) << centre.transpose() << " r " << radius;
            }
        }
    }
    EXPECT_GT(cleared, 150);
    EXPECT_GT(kept, 200);
}

TEST(SignedDistanceField, ClearOfClearsWhatTheFineSampleClears) {
    // clearOf answers no for a large ball, without its fine sample, where the coarse grid shows
    // that sample cannot clear it. Reference: the fine test itself (the sample at the centre
    // above sqrt(3) times the radius, or the radius plus two cell diagonals, whichever is
    // less), with a margin above its rounding terms. Every ball it clears, clearOf must clear.
    // Two spheres 3 apart: between them the distance is not convex, so the coarse sample can
    // fall below the fine one there, which the bound must allow for (without its sample-error
    // term, this test fails).
    TriMesh two = makeIcoSphere(1.0, 2);
    const TriMesh other = makeIcoSphere(1.0, 2);
    const Index offset = Index(two.vertices.size());
    for (const Vec3& v : other.vertices) two.vertices.push_back(v + Vec3(3.0, 0.0, 0.0));
    for (const Face& f : other.faces) two.faces.push_back({f[0] + offset, f[1] + offset, f[2] + offset});
    const SignedDistanceField field = fieldOf(two);
    const double cell = field.cellSize();
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> x(0.3, 2.7), yz(-1.0, 1.0), r(2.0 * cell, 1.0);
    int checked = 0, large = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3 centre(x(rng), yz(rng), yz(rng));
        const double radius = r(rng);
        ASSERT_TRUE(field.inGrid(centre));
        const double reach = std::min(std::sqrt(3.0) * radius, radius + 2.0 * std::sqrt(3.0) * cell);
        if (!(field.sample(centre).distance > reach + 1e-4)) continue;
        ++checked;
        large += radius > 8.0 * cell;
        EXPECT_TRUE(field.clearOf(centre, radius)) << centre.transpose() << " r " << radius;
    }
    EXPECT_GT(checked, 500);
    EXPECT_GT(large, 300);
}

TEST(SignedDistanceField, NoPointWithinASamplesClearReachTouches) {
    // The coherent point shell skips a mass while it stays within squaredClearReach of its last
    // sample: every point that close samples > 0, down the gradient and at random. And the
    // squared reach is staysClear's bound: a motion just inside it stays clear, one outside not.
    const SignedDistanceField field = fieldOf(makeIcoSphere(2.0, 2));
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-2.8, 2.8), unit(-1.0, 1.0);
    int reached = 0, none = 0;
    for (int i = 0; i < 2000; ++i) {
        const Vec3 centre(u(rng), u(rng), u(rng));
        if (!field.inGrid(centre)) continue;
        const SignedDistanceField::Interpolated s = field.sample(centre);
        const double squaredReach = field.squaredClearReach(s.distance);
        if (squaredReach < 0.0) {
            ++none;
            EXPECT_FALSE(field.staysClear(s.distance, 0.0)) << s.distance;
            continue;
        }
        ++reached;
        const double reach = std::sqrt(squaredReach);
        EXPECT_TRUE(field.staysClear(s.distance, reach * (1.0 - 1e-6)));
        EXPECT_FALSE(field.staysClear(s.distance, reach * (1.0 + 1e-6)));
        const Vec3 down = centre - reach * s.gradient.normalized();
        if (field.inGrid(down)) {
            ASSERT_GT(field.sample(down).distance, 0.0) << centre.transpose();
        }
        for (int k = 0; k < 50; ++k) {
            Vec3 d(unit(rng), unit(rng), unit(rng));
            if (d.norm() > 1.0) d.normalize();
            const Vec3 p = centre + reach * d;
            if (field.inGrid(p)) {
                ASSERT_GT(field.sample(p).distance, 0.0) << centre.transpose();
            }
        }
    }
    EXPECT_GT(reached, 500);
    EXPECT_GT(none, 20);
}

TEST(SignedDistanceField, OpenFlippedOrInsideOutMeshIsRefused) {
    TriMesh open = unitCube();
    open.faces.pop_back();
    EXPECT_THROW(fieldOf(open), std::invalid_argument);
    TriMesh flipped = unitCube();
    std::swap(flipped.faces[3][1], flipped.faces[3][2]);  // one face turned over
    EXPECT_THROW(fieldOf(flipped), std::invalid_argument);
    TriMesh insideOut = unitCube();
    for (Face& f : insideOut.faces) std::swap(f[1], f[2]);
    EXPECT_THROW(fieldOf(insideOut), std::invalid_argument);
    EXPECT_NO_THROW(fieldOf(unitCube()));
}

// The batch sampler (eight points a vector with AVX-512, four with AVX2) against sample() on a
// second field of the same mesh, bit for bit: points near the surface (corners computed when
// built) and far from it (corners computed on first reading, by whichever field reads first),
// in batches of every length, so whole vectors of 8 and of 4 and the scalar tail all run.
namespace {

void expectSampleManyEqualsSample() {
    const TriMesh sphere = makeIcoSphere(1.0, 2);
    const SignedDistanceField batched = fieldOf(sphere), single = fieldOf(sphere);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.6, 1.6);
    std::vector<Vec3> points;
    while (points.size() < 4000) {
        const Vec3 p(u(rng), u(rng), u(rng));
        if (batched.inGrid(p)) points.push_back(p);
    }
    std::size_t start = 0, compared = 0;
    for (std::size_t length = 0; start + length <= points.size(); start += length, length = (length + 1) % 23) {
        const std::span<const Vec3> batch(points.data() + start, length);
        std::vector<SignedDistanceField::Interpolated> out(length);
        batched.sampleMany(batch, out);
        for (std::size_t k = 0; k < length; ++k, ++compared) {
            const SignedDistanceField::Interpolated s = single.sample(batch[k]);
            ASSERT_EQ(std::bit_cast<std::uint64_t>(out[k].distance), std::bit_cast<std::uint64_t>(s.distance)) << batch[k].transpose();
            for (int d = 0; d < 3; ++d)
                ASSERT_EQ(std::bit_cast<std::uint64_t>(out[k].gradient[d]), std::bit_cast<std::uint64_t>(s.gradient[d])) << batch[k].transpose();
        }
    }
    EXPECT_GT(compared, 3500u);
}

}  // namespace

TEST(SignedDistanceField, SampleManyEqualsSampleBitForBit) {
    if (!detail::vectorSamplingEnabled()) GTEST_SKIP() << "no AVX2 on this CPU: sampleMany is sample() point by point";
    expectSampleManyEqualsSample();
}

TEST(SignedDistanceField, SampleManyFourLanePathEqualsSample) {
    const detail::ScopedFourLaneSampling four;
    if (!detail::vectorSamplingEnabled()) GTEST_SKIP() << "no AVX2 on this CPU: sampleMany is sample() point by point";
    ASSERT_FALSE(detail::eightLaneSamplingEnabled());
    expectSampleManyEqualsSample();
}

TEST(SignedDistanceField, SampleManyScalarPathEqualsSample) {
    const detail::ScopedScalarSampling scalar;
    ASSERT_FALSE(detail::vectorSamplingEnabled());
    expectSampleManyEqualsSample();
}

#if defined(__linux__)
// The band and the coarse grid are computed on every usable core, in fixed chunks: pinned to
// one core, the same grids bit for bit, the band computed when the field is built.
TEST(SignedDistanceField, OneCoreBuildsTheSameFieldAsAll) {
    const TriMesh mesh = makeIcoSphere(8.5, 3);
    const SignedDistanceField all = fieldOf(mesh, 0.4);
    const SignedDistanceField single = flexfit::testing::onOneCore([&] { return fieldOf(mesh, 0.4); });
    EXPECT_GT(all.computedNodes(), std::size_t(4 * 4096));  // several chunks
    EXPECT_EQ(single.computedNodes(), all.computedNodes());
    EXPECT_EQ(single.gridHash(), all.gridHash());
    // A sample away from the band computes its corners, which changes the hash.
    const std::uint64_t built = all.gridHash();
    (void)all.sample(Vec3(0.0, 0.0, 0.0));
    EXPECT_GT(all.computedNodes(), single.computedNodes());
    EXPECT_NE(all.gridHash(), built);
}
#endif


namespace {

struct BoundCounts {
    std::size_t exact = 0, below = 0, unbounded = 0;
};

// Lower bounds (sampleLowerBounds, and clearOf through them) of points spread over the field's
// grid, against the exact samples of the same points taken afterwards from the same field
// (which computes the nodes they need), and against a second field's bounds point by point.
BoundCounts lowerBoundsAgainstSamples(const TriMesh& mesh, double cell, double spread) {
    const SignedDistanceField field = fieldOf(mesh, cell), pointByPoint = fieldOf(mesh, cell);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-spread, spread);
    std::vector<Vec3> points;
    while (points.size() < 4000) {
        const Vec3 p(u(rng), u(rng), u(rng));
        if (field.inGrid(p)) points.push_back(p);
    }
    const std::size_t built = field.computedNodes();
    std::vector<double> bounds(points.size());
    field.sampleLowerBounds(points, bounds);
    std::vector<bool> cleared(points.size());
    for (std::size_t k = 0; k < points.size(); ++k) cleared[k] = field.clearOf(points[k], 0.05 * double(k % 10));
    EXPECT_EQ(field.computedNodes(), built) << "neither computes a node";
    BoundCounts counts;
    for (std::size_t k = 0; k < points.size(); ++k) {
        const double s = field.sample(points[k]).distance;
        EXPECT_LE(bounds[k], s) << points[k].transpose();
        std::vector<double> one(1);
        pointByPoint.sampleLowerBounds(std::span<const Vec3>(&points[k], 1), one);
        EXPECT_EQ(std::bit_cast<std::uint64_t>(one[0]), std::bit_cast<std::uint64_t>(bounds[k])) << points[k].transpose();
        if (cleared[k]) {
            EXPECT_GT(s, 0.0) << "cleared a ball whose centre samples <= 0: " << points[k].transpose();
        }
        counts.exact += bounds[k] == s;
        counts.unbounded += std::isinf(bounds[k]);
        counts.below += bounds[k] < s && !std::isinf(bounds[k]);
    }
    EXPECT_GT(field.computedNodes(), built);
    return counts;
}

// A sphere of 5 cells' edges whose core lies beyond the band (no bound there: it may be inside),
// and a torus whose hole and surroundings lie beyond it (outside, reached from the grid's border
// along the axis: a finite bound).
void expectLowerBoundsBelowTheSamples() {
    const BoundCounts sphere = lowerBoundsAgainstSamples(makeIcoSphere(2.0, 2), 0.1, 2.2);
    EXPECT_GT(sphere.exact, 1000u) << "in the band: the sample itself";
    EXPECT_GT(sphere.unbounded, 20u) << "deep inside: no bound";
    EXPECT_GT(sphere.below, 20u) << "the grid's corners: a finite bound";
    const BoundCounts torus = lowerBoundsAgainstSamples(makeTorus(2.0, 0.8, 32, 12), 0.08, 3.0);
    EXPECT_GT(torus.exact, 1000u);
    EXPECT_GT(torus.below, 200u) << "around the tube and in its hole: a finite bound";
}

}  // namespace

TEST(SignedDistanceField, LowerBoundsStayBelowTheSamplesAndComputeNoNode) {
    expectLowerBoundsBelowTheSamples();
}

TEST(SignedDistanceField, LowerBoundsFourLaneAndScalarPathsAgree) {
    {
        const detail::ScopedFourLaneSampling four;
        expectLowerBoundsBelowTheSamples();
    }
    const detail::ScopedScalarSampling scalar;
    expectLowerBoundsBelowTheSamples();
}

TEST(SignedDistanceField, BadCellSizesAreRefusedAndTinyOnesFitTheGrid) {
    const TriMesh cube = unitCube();
    const Topology topology = buildTopology(cube.faces, cube.vertices.size());
    // NaN and cells beyond the mesh: refused (a cell of 1e300 gave NaN samples).
    for (const double bad : {std::nan(""), 1e300, double(INFINITY), 1.5})
        EXPECT_THROW(SignedDistanceField(cube, topology, bad), std::invalid_argument) << bad;
    // A cell so small the node count overflows (it looped forever): the grid's largest cell
    // count instead, and the field is still exact at the nodes near the faces.
    const SignedDistanceField tiny(cube, topology, 1e-300);
    const Vec3 inside(0.5, 0.5, 0.25);  // 0.25 inside the face z = 0
    const SignedDistanceField::Sample exact = tiny.query(inside);
    EXPECT_NEAR(tiny.sample(inside).distance, exact.distance, 0.05);
    // A NaN point (it indexed the grid with int(NaN)): NaN values, no read outside the grid.
    EXPECT_TRUE(std::isnan(tiny.sample(Vec3(std::nan(""), 0.0, 0.0)).distance));
}
