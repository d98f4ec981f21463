#include "collision/triangle_queries.hpp"
#include "core/lanes256.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

namespace flexfit {
namespace {

Vec3 closestPointOnSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
    const Vec3 ab = b - a;
    const double length2 = ab.squaredNorm();
    if (!(length2 > 0.0)) return a;
    const double t = std::clamp((p - a).dot(ab) / length2, 0.0, 1.0);
    return a + t * ab;
}

// Degenerate triangle (collinear or coincident vertices): the closest of its three edges.
// The closest of the three edges' closest points, and which edge.
Vec3 closestPointOnEdges(const Vec3& p, const Triangle& t, TriangleFeature& feature) {
    const Vec3 candidates[3] = {closestPointOnSegment(p, t.a, t.b), closestPointOnSegment(p, t.b, t.c),
                                closestPointOnSegment(p, t.c, t.a)};
    const auto* best = std::min_element(std::begin(candidates), std::end(candidates),
                                        [&](const Vec3& x, const Vec3& y) { return (x - p).squaredNorm() < (y - p).squaredNorm(); });
    feature = TriangleFeature(int(TriangleFeature::EdgeAB) + int(best - candidates));
    return *best;
}

struct Interval {
    double min, max;
};

[[gnu::always_inline]] inline Interval project(const Triangle& t, const Vec3& axis) {
    const double a = t.a.dot(axis), b = t.b.dot(axis), c = t.c.dot(axis);
    return {std::min({a, b, c}), std::max({a, b, c})};
}

// Intersection of segment pq with triangle t (coplanar segments excluded); appends the point.
template <class Points>
void segmentTriangle(const Vec3& p, const Vec3& q, const Triangle& t, const Vec3& normal, Points& out) {
    const double dp = (p - t.a).dot(normal), dq = (q - t.a).dot(normal);
    if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0) || dp == dq) return;
    const Vec3 x = p + (dp / (dp - dq)) * (q - p);
    if ((closestPointOnTriangle(x, t) - x).squaredNorm() <= 1e-20 * (1.0 + x.squaredNorm())) out.push(x);
}

// A few points on the stack (at most 12 in use).
struct PointSet {
    std::array<Vec3, 12> points;
    int count = 0;
    void push(const Vec3& p) {
        if (count < 12) points[std::size_t(count++)] = p;
    }
};

// Signed distances of t's vertices to the plane (n, d): all strictly on one side means no contact.
bool strictlyOneSide(const Triangle& t, const Vec3& n, double d, double tolerance) {
    const double a = n.dot(t.a) - d, b = n.dot(t.b) - d, c = n.dot(t.c) - d;
    return (a > tolerance && b > tolerance && c > tolerance) || (a < -tolerance && b < -tolerance && c < -tolerance);
}

// An edge-edge axis (unnormalised: no square root) along which the triangles lie apart by
// clearly more than the rounding of this test and of intersectTriangles' normalised one:
// gap / |axis| > 1e-12 * the largest vertex norm, where both roundings stay below 1e-14 times
// it. intersectTriangles' own loop rejects every such pair too, so asking this first changes
// no result; it spares the loop's square roots for most pairs that pass the plane tests.
bool clearlyApartOnAnEdgeAxis(const Triangle& first, const Triangle& second, std::span<const Vec3> edgeAxes, double scale) {
    const double reach2 = std::max({first.a.squaredNorm(), first.b.squaredNorm(), first.c.squaredNorm(), second.a.squaredNorm(),
                                    second.b.squaredNorm(), second.c.squaredNorm()});
    for (const Vec3& axis : edgeAxes) {
        const double length2 = axis.squaredNorm();
        if (!(length2 > 1e-24 * scale * scale)) continue;  // the loop skips it too
        const Interval i1 = project(first, axis), i2 = project(second, axis);
        const double gap = std::max(i2.min - i1.max, i1.min - i2.max);
        if (gap > 0.0 && gap * gap > 1e-24 * reach2 * length2) return true;
    }
    return false;
}

// How far a push may lean out along first's normal or into second's (the cosine with the unit
// normal) and still count as leaving the other's solid: 60 degrees from the face planes. A push
// along a face plane stays allowed at any rounding, and at a solid's convex edge the push that
// does separate leans into the plane of the face beside it by up to the edge's turn.
constexpr double kSolidPushSlack = 0.5;

