// Triangle queries against independent references: dense sampling of the triangle for the
// closest point, and edge-through-triangle (Moller-Trumbore) tests for intersection.
#include "collision/triangle_queries.hpp"
#include "core/lanes256.hpp"
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <utility>

using namespace flexfit;

namespace {

// Closest point by sampling the triangle on a fine barycentric grid (and its edges finely).
Vec3 sampledClosest(const Vec3& p, const Triangle& t, int n = 400) {
    Vec3 best = t.a;
    auto consider = [&](const Vec3& q) {
        if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
    };
    for (int i = 0; i <= n; ++i)
        for (int j = 0; i + j <= n; ++j) consider(t.a + (double(i) / n) * (t.b - t.a) + (double(j) / n) * (t.c - t.a));
    for (int k = 0; k <= 20 * n; ++k) {
        const double s = double(k) / (20 * n);
        consider(t.a + s * (t.b - t.a));
        consider(t.b + s * (t.c - t.b));
        consider(t.c + s * (t.a - t.c));
    }
    return best;
}

// Segment pq against triangle t (Moller-Trumbore), closed.
bool segmentHitsTriangle(const Vec3& p, const Vec3& q, const Triangle& t) {
    const Vec3 d = q - p, e1 = t.b - t.a, e2 = t.c - t.a;
    const Vec3 h = d.cross(e2);
    const double det = e1.dot(h);
    if (std::abs(det) < 1e-14) return false;
    const double inv = 1.0 / det;
    const Vec3 s = p - t.a;
    const double u = inv * s.dot(h);
    if (u < 0 || u > 1) return false;
    const Vec3 qv = s.cross(e1);
    const double v = inv * d.dot(qv);
    if (v < 0 || u + v > 1) return false;
    const double w = inv * e2.dot(qv);
    return w >= 0 && w <= 1;
}

bool referenceIntersects(const Triangle& x, const Triangle& y) {
    const Vec3 xs[3] = {x.a, x.b, x.c}, ys[3] = {y.a, y.b, y.c};
    for (int i = 0; i < 3; ++i)
        if (segmentHitsTriangle(xs[i], xs[(i + 1) % 3], y) || segmentHitsTriangle(ys[i], ys[(i + 1) % 3], x)) return true;
    return false;
}

Triangle shifted(const Triangle& t, const Vec3& d) { return {t.a + d, t.b + d, t.c + d}; }

// Corners uniform in [-1, 1]^3 (drawn in order: a, then b, then c; x, y, z each).
Triangle randomTriangle(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-1, 1);
    Triangle t;
    for (Vec3* corner : {&t.a, &t.b, &t.c})
        for (int d = 0; d < 3; ++d) (*corner)[d] = u(rng);
    return t;
}

}  // namespace

TEST(ClosestPoint, MatchesDenseSamplingInEveryRegion) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-2, 2);
    const Triangle shapes[] = {
        {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},             // right triangle
        {{0, 0, 0}, {3, 0.01, 0}, {1.5, 0.02, 0.01}},   // needle
        {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}},             // degenerate: collinear
        {{0.3, 0.3, 0.3}, {0.3, 0.3, 0.3}, {0.3, 0.3, 0.3}},  // degenerate: a point
        {{-1, 0.2, 0.5}, {0.7, -0.4, 1.1}, {0.1, 1.3, -0.6}},
    };
    for (const Triangle& t : shapes)
        for (int k = 0; k < 60; ++k) {
            const Vec3 p(u(rng), u(rng), u(rng));
            const Vec3 exact = closestPointOnTriangle(p, t);
            const Vec3 sampled = sampledClosest(p, t);
            // The exact point is never farther than the best sample, and lies within the grid's spacing of it.
            EXPECT_LE((exact - p).norm(), (sampled - p).norm() + 1e-12);
            EXPECT_NEAR((exact - p).norm(), (sampled - p).norm(), 2e-2);
        }
}