// Which ways along an axis intersectTriangles may push `first` (the header's FaceSides):
// either way, or with `active` neither clearly out along n1 nor clearly against n2 (unit
// outward normals).
struct PushCone {
    bool active = false;
    Vec3 n1 = Vec3::Zero(), n2 = Vec3::Zero();
    // Along +axis, given axis . n1 and axis . n2; along -axis, the same with both negated.
    static bool allows(double along1, double along2) { return along1 <= kSolidPushSlack && along2 >= -kSolidPushSlack; }
};

// The separating-axis loop of intersectTriangles: over `axes` in order, skipping those shorter
// than `minLength2`, the smallest overlap and its axis (pointing the way `first` must move)
// among the ways `cone` allows; false when an axis separates the triangles.
bool smallestOverlap(const Triangle& first, const Triangle& second, std::span<const Vec3> axes, double minLength2,
                     const PushCone& cone, double& bestOverlap, Vec3& bestAxis) {
    for (Vec3 axis : axes) {
        const double length2 = axis.squaredNorm();
        if (!(length2 > minLength2)) continue;  // parallel edges: no axis
        axis /= std::sqrt(length2);
        const Interval i1 = project(first, axis), i2 = project(second, axis);
        const double pushUp = i2.max - i1.min;    // move first along +axis by this to separate
        const double pushDown = i1.max - i2.min;  // or along -axis by this
        if (pushUp < 0 || pushDown < 0) return false;  // separating axis
        bool up = true, down = true;
        if (cone.active) {
            const double along1 = axis.dot(cone.n1), along2 = axis.dot(cone.n2);
            up = PushCone::allows(along1, along2);
            down = PushCone::allows(-along1, -along2);
        }
        if (!up && !down) continue;
        const double overlap = !down ? pushUp : !up ? pushDown : std::min(pushUp, pushDown);
        if (overlap < bestOverlap) {
            bestOverlap = overlap;
            bestAxis = (up && (!down || pushUp <= pushDown)) ? axis : Vec3(-axis);
        }
    }
    return true;
}

#if defined(FLEXFIT_LANES256)
using namespace detail::lanes;

// std::min({a, b, c}) and std::max({a, b, c}) lane by lane, NaNs included (min_pd(x, y) is
// x < y ? x : y, as std::min's "b < smallest ? b : smallest").
FLEXFIT_AVX2_LANES inline __m256d min3(__m256d a, __m256d b, __m256d c) { return _mm256_min_pd(c, _mm256_min_pd(b, a)); }
FLEXFIT_AVX2_LANES inline __m256d max3(__m256d a, __m256d b, __m256d c) { return _mm256_max_pd(c, _mm256_max_pd(b, a)); }

// smallestOverlap four axes a vector: the square roots and the divisions that normalise the
// axes (the loop's costliest instructions in perf, on the stack scene's resting boxes) run in
// lanes, by the same operations in the same order, so each lane gives the scalar loop's bits;
// the smallest overlap is then taken lane by lane in the axes' order, as the loop takes it.
FLEXFIT_AVX2_LANES bool smallestOverlapFours(const Triangle& first, const Triangle& second, std::span<const Vec3> axes,
                                             double minLength2, const PushCone& cone, double& bestOverlap, Vec3& bestAxis) {
    const Lanes3 a1 = broadcast(first.a), b1 = broadcast(first.b), c1 = broadcast(first.c);
    const Lanes3 a2 = broadcast(second.a), b2 = broadcast(second.b), c2 = broadcast(second.c);
    const __m256d threshold = _mm256_set1_pd(minLength2), zero = _mm256_setzero_pd();
    const Vec3 none = Vec3::Zero();  // pads the last four: length 0, never an axis
    for (std::size_t k = 0; k < axes.size(); k += 4) {
        const Lanes3 axis = gather([&](int l) -> const Vec3& { return k + std::size_t(l) < axes.size() ? axes[k + std::size_t(l)] : none; });
        const __m256d length2 = dot(axis, axis);
        const __m256d valid = _mm256_cmp_pd(length2, threshold, _CMP_GT_OQ);
        // Lanes that are no axis divide by 1 (no 0 / 0: it would raise FE_INVALID).
        const Lanes3 unit = divide(axis, _mm256_blendv_pd(_mm256_set1_pd(1.0), _mm256_sqrt_pd(length2), valid));
        const __m256d pa1 = dot(a1, unit), pb1 = dot(b1, unit), pc1 = dot(c1, unit);
        const __m256d pa2 = dot(a2, unit), pb2 = dot(b2, unit), pc2 = dot(c2, unit);
        const __m256d pushUp = _mm256_sub_pd(max3(pa2, pb2, pc2), min3(pa1, pb1, pc1));
        const __m256d pushDown = _mm256_sub_pd(max3(pa1, pb1, pc1), min3(pa2, pb2, pc2));
        const __m256d separates = _mm256_and_pd(valid, _mm256_or_pd(_mm256_cmp_pd(pushUp, zero, _CMP_LT_OQ), _mm256_cmp_pd(pushDown, zero, _CMP_LT_OQ)));
        if (_mm256_movemask_pd(separates) != 0) return false;
        __m256d overlaps = _mm256_min_pd(pushDown, pushUp);  // std::min(pushUp, pushDown)
        __m256d upward = _mm256_cmp_pd(pushUp, pushDown, _CMP_LE_OQ);
        __m256d allowed = valid;
        if (cone.active) {  // PushCone::allows for +axis and -axis, then the loop's choice
            const __m256d tolerance = _mm256_set1_pd(kSolidPushSlack), minusTolerance = _mm256_set1_pd(-kSolidPushSlack);
            const __m256d along1 = dot(unit, broadcast(cone.n1)), along2 = dot(unit, broadcast(cone.n2));
            const __m256d up = _mm256_and_pd(_mm256_cmp_pd(along1, tolerance, _CMP_LE_OQ), _mm256_cmp_pd(along2, minusTolerance, _CMP_GE_OQ));
            const __m256d down = _mm256_and_pd(_mm256_cmp_pd(along1, minusTolerance, _CMP_GE_OQ), _mm256_cmp_pd(along2, tolerance, _CMP_LE_OQ));
            const __m256d both = _mm256_and_pd(up, down);
            overlaps = _mm256_blendv_pd(_mm256_blendv_pd(pushDown, pushUp, up), overlaps, both);
            upward = _mm256_blendv_pd(up, _mm256_and_pd(upward, up), both);
            allowed = _mm256_and_pd(valid, _mm256_or_pd(up, down));
        }
        alignas(32) double overlap[4], up[4];
        _mm256_store_pd(overlap, overlaps);
        _mm256_store_pd(up, upward);
        const int validLanes = _mm256_movemask_pd(allowed);
        const Stored3 units = store(unit);
        for (int l = 0; l < 4; ++l) {
            if ((validLanes >> l & 1) == 0 || !(overlap[l] < bestOverlap)) continue;
            bestOverlap = overlap[l];
            bestAxis = std::bit_cast<std::uint64_t>(up[l]) != 0 ? units[l] : Vec3(-units[l]);
        }
    }
    return true;
}
#endif

// smallestOverlap, four axes a vector where lanes run.
bool smallestOverlapByLanes(const Triangle& first, const Triangle& second, std::span<const Vec3> axes, double minLength2,
                            const PushCone& cone, double& bestOverlap, Vec3& bestAxis) {
#if defined(FLEXFIT_LANES256)
    if (detail::lanesEnabled()) return smallestOverlapFours(first, second, axes, minLength2, cone, bestOverlap, bestAxis);
#endif
    return smallestOverlap(first, second, axes, minLength2, cone, bestOverlap, bestAxis);
}

// Whether two face normals lie within 30 degrees of one line (either way).
bool nearlyParallel(const Vec3& n1, const Vec3& n2) {
    const double c = n1.dot(n2);
    return c * c > 0.75 * n1.squaredNorm() * n2.squaredNorm();  // cos^2(30 deg)
}

// Whether a push along `unit` leaves the cone of PushCone::allows, from the unnormalised face
// normals (no square root on the common path: a push that stays in the cone).
bool leavesCone(const Vec3& unit, const Vec3& n1, const Vec3& n2) {
    const double along1 = unit.dot(n1), along2 = unit.dot(n2);
    constexpr double slack2 = kSolidPushSlack * kSolidPushSlack;
    return (along1 > 0.0 && along1 * along1 > slack2 * n1.squaredNorm()) || (along2 < 0.0 && along2 * along2 > slack2 * n2.squaredNorm());
}