TEST(ClosestPoint, VoronoiRegionsExactly) {
    const Triangle t{{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
    EXPECT_TRUE(closestPointOnTriangle({-1, -1, 3}, t).isApprox(Vec3(0, 0, 0)));    // vertex A
    EXPECT_TRUE(closestPointOnTriangle({3, -1, 1}, t).isApprox(Vec3(2, 0, 0)));     // vertex B
    EXPECT_TRUE(closestPointOnTriangle({-1, 3, -2}, t).isApprox(Vec3(0, 2, 0)));    // vertex C
    EXPECT_TRUE(closestPointOnTriangle({1, -1, 0}, t).isApprox(Vec3(1, 0, 0)));     // edge AB
    EXPECT_TRUE(closestPointOnTriangle({-1, 1, 5}, t).isApprox(Vec3(0, 1, 0)));     // edge AC
    EXPECT_TRUE(closestPointOnTriangle({2, 2, 0}, t).isApprox(Vec3(1, 1, 0)));      // edge BC
    EXPECT_TRUE(closestPointOnTriangle({0.5, 0.5, -4}, t).isApprox(Vec3(0.5, 0.5, 0)));  // face
}

TEST(SphereTriangle, ContactPointNormalDepth) {
    const Triangle t{{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
    const auto hit = sphereTriangleContact({0.5, 0.5, 0.3}, 0.5, t);
    ASSERT_TRUE(hit);
    EXPECT_TRUE(hit->point.isApprox(Vec3(0.5, 0.5, 0)));
    EXPECT_TRUE(hit->normal.isApprox(Vec3(0, 0, 1)));
    EXPECT_NEAR(hit->depth, 0.2, 1e-12);
    EXPECT_FALSE(sphereTriangleContact({0.5, 0.5, 0.6}, 0.5, t));
    const auto centred = sphereTriangleContact({0.5, 0.5, 0.0}, 0.5, t);  // centre on the face
    ASSERT_TRUE(centred);
    EXPECT_NEAR(std::abs(centred->normal.z()), 1.0, 1e-12);
}

TEST(TriangleTriangle, AgreesWithEdgeTestsOnRandomPairs) {
    std::mt19937 rng(2);
    int hits = 0;
    for (int k = 0; k < 20000; ++k) {
        const Triangle x = randomTriangle(rng), y = randomTriangle(rng);
        const bool reference = referenceIntersects(x, y);
        const auto contact = intersectTriangles(x, y);
        ASSERT_EQ(contact.has_value(), reference) << "pair " << k;
        if (!contact) continue;
        ++hits;
        // The minimum translation: a little less still intersects, a little more separates.
        EXPECT_TRUE(intersectTriangles(shifted(x, (contact->depth * (1 - 1e-6)) * contact->normal), y)) << k;
        EXPECT_FALSE(intersectTriangles(shifted(x, (contact->depth * (1 + 1e-6) + 1e-9) * contact->normal), y)) << k;
        EXPECT_NEAR(contact->normal.norm(), 1.0, 1e-12);
    }
    EXPECT_GT(hits, 1000);
}

namespace {

std::uint64_t bitsOf(double x) { return std::bit_cast<std::uint64_t>(x); }

// The same contact bit for bit (or none on both sides).
void expectSameBits(const std::optional<TriangleContact>& x, const std::optional<TriangleContact>& y, int pair) {
    ASSERT_EQ(x.has_value(), y.has_value()) << "pair " << pair;
    if (!x) return;
    EXPECT_EQ(bitsOf(x->depth), bitsOf(y->depth)) << "pair " << pair;
    for (int d = 0; d < 3; ++d) {
        EXPECT_EQ(bitsOf(x->normal[d]), bitsOf(y->normal[d])) << "pair " << pair;
        EXPECT_EQ(bitsOf(x->point[d]), bitsOf(y->point[d])) << "pair " << pair;
    }
}

// intersectTriangles with lanes and one at a time give the same contact; whether there is one.
bool expectLanesMatchScalar(const Triangle& x, const Triangle& y, int pair) {
    const auto lanes = intersectTriangles(x, y);
    std::optional<TriangleContact> scalar;
    {
        const detail::ScopedScalarLanes oneAtATime;
        scalar = intersectTriangles(x, y);
    }
    expectSameBits(lanes, scalar, pair);
    return lanes.has_value();
}

}  // namespace

TEST(TriangleTriangle, AxesFourAVectorGiveTheScalarLoopsBits) {
    // intersectTriangles' separating-axis loop runs four axes a vector where lanes run
    // (lanes256.hpp); one at a time under ScopedScalarLanes. Random pairs (most intersect:
    // the second is the first moved a little, or shares a corner with it), coplanar ones (17 axes), pairs with
    // parallel edges (axes skipped), needles, and pairs an axis separates.
    if (!detail::lanesEnabled()) GTEST_SKIP() << "no AVX2 lanes here (CPU, or a build with FMA)";
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> small(-0.3, 0.3);
    int contacts = 0;
    for (int k = 0; k < 20000; ++k) {
        Triangle x = randomTriangle(rng), y = randomTriangle(rng);
        switch (k % 5) {
        case 0: y = shifted(x, {small(rng), small(rng), small(rng)}); break;  // parallel edges
        case 1: y = {x.a + Vec3(small(rng), small(rng), 0.0), x.c, x.b + Vec3(0.0, small(rng), 0.0)}; break;
        case 2:  // coplanar: both in z = 0.25
            for (Triangle* t : {&x, &y}) t->a.z() = t->b.z() = t->c.z() = 0.25;
            break;
        case 3: y.c = y.a + 1e-7 * (y.b - y.a); break;  // a needle
        default: break;
        }
        contacts += expectLanesMatchScalar(x, y, k);
    }
    EXPECT_GT(contacts, 4000);
    // Ties and special values random pairs do not reach: a triangle against itself (pushUp
    // equals pushDown on every axis), zeros of both signs, a NaN corner (projections with a NaN
    // operand: the lanes' min and max must keep std::min / std::max's choices).
    const Triangle t{{0.0, 0.0, 0.0}, {1.0, -0.0, 0.0}, {0.0, 1.0, -0.0}};
    const Triangle u{{-0.0, 0.25, -1.0}, {0.0, 0.25, 1.0}, {0.5, -0.0, 0.0}};
    Triangle withNaN = t;
    withNaN.c.x() = std::numeric_limits<double>::quiet_NaN();
    const std::pair<Triangle, Triangle> special[] = {{t, t}, {u, u}, {t, u}, {u, t}, {withNaN, u}, {u, withNaN}, {withNaN, withNaN}};
    for (std::size_t i = 0; i < std::size(special); ++i) expectLanesMatchScalar(special[i].first, special[i].second, int(100000 + i));
}

TEST(TriangleTriangle, CoplanarAndTouching) {
    const Triangle x{{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
    EXPECT_TRUE(intersectTriangles(x, {{0.5, 0.5, 0}, {3, 0.5, 0}, {0.5, 3, 0}}));   // coplanar, overlapping
    EXPECT_FALSE(intersectTriangles(x, {{3, 3, 0}, {5, 3, 0}, {3, 5, 0}}));          // coplanar, apart
    EXPECT_FALSE(intersectTriangles(x, {{0, 0, 0.1}, {2, 0, 0.1}, {0, 2, 0.1}}));    // parallel planes
    const auto pierce = intersectTriangles(x, {{0.5, 0.5, -1}, {0.6, 0.5, 1}, {0.5, 0.6, 1}});
    ASSERT_TRUE(pierce);
    EXPECT_NEAR(pierce->point.z(), 0.0, 1e-9);
}

// Two edges crossing at exactly one point, each triangle on its own side of the other's edge:
// the edge-edge axis shows a gap of exactly 0. Touching counts as intersecting, so neither the
// unnormalised early rejection nor the normalised loop may reject it; a hair apart, both do.
TEST(TriangleTriangle, EdgesTouchingAtAPointIntersect) {
    const Triangle below{{-1, 0, 0}, {1, 0, 0}, {0, 0, -1}};
    const Triangle above{{0, -1, 0}, {0, 1, 0}, {0, 0, 1}};
    const auto touch = intersectTriangles(below, above);
    ASSERT_TRUE(touch);
    EXPECT_EQ(touch->depth, 0.0);
    EXPECT_FALSE(intersectTriangles(below, shifted(above, {0, 0, 1e-9})));
    EXPECT_TRUE(intersectTriangles(below, shifted(above, {0, 0, -1e-9})));
}

// Faces of solids (FaceSides::Solids): an upper box sunk 0.01 into an equal one below, flush. Its side
// face (x = 0.5, facing +x) meets the lower box's top face (y = 0.5, facing +y) only along the
// lower box's top edge, which lies in the side face's plane: two-sided, the smallest push slides
// the side face off that edge by 0 (out along its own normal); the solids overlap by 0.01 along
// y, the push that takes the upper box out.
TEST(TriangleTriangle, FacesOfSolidsArePushedOutOfEachOtherNotOffAnEdge) {
    const Triangle side{{0.5, 0.49, -0.5}, {0.5, 1.49, -0.5}, {0.5, 0.49, 0.5}};  // normal +x
    const Triangle top{{0.5, 0.5, -0.5}, {-0.5, 0.5, -0.5}, {0.5, 0.5, 0.5}};     // normal +y
    const auto twoSided = intersectTriangles(side, top);
    ASSERT_TRUE(twoSided);
    EXPECT_LT(twoSided->depth, 1e-12);
    EXPECT_GT(twoSided->normal.x(), 0.5);  // out along the side face's own normal
    const auto solids = intersectTriangles(side, top, FaceSides::Solids);
    ASSERT_TRUE(solids);
    EXPECT_NEAR(solids->depth, 0.01, 1e-12);
    EXPECT_TRUE(solids->normal.isApprox(Vec3::UnitY(), 1e-12));
    // The same with the lower box's face first: it is pushed down, out of the upper box.
    const auto reversed = intersectTriangles(top, side, FaceSides::Solids);
    ASSERT_TRUE(reversed);
    EXPECT_NEAR(reversed->depth, 0.01, 1e-12);
    EXPECT_TRUE(reversed->normal.isApprox(-Vec3::UnitY(), 1e-12));
    // Sunk deeper than a tenth of the faces' size, the push along y is no longer taken for the
    // solids' overlap (it could be a slide along a face): the two-sided push stays.
    const Triangle deep = shifted(side, {0, -0.2, 0});
    EXPECT_LT(intersectTriangles(deep, top, FaceSides::Solids)->depth, 1e-12);
}

// Faces of solids meeting nearly parallel and opposing: a small face tilted 3.8 degrees on a
// large floor face, one side 0.06 below the floor's plane and the other 0.006 above. Two-sided,
// the smallest push lifts the floor through the small face by 0.006; read as solids, the floor
// is pushed back down by the small face's depth behind it, 0.06 (its lowest corners), at the
// middle of that depth. (The floor behind the tilted face reaches 0.06 / cos 3.8 deg: deeper.)
TEST(TriangleTriangle, OpposingFacesOfSolidsArePushedBackNotThrough) {
    const Triangle floor{{-5, 0, -5}, {-5, 0, 10}, {10, 0, -5}};     // normal +y
    const Triangle tilted{{0, -0.06, 0}, {1, 0.006, 0}, {0, -0.06, 1}};  // normal (0.066, -1, 0), down
    const auto twoSided = intersectTriangles(floor, tilted);
    ASSERT_TRUE(twoSided);
    EXPECT_GT(twoSided->normal.y(), 0.99);  // through: the floor lifted over the small face
    EXPECT_NEAR(twoSided->depth, 0.006, 1e-12);
    expectSameBits(intersectTriangles(floor, tilted, FaceSides::Solids), twoSided, 0);  // deformable pairs: two-sided
    const auto solids = intersectTriangles(floor, tilted, FaceSides::RigidSolids);
    ASSERT_TRUE(solids);
    EXPECT_TRUE(solids->normal.isApprox(-Vec3::UnitY(), 1e-12));
    EXPECT_NEAR(solids->depth, 0.06, 1e-12);
    EXPECT_NEAR(solids->point.y(), -0.03, 1e-12);
    EXPECT_NEAR(solids->point.x(), 0.0, 1e-12);
    // First and second swapped: the small face is pushed back up out of the floor, as deep.
    const auto swapped = intersectTriangles(tilted, floor, FaceSides::RigidSolids);
    ASSERT_TRUE(swapped);
    EXPECT_NEAR(swapped->depth, 0.06, 1e-12);
    EXPECT_GT(swapped->normal.y(), 0.99);
}

// On random pairs, faces of rigid solids change the push only as the header says: the contact is
// there exactly when the two-sided one is; the push is the two-sided one unless that leans more
// than 30 degrees out along the first face's normal or into the second's, and then it leans
// less and still separates the triangles (checked by the existence test, which does not depend
// on the push); between faces more than 30 degrees from parallel it is no longer than a tenth
// of the shorter triangle's longest edge, between opposing faces nearer parallel it is along
// one face's normal (FaceSides::Solids leaves those two-sided). With lanes and one at a time,
// the same bits.
TEST(TriangleTriangle, FacesOfSolidsChangeOnlyPushesOutOfTheCone) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> small(-0.3, 0.3);
    int changed = 0, contacts = 0, opposing = 0;
    for (int k = 0; k < 20000; ++k) {
        const Triangle x = randomTriangle(rng);
        const Triangle y = k % 2 == 0 ? randomTriangle(rng) : shifted(x, {small(rng), small(rng), small(rng)});
        const auto twoSided = intersectTriangles(x, y), solids = intersectTriangles(x, y, FaceSides::RigidSolids);
        const auto deformable = intersectTriangles(x, y, FaceSides::Solids);
        ASSERT_EQ(twoSided.has_value(), solids.has_value()) << "pair " << k;
        if (!solids) continue;
        ++contacts;
        if (detail::lanesEnabled()) {
            const detail::ScopedScalarLanes oneAtATime;
            expectSameBits(solids, intersectTriangles(x, y, FaceSides::RigidSolids), k);
        }
        if (bitsOf(solids->depth) == bitsOf(twoSided->depth) && solids->normal == twoSided->normal) continue;
        ++changed;
        const Vec3 n1 = (x.b - x.a).cross(x.c - x.a).normalized(), n2 = (y.b - y.a).cross(y.c - y.a).normalized();
        EXPECT_TRUE(twoSided->normal.dot(n1) > 0.5 || twoSided->normal.dot(n2) < -0.5) << "pair " << k;
        EXPECT_LE(solids->normal.dot(n1), 0.5) << "pair " << k;
        EXPECT_GE(solids->normal.dot(n2), -0.5) << "pair " << k;
        if (std::abs(n1.dot(n2)) > std::cos(M_PI / 6)) {
            ++opposing;
            EXPECT_LT(n1.dot(n2), 0.0) << "pair " << k;
            EXPECT_TRUE(solids->normal.isApprox(n2, 1e-12) || solids->normal.isApprox(-n1, 1e-12)) << "pair " << k;
            expectSameBits(deformable, twoSided, k);  // Solids alone leaves these two-sided
        } else {
            expectSameBits(deformable, solids, k);
            const double shorter = std::min({std::max({(x.b - x.a).norm(), (x.c - x.b).norm(), (x.a - x.c).norm()}),
                                             std::max({(y.b - y.a).norm(), (y.c - y.b).norm(), (y.a - y.c).norm()})});
            EXPECT_LE(solids->depth, 0.1 * shorter + 1e-12) << "pair " << k;
        }
        EXPECT_FALSE(intersectTriangles(shifted(x, (solids->depth * (1 + 1e-6) + 1e-9) * solids->normal), y)) << "pair " << k;
    }
    EXPECT_GT(contacts, 2000);
    EXPECT_GT(changed, 50);
    EXPECT_GT(opposing, 10);
}

TEST(TriangleGap, ALowerBoundOnTheDistanceThatKeepsPairsApart) {
    // Random pairs: intersecting ones have no gap; separated ones a gap no wider than their
    // distance (sampled: the closest sampled point of one to each vertex and edge sample of the
    // other bounds it from above), and any move shorter than the gap leaves them apart.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    int apart = 0;
    for (int k = 0; k < 3000; ++k) {
        const Triangle x = randomTriangle(rng), y = randomTriangle(rng);
        const double gap = triangleGap(x, y);
        ASSERT_GE(gap, 0.0);
        if (intersectTriangles(x, y)) {
            EXPECT_EQ(gap, 0.0) << "pair " << k;
            continue;
        }
        ++apart;
        double distance = std::numeric_limits<double>::infinity();
        for (const Triangle* t : {&x, &y}) {
            const Triangle& other = t == &x ? y : x;
            for (int i = 0; i <= 40; ++i) {
                const double s = i / 40.0;
                for (const Vec3& p : {Vec3(t->a + s * (t->b - t->a)), Vec3(t->b + s * (t->c - t->b)), Vec3(t->c + s * (t->a - t->c))})
                    distance = std::min(distance, (closestPointOnTriangle(p, other) - p).norm());
            }
        }
        EXPECT_LE(gap, distance * (1 + 1e-9) + 1e-12) << "pair " << k;
        const Vec3 direction = Vec3(u(rng), u(rng), u(rng)).normalized();
        EXPECT_FALSE(intersectTriangles(shifted(x, (0.999 * gap) * direction), y)) << "pair " << k;
    }
    EXPECT_GT(apart, 1000);
}

TEST(TriangleGap, StoppedAtEnoughItStillBoundsTheFullGap) {
    // With `enough`, it may stop at the first axis whose gap exceeds it: the result is then
    // above `enough` and at most the full gap; when the full gap does not exceed `enough`, the
    // result is the full gap itself (no axis stops it).
    std::mt19937 rng(5);
    int stopped = 0;
    for (int k = 0; k < 3000; ++k) {
        const Triangle x = randomTriangle(rng), y = randomTriangle(rng);
        const double gap = triangleGap(x, y);
        for (const double enough : {0.0, 0.25 * gap, 0.5 * gap, 0.999 * gap, gap, 2.0 * gap}) {
            const double early = triangleGap(x, y, enough);
            EXPECT_LE(early, gap) << "pair " << k;
            if (gap > enough) {
                EXPECT_GT(early, enough) << "pair " << k;
                stopped += early < gap;
            } else {
                EXPECT_EQ(early, gap) << "pair " << k;
            }
        }
    }
    EXPECT_GT(stopped, 100) << "some searches must stop before the widest axis";
}