// Faces of solids (FaceSides::Solids) more than 30 degrees from parallel whose smallest push
// clearly leaves the cone (out along first's normal or into second): the smallest push within
// the cone instead, if it is short: within a tenth of the shorter of the two triangles' longest
// edges. A longer one is more likely a slide along a face than the solids' overlap (at a
// convex edge turned more than the slack, the push that separates leaves the cone of one of
// the faces), and the two-sided push stays.
void solidPush(const Triangle& first, const Triangle& second, std::span<const Vec3> axes, double minLength2, const Vec3& n1,
               const Vec3& n2, double& bestOverlap, Vec3& bestAxis) {
    const PushCone cone{true, n1.normalized(), n2.normalized()};
    auto longestEdge2 = [](const Triangle& t) { return std::max({(t.b - t.a).squaredNorm(), (t.c - t.b).squaredNorm(), (t.a - t.c).squaredNorm()}); };
    const double reach = 0.1 * std::sqrt(std::min(longestEdge2(first), longestEdge2(second)));
    double overlap = std::numeric_limits<double>::infinity();
    Vec3 axis = bestAxis;
    smallestOverlapByLanes(first, second, axes, minLength2, cone, overlap, axis);
    if (overlap <= reach) {
        bestOverlap = overlap;
        bestAxis = axis;
    }
}

// The deepest point of `t` behind the plane of `base` (unit outward normal `unit`) within the
// prism over `base` (its triangle swept along the normal): t clipped by the prism's three sides
// (Sutherland-Hodgman), then the clipped polygon's deepest corner. Depth > 0, or none.
struct Deepest {
    Vec3 point;
    double depth;
};
std::optional<Deepest> deepestBehind(const Triangle& t, const Triangle& base, const Vec3& unit) {
    PointSet polygon, clipped;
    for (const Vec3& v : {t.a, t.b, t.c}) polygon.push(v);
    const std::array<Vec3, 3> corners{base.a, base.b, base.c};
    for (std::size_t e = 0; e < 3 && polygon.count > 0; ++e) {
        const Vec3& p = corners[e];
        const Vec3 inward = unit.cross(corners[(e + 1) % 3] - p);  // counter-clockwise seen from outside
        clipped.count = 0;
        for (int i = 0; i < polygon.count; ++i) {
            const Vec3& x = polygon.points[std::size_t(i)];
            const Vec3& y = polygon.points[std::size_t((i + 1) % polygon.count)];
            const double dx = inward.dot(x - p), dy = inward.dot(y - p);
            if (dx >= 0.0) clipped.push(x);
            if ((dx >= 0.0) != (dy >= 0.0)) clipped.push(x + (dx / (dx - dy)) * (y - x));
        }
        polygon = clipped;
    }
    std::optional<Deepest> deepest;
    const double offset = unit.dot(base.a);
    for (int i = 0; i < polygon.count; ++i) {
        const Vec3& x = polygon.points[std::size_t(i)];
        const double depth = offset - unit.dot(x);
        if (depth > 0.0 && (!deepest || depth > deepest->depth)) deepest = Deepest{x, depth};
    }
    return deepest;
}

// Opposing faces of rigid solids within 30 degrees of parallel whose smallest push leaves the
// cone (it goes through the other face): the push back, out of the other's solid along one
// face's normal, by the depth of one triangle's deepest point behind the other within its
// prism, at the middle of that depth. Of first pushed along n2 and first pushed back along -n1
// (second's deepest point behind first), the shallower; none when neither reaches behind.
std::optional<TriangleContact> opposingFacesPush(const Triangle& first, const Triangle& second, const Vec3& n1, const Vec3& n2) {
    const Vec3 u1 = n1.normalized(), u2 = n2.normalized();
    const std::optional<Deepest> firstBehind = deepestBehind(first, second, u2), secondBehind = deepestBehind(second, first, u1);
    if (firstBehind && (!secondBehind || firstBehind->depth <= secondBehind->depth))
        return TriangleContact{firstBehind->point + (0.5 * firstBehind->depth) * u2, u2, firstBehind->depth};
    if (secondBehind) return TriangleContact{secondBehind->point + (0.5 * secondBehind->depth) * u1, Vec3(-u1), secondBehind->depth};
    return std::nullopt;
}

}  // namespace

Vec3 closestPointOnTriangle(const Vec3& p, const Triangle& t, TriangleFeature* feature) {
    TriangleFeature ignored;
    TriangleFeature& region = feature != nullptr ? *feature : ignored;
    auto found = [&region](TriangleFeature where, const Vec3& point) {
        region = where;
        return point;
    };
    const Vec3& a = t.a;
    const Vec3& b = t.b;
    const Vec3& c = t.c;
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    // Zero-area triangles have no face region: use the edges.
    if (!(ab.cross(ac).squaredNorm() > 1e-30 * std::max(ab.squaredNorm(), ac.squaredNorm()) * std::max(ab.squaredNorm(), ac.squaredNorm())))
        return closestPointOnEdges(p, t, region);
    // Vertex region A.
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return found(TriangleFeature::CornerA, a);
    // Vertex region B.
    const Vec3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return found(TriangleFeature::CornerB, b);
    // Edge region AB.
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return found(TriangleFeature::EdgeAB, a + (d1 / (d1 - d3)) * ab);
    // Vertex region C.
    const Vec3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return found(TriangleFeature::CornerC, c);
    // Edge region AC.
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return found(TriangleFeature::EdgeCA, a + (d2 / (d2 - d6)) * ac);
    // Edge region BC.
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        return found(TriangleFeature::EdgeBC, b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b));
    // Face region: barycentric coordinates (u, v, w).
    region = TriangleFeature::Interior;
    const double denominator = 1.0 / (va + vb + vc);
    return a + ab * (vb * denominator) + ac * (vc * denominator);
}

std::optional<TriangleContact> sphereTriangleContact(const Vec3& centre, double radius, const Triangle& t) {
    const Vec3 q = closestPointOnTriangle(centre, t);
    const Vec3 d = centre - q;
    const double distance2 = d.squaredNorm();
    if (distance2 > radius * radius) return std::nullopt;
    const double distance = std::sqrt(distance2);
    Vec3 normal = distance > 0.0 ? Vec3(d / distance) : (t.b - t.a).cross(t.c - t.a);
    if (distance == 0.0) {
        const double n = normal.norm();
        normal = n > 0.0 ? Vec3(normal / n) : Vec3::UnitY();
    }
    return TriangleContact{q, normal, radius - distance};
}

double triangleGap(const Triangle& first, const Triangle& second, double enough) {
    const std::array<Vec3, 3> e1{first.b - first.a, first.c - first.b, first.a - first.c};
    const std::array<Vec3, 3> e2{second.b - second.a, second.c - second.b, second.a - second.c};
    std::array<Vec3, 11> axes;
    axes[0] = e1[0].cross(-e1[2]);
    axes[1] = e2[0].cross(-e2[2]);
    std::size_t count = 2;
    for (const Vec3& a : e1)
        for (const Vec3& b : e2) axes[count++] = a.cross(b);
    // Projected on the axis as it is; only a separating axis wider than the best so far pays
    // for its length (squared comparison first, then the square root).
    double gap = 0.0;
    for (const Vec3& axis : axes) {
        const Interval i1 = project(first, axis), i2 = project(second, axis);
        const double apart = std::max(i2.min - i1.max, i1.min - i2.max);
        if (!(apart > 0.0)) continue;
        const double squaredLength = axis.squaredNorm();
        if (!(squaredLength > 0.0) || apart * apart <= gap * gap * squaredLength) continue;
        gap = apart / std::sqrt(squaredLength);
        if (gap > enough) break;
    }
    return gap;
}

std::optional<TriangleContact> intersectTriangles(const Triangle& first, const Triangle& second, FaceSides sides) {
    const std::array<Vec3, 3> e1{first.b - first.a, first.c - first.b, first.a - first.c};
    const std::array<Vec3, 3> e2{second.b - second.a, second.c - second.b, second.a - second.c};
    const Vec3 n1 = e1[0].cross(-e1[2]), n2 = e2[0].cross(-e2[2]);
    const double scale = std::max({e1[0].squaredNorm(), e1[1].squaredNorm(), e2[0].squaredNorm(), e2[1].squaredNorm()});
    // Quick rejection (Moller): a triangle strictly on one side of the other's plane. The
    // tolerance is far below any overlap the axes below would report.
    const double tolerance = 1e-12 * scale;
    if (strictlyOneSide(second, n1, n1.dot(first.a), tolerance * n1.norm()) ||
        strictlyOneSide(first, n2, n2.dot(second.a), tolerance * n2.norm()))
        return std::nullopt;
    std::array<Vec3, 17> axes;
    std::size_t axisCount = 0;
    axes[axisCount++] = n1;
    axes[axisCount++] = n2;
    for (const Vec3& a : e1)
        for (const Vec3& b : e2) axes[axisCount++] = a.cross(b);
    if (clearlyApartOnAnEdgeAxis(first, second, std::span<const Vec3>(axes).subspan(2, 9), scale)) return std::nullopt;
    const bool coplanar = n1.cross(n2).squaredNorm() <= 1e-24 * n1.squaredNorm() * n2.squaredNorm();
    if (coplanar)
        for (const auto* edges : {&e1, &e2})
            for (const Vec3& e : *edges) axes[axisCount++] = n1.cross(e);

    double bestOverlap = std::numeric_limits<double>::infinity();
    Vec3 bestAxis = Vec3::UnitY();
    const std::span<const Vec3> allAxes(axes.data(), axisCount);
    const double minLength2 = 1e-24 * scale * scale;
    if (!smallestOverlapByLanes(first, second, allAxes, minLength2, PushCone{}, bestOverlap, bestAxis)) return std::nullopt;
    if (sides != FaceSides::TwoSided && leavesCone(bestAxis, n1, n2)) {
        if (!nearlyParallel(n1, n2))
            solidPush(first, second, allAxes, minLength2, n1, n2, bestOverlap, bestAxis);
        else if (sides == FaceSides::RigidSolids && n1.dot(n2) < 0.0)
            if (const std::optional<TriangleContact> back = opposingFacesPush(first, second, n1, n2)) return back;
    }
    // Contact point: centroid of the edge-through-triangle intersection points.
    PointSet points;
    if (!coplanar) {
        const Vec3 u1 = n1.normalized(), u2 = n2.normalized();
        segmentTriangle(first.a, first.b, second, u2, points);
        segmentTriangle(first.b, first.c, second, u2, points);
        segmentTriangle(first.c, first.a, second, u2, points);
        segmentTriangle(second.a, second.b, first, u1, points);
        segmentTriangle(second.b, second.c, first, u1, points);
        segmentTriangle(second.c, second.a, first, u1, points);
    }
    if (points.count == 0) {
        // Coplanar (or grazing): the centroid of the vertices of each lying on the other.
        for (const Vec3& v : {first.a, first.b, first.c})
            if ((closestPointOnTriangle(v, second) - v).squaredNorm() <= 1e-20 * (1 + v.squaredNorm())) points.push(v);
        for (const Vec3& v : {second.a, second.b, second.c})
            if ((closestPointOnTriangle(v, first) - v).squaredNorm() <= 1e-20 * (1 + v.squaredNorm())) points.push(v);
    }
    if (points.count == 0) points.push((first.a + first.b + first.c + second.a + second.b + second.c) / 6.0);
    Vec3 point = Vec3::Zero();
    for (int i = 0; i < points.count; ++i) point += points.points[std::size_t(i)];
    point /= double(points.count);
    return TriangleContact{point, bestAxis, bestOverlap};
}

namespace {
double squaredDistance(const Aabb& box, const Vec3& p) {
    return (box.min - p).cwiseMax(p - box.max).cwiseMax(0.0).squaredNorm();
}
}  // namespace

ClosestFace closestFace(const Bvh<Aabb>& faceTree, std::span<const Vec3> vertices, std::span<const Face> faces, const Vec3& p) {
    ClosestFace best;
    best.squaredDistance = std::numeric_limits<double>::infinity();
    best.point = p;
    const auto& nodes = faceTree.nodes();
    if (nodes.empty()) return best;
    thread_local std::vector<std::int32_t> stack;
    stack.assign(1, 0);
    while (!stack.empty()) {
        const auto& node = nodes[std::size_t(stack.back())];
        stack.pop_back();
        if (squaredDistance(node.volume, p) >= best.squaredDistance) continue;
        if (node.isLeaf()) {
            const Face& f = faces[node.item];
            TriangleFeature feature;
            const Vec3 c = closestPointOnTriangle(p, {vertices[f[0]], vertices[f[1]], vertices[f[2]]}, &feature);
            const double d2 = (p - c).squaredNorm();
            if (d2 < best.squaredDistance) best = {node.item, c, feature, d2};
            continue;
        }
        const double dl = squaredDistance(nodes[std::size_t(node.left)].volume, p);
        const double dr = squaredDistance(nodes[std::size_t(node.right)].volume, p);
        // Nearer child on top of the stack.
        if (dl < dr) {
            stack.push_back(node.right);
            stack.push_back(node.left);
        } else {
            stack.push_back(node.left);
            stack.push_back(node.right);
        }
    }
    return best;
}

}  // namespace flexfit
