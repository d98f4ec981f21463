#include "flexfit/distance_field.hpp"
#include "core/fnv1a.hpp"
#include "core/parallel.hpp"
#include "flexfit/collision.hpp"
#include "collision/sampling_kernel.hpp"
#include "collision/triangle_queries.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#if defined(__x86_64__) && defined(__GNUC__)
#define FLEXFIT_SDF_AVX2 1
#include <immintrin.h>
#endif

namespace flexfit {
namespace {

// Nodes computed when the field is built: those within this many cells of a face's box.
constexpr int kBandCells = 6;

double angleAt(const Vec3& corner, const Vec3& u, const Vec3& v) {
    return std::atan2((u - corner).cross(v - corner).norm(), (u - corner).dot(v - corner));
}

}  // namespace

SignedDistanceField::SignedDistanceField(const TriMesh& mesh, const Topology& topology, double cellSize)
    : vertices_(mesh.vertices), faces_(mesh.faces) {
    if (faces_.empty()) throw std::invalid_argument("signed distance field: the mesh has no faces");
    const Aabb meshBox = Aabb::around(vertices_);
    const double extent = (meshBox.max - meshBox.min).maxCoeff();
    if (std::isnan(cellSize) || cellSize > extent)  // <= 0: the default, from the mesh's edges
        throw std::invalid_argument("signed distance field: the cell size " + std::to_string(cellSize) +
                                    " must be at most the mesh's extent " + std::to_string(extent) + " (or <= 0: chosen from the edges)");
    switch (solidDefect(vertices_, faces_, topology)) {
    case SolidDefect::None: break;
    case SolidDefect::Open: throw std::invalid_argument("signed distance field: the mesh '" + mesh.name + "' is not closed and manifold");
    case SolidDefect::Inconsistent:
        throw std::invalid_argument("signed distance field: the faces of '" + mesh.name + "' are not consistently oriented");
    case SolidDefect::InsideOut:
        throw std::invalid_argument("signed distance field: the mesh '" + mesh.name + "' is inside out (negative volume)");
    }
    faceNormal_.resize(faces_.size());
    vertexNormal_.assign(vertices_.size(), Vec3::Zero());
    double edgeSum = 0.0;
    for (std::size_t f = 0; f < faces_.size(); ++f) {
        const Face& face = faces_[f];
        const Vec3 &a = vertices_[face[0]], &b = vertices_[face[1]], &c = vertices_[face[2]];
        faceNormal_[f] = (b - a).cross(c - a).normalized();
        for (int k = 0; k < 3; ++k) {
            const Vec3& corner = vertices_[face[k]];
            vertexNormal_[face[k]] += angleAt(corner, vertices_[face[(k + 1) % 3]], vertices_[face[(k + 2) % 3]]) * faceNormal_[f];
            edgeSum += (vertices_[face[(k + 1) % 3]] - corner).norm();
        }
    }
    for (Vec3& n : vertexNormal_) n.normalize();
    // Edge pseudonormal: the sum of the normals of the two faces sharing it.
    edgeNormal_.resize(faces_.size());
    for (std::size_t f = 0; f < faces_.size(); ++f)
        for (int e = 0; e < 3; ++e) {
            const Index u = faces_[f][std::size_t(e)], v = faces_[f][std::size_t(e + 1) % 3];
            Vec3 sum = faceNormal_[f];
            for (Index g : topology.facesOf(u)) {
                const Face& other = faces_[g];
                if (g != f && (other[0] == v || other[1] == v || other[2] == v)) sum += faceNormal_[g];
            }
            edgeNormal_[f][std::size_t(e)] = sum.normalized();
        }
    std::vector<Aabb> leaves(faces_.size());
    for (std::size_t f = 0; f < faces_.size(); ++f) leaves[f] = faceBox(vertices_, faces_[f]);
    bvh_.build(leaves);

    setUpGrid(fine_, cellSize > 0.0 ? cellSize : 0.125 * edgeSum / double(3 * faces_.size()), std::size_t(1) << 21);
    fillBand(fine_, kBandCells);
    markOutside(fine_, kBandCells);
    setUpGrid(coarse_, 8.0 * fine_.cell, std::size_t(1) << 15);
    std::vector<std::size_t> every(coarse_.values.size());
    std::iota(every.begin(), every.end(), std::size_t(0));
    fillNodes(coarse_, every);
}

// The mesh's box grown by two cells, at most about maxNodes nodes.
void SignedDistanceField::setUpGrid(Grid& grid, double cell, std::size_t maxNodes) const {
    const Aabb meshBox = Aabb::around(vertices_);
    for (;;) {
        grid.box = {meshBox.min - Vec3::Constant(2.0 * cell), meshBox.max + Vec3::Constant(2.0 * cell)};
        double nodes = 1.0;
        for (int d = 0; d < 3; ++d) {
            const double count = std::ceil((grid.box.max[d] - grid.box.min[d]) / cell) + 1.0;
            grid.dims[std::size_t(d)] = int(std::min(count, double(maxNodes)));  // the loop grows the cell when too many
            nodes *= count;
        }
        if (nodes <= double(maxNodes)) break;
        if (!std::isfinite(nodes)) {  // a cell so small the count overflows: start from one that fits
            cell = (meshBox.max - meshBox.min).maxCoeff() / std::cbrt(double(maxNodes));
            continue;
        }
        cell *= std::cbrt(nodes / double(maxNodes)) * 1.01;
    }
    grid.cell = cell;
    for (int d = 0; d < 3; ++d) grid.box.max[d] = grid.box.min[d] + cell * (grid.dims[std::size_t(d)] - 1);
    grid.roundingReach = 1e-6 * (grid.box.max - grid.box.min).norm();
    // Not computed yet, and "maybe inside" (the sign bit set) until markOutside says otherwise:
    // lowerBound gives no bound for such a node on any grid.
    grid.values.assign(std::size_t(grid.dims[0]) * std::size_t(grid.dims[1]) * std::size_t(grid.dims[2]),
                       std::copysign(std::numeric_limits<float>::quiet_NaN(), -1.0f));
}

// The nodes within `cells` of a face's box, marked first, then computed together.
void SignedDistanceField::fillBand(Grid& grid, int cells) const {
    std::vector<char> inBand(grid.values.size(), 0);
    for (const Face& f : faces_) {
        const Aabb box = faceBox(vertices_, f);
        int lo[3], hi[3];
        for (int d = 0; d < 3; ++d) {
            lo[d] = std::max(0, int(std::floor((box.min[d] - grid.box.min[d]) / grid.cell)) - cells);
            hi[d] = std::min(grid.dims[std::size_t(d)] - 1, int(std::ceil((box.max[d] - grid.box.min[d]) / grid.cell)) + cells);
        }
        for (int k = lo[2]; k <= hi[2]; ++k)
            for (int j = lo[1]; j <= hi[1]; ++j)
                for (int i = lo[0]; i <= hi[0]; ++i) inBand[&grid.node(i, j, k) - grid.values.data()] = 1;
    }
    std::vector<std::size_t> nodes;
    for (std::size_t n = 0; n < inBand.size(); ++n)
        if (inBand[n]) nodes.push_back(n);
    fillNodes(grid, nodes);
}

// The nodes left out of the band lie more than `cells` cells from every face's box, so their
// distance exceeds that; their sign is found without a query: those joined to the grid's
// border through nodes out of the band (6-neighbours) lie outside the mesh, since a path that
// crossed the surface would pass through the band. They become NaN with the sign bit clear;
// the others (inside, or outside in a pocket the band closes off) keep setUpGrid's NaN with it
// set, which lowerBound reads as "no bound".
void SignedDistanceField::markOutside(Grid& grid, int cells) {
    grid.unfilledReach = double(cells) * grid.cell;
    const float outside = std::copysign(std::numeric_limits<float>::quiet_NaN(), 1.0f);
    const int nx = grid.dims[0], ny = grid.dims[1], nz = grid.dims[2];
    std::vector<std::array<int, 3>> open;
    const auto reach = [&](int i, int j, int k) {
        if (i < 0 || j < 0 || k < 0 || i >= nx || j >= ny || k >= nz) return;
        float& v = grid.node(i, j, k);
        if (!std::isnan(v) || !std::signbit(v)) return;
        v = outside;
        open.push_back({i, j, k});
    };
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                if (i == 0 || j == 0 || k == 0 || i == nx - 1 || j == ny - 1 || k == nz - 1) reach(i, j, k);
    while (!open.empty()) {
        const auto [i, j, k] = open.back();
        open.pop_back();
        reach(i - 1, j, k), reach(i + 1, j, k), reach(i, j - 1, k), reach(i, j + 1, k), reach(i, j, k - 1), reach(i, j, k + 1);
    }
}

// Each node's value is its exact distance alone (query() only reads the mesh and its
// hierarchy), so the nodes are computed on every usable core, in chunks, each into its own
// float: the same grid on any number of cores. ~1 M band nodes at 1-3 us each made a field
// of a 5,000-20,000-face part take 1-2 s to build on one core.
void SignedDistanceField::fillNodes(Grid& grid, std::span<const std::size_t> nodes) const {
    const std::size_t dx = std::size_t(grid.dims[0]), dxy = dx * std::size_t(grid.dims[1]);
    detail::forChunks(nodes.size(), 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t n = begin; n < end; ++n) {
            const std::size_t node = nodes[n];
            fill(grid, int(node % dx), int(node % dxy / dx), int(node / dxy));
        }
    });
}

void SignedDistanceField::fill(Grid& grid, int i, int j, int k) const {
    float& v = grid.node(i, j, k);
    if (!std::isnan(v)) return;
    v = float(query(grid.box.min + grid.cell * Vec3(i, j, k)).distance);
}

SignedDistanceField::Sample SignedDistanceField::query(const Vec3& p) const {
    const ClosestFace nearest = closestFace(bvh_, vertices_, faces_, p);
    const Index bestFace = nearest.face;
    const TriangleFeature closestFeature = nearest.feature;
    const Vec3& closest = nearest.point;
    const double best = nearest.squaredDistance;
    const Face& f = faces_[bestFace];
    // Pseudonormal of the closest feature (TriangleFeature numbers corners 0..2, edges 3..5).
    const int feature = int(closestFeature);
    const Vec3 pseudo = closestFeature == TriangleFeature::Interior ? faceNormal_[bestFace]
                        : feature >= int(TriangleFeature::EdgeAB)
                            ? edgeNormal_[bestFace][std::size_t(feature - int(TriangleFeature::EdgeAB))]
                            : vertexNormal_[f[std::size_t(feature)]];
    const Vec3 offset = p - closest;
    const double distance = std::sqrt(best);
    Sample s;
    s.closest = closest;
    s.distance = offset.dot(pseudo) < 0.0 ? -distance : distance;
    // Away from the surface the offset gives the normal; on it, the pseudonormal.
    s.normal = distance > 1e-12 * fine_.cell ? Vec3(offset / s.distance) : pseudo;
    return s;
}

SignedDistanceField::Cell SignedDistanceField::cellAt(Grid& grid, const Vec3& p, bool fillMissing) const {
    const Vec3 g = (p - grid.box.min) / grid.cell;
    int base[3];
    Cell cell;
    for (int d = 0; d < 3; ++d) {
        // Clamped as a double first: a far point must not overflow the int, a NaN one reads cell 0.
        const double lower = std::floor(g[d]);
        base[d] = lower > 0.0 ? int(std::min(lower, double(grid.dims[std::size_t(d)] - 2))) : 0;
        cell.t[d] = std::clamp(g[d] - base[d], 0.0, 1.0);
    }
    const std::size_t sx = 1, sy = std::size_t(grid.dims[0]), sz = sy * std::size_t(grid.dims[1]);
    const float* c = &grid.node(base[0], base[1], base[2]);
    // The 8 corners, x fastest.
    const std::size_t offset[8] = {0, sx, sy, sx + sy, sz, sz + sx, sz + sy, sz + sx + sy};
    for (int n = 0; n < 8; ++n) {
        if (fillMissing && std::isnan(c[offset[n]])) fill(grid, base[0] + (n & 1), base[1] + ((n >> 1) & 1), base[2] + ((n >> 2) & 1));
        cell.v[n] = c[offset[n]];
    }
    return cell;
}

SignedDistanceField::Interpolated SignedDistanceField::interpolate(const Cell& cell, double cellSize, bool withGradient) {
    const double(&v)[8] = cell.v;
    const double(&t)[3] = cell.t;
    const double x0 = 1.0 - t[0], y0 = 1.0 - t[1], z0 = 1.0 - t[2];
    // Along x, then y, then z.
    const double a00 = x0 * v[0] + t[0] * v[1], a10 = x0 * v[2] + t[0] * v[3];
    const double a01 = x0 * v[4] + t[0] * v[5], a11 = x0 * v[6] + t[0] * v[7];
    const double b0 = y0 * a00 + t[1] * a10, b1 = y0 * a01 + t[1] * a11;
    Interpolated out;
    out.distance = z0 * b0 + t[2] * b1;
    if (!withGradient) return out;
    const double dx00 = v[1] - v[0], dx10 = v[3] - v[2], dx01 = v[5] - v[4], dx11 = v[7] - v[6];
    out.gradient.x() = (z0 * (y0 * dx00 + t[1] * dx10) + t[2] * (y0 * dx01 + t[1] * dx11)) / cellSize;
    out.gradient.y() = (z0 * (a10 - a00) + t[2] * (a11 - a01)) / cellSize;
    out.gradient.z() = (b1 - b0) / cellSize;
    return out;
}

SignedDistanceField::Interpolated SignedDistanceField::sample(Grid& grid, const Vec3& p) const {
    return interpolate(cellAt(grid, p, true), grid.cell, true);
}

double SignedDistanceField::lowerBound(Grid& grid, const Vec3& p) const {
    Cell cell = cellAt(grid, p, false);
    for (double& v : cell.v) {
        if (!std::isnan(v)) continue;
        if (std::signbit(v)) return -std::numeric_limits<double>::infinity();  // maybe inside: no bound
        v = grid.unfilledReach;
    }
    // Each product has a weight >= 0 and each rounding is monotonic: a lower corner value never
    // raises the result.
    return interpolate(cell, grid.cell, false).distance;
}

SignedDistanceField::Interpolated SignedDistanceField::sample(const Vec3& p) const { return sample(fine_, p); }

std::size_t SignedDistanceField::computedNodes() const {
    return std::size_t(std::count_if(fine_.values.begin(), fine_.values.end(), [](float v) { return !std::isnan(v); }));
}

std::uint64_t SignedDistanceField::gridHash() const {
    detail::Fnv1a hash;
    for (const Grid* grid : {&fine_, &coarse_}) hash.mix(grid->values.data(), grid->values.size() * sizeof(float));
    return hash.value();
}

#if defined(FLEXFIT_SDF_AVX2)
namespace {

#define FLEXFIT_AVX2 __attribute__((target("avx2")))

// Lanes of doubles as GCC vector types (the intrinsics' __m256d and __m512d, without their
// may_alias attribute, which a template argument would drop).
using Doubles4 = double __attribute__((vector_size(32)));
using Doubles8 = double __attribute__((vector_size(64)));

// A sample's distance and gradient, as lanes.
template <class V>
struct LaneSamples {
    V distance, gx, gy, gz;
};

// sample()'s interpolation of the corner values v (x fastest) at the fractions t, and its
// gradient, for V = Doubles4 or Doubles8: GCC vector types, whose + - * / are each lane's
// correctly rounded operation (never fused: -ffp-contract=off), so every lane gives sample()'s
// bits. Inlined into sampleFour and sampleEight, whose targets give it their instructions.
template <class V>
[[gnu::always_inline]] inline void interpolateLanes(const V (&v)[8], const V (&t)[3], const V& cell, LaneSamples<V>& out) {
    const V x0 = 1.0 - t[0], y0 = 1.0 - t[1], z0 = 1.0 - t[2];
    // Along x, then y, then z; each w0 a + w1 b with both products rounded, then the sum.
    const V a00 = x0 * v[0] + t[0] * v[1], a10 = x0 * v[2] + t[0] * v[3];
    const V a01 = x0 * v[4] + t[0] * v[5], a11 = x0 * v[6] + t[0] * v[7];
    const V b0 = y0 * a00 + t[1] * a10, b1 = y0 * a01 + t[1] * a11;
    out.distance = z0 * b0 + t[2] * b1;
    const V dx00 = v[1] - v[0], dx10 = v[3] - v[2], dx01 = v[5] - v[4], dx11 = v[7] - v[6];
    out.gx = (z0 * (y0 * dx00 + t[1] * dx10) + t[2] * (y0 * dx01 + t[1] * dx11)) / cell;
    out.gy = (z0 * (a10 - a00) + t[2] * (a11 - a01)) / cell;
    out.gz = (b1 - b0) / cell;
}

// What the vector sampler needs of a grid, as lanes.
struct GridLanes {
    __m256d min[3], hi[3], cell;
    __m128i dx, dy;
    const float* values;
};

FLEXFIT_AVX2 __m256d lanesOf(const Vec3* p, int d) { return _mm256_set_pd(p[3][d], p[2][d], p[1][d], p[0][d]); }

// std::clamp(v, lo, hi) for v not NaN and lo <= hi.
FLEXFIT_AVX2 __m256d clampLanes(__m256d v, __m256d lo, __m256d hi) {
    return _mm256_blendv_pd(_mm256_blendv_pd(v, hi, _mm256_cmp_pd(hi, v, _CMP_LT_OQ)), lo, _mm256_cmp_pd(v, lo, _CMP_LT_OQ));
}

// Four points' samples as sample(Grid&, p) computes them, lane by lane; false (nothing
// written) when a corner is not computed yet.
FLEXFIT_AVX2 bool sampleFour(const GridLanes& g, const Vec3* p, SignedDistanceField::Interpolated* out) {
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
    Doubles4 t[3];
    __m128i base[3];
    for (int d = 0; d < 3; ++d) {
        const __m256d x = _mm256_div_pd(_mm256_sub_pd(lanesOf(p, d), g.min[d]), g.cell);
        base[d] = _mm256_cvttpd_epi32(clampLanes(_mm256_floor_pd(x), zero, g.hi[d]));
        // As sample(): minus the int converted back (+0.0 where the floor was -0.0).
        t[d] = clampLanes(_mm256_sub_pd(x, _mm256_cvtepi32_pd(base[d])), zero, one);
    }
    const __m128i node =
        _mm_add_epi32(_mm_mullo_epi32(_mm_add_epi32(_mm_mullo_epi32(base[2], g.dy), base[1]), g.dx), base[0]);
    const __m128i sy = g.dx, sz = _mm_mullo_epi32(g.dx, g.dy), sx = _mm_set1_epi32(1);
    const __m128i offset[8] = {_mm_setzero_si128(), sx, sy, _mm_add_epi32(sx, sy), sz, _mm_add_epi32(sz, sx), _mm_add_epi32(sz, sy),
                               _mm_add_epi32(_mm_add_epi32(sz, sx), sy)};
    // Corners n and n + 1 (x and x + 1) are adjacent floats: one 64-bit gather fetches both,
    // half the elements of gathering each (the same values, so the same bits).
    Doubles4 v[8];
    __m256d unknown = zero;
    const __m256i evensThenOdds = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
    for (int n = 0; n < 8; n += 2) {
        const __m256 pairs = _mm256_permutevar8x32_ps(
            _mm256_castpd_ps(_mm256_mask_i32gather_pd(zero, reinterpret_cast<const double*>(g.values), _mm_add_epi32(node, offset[n]),
                                                      _mm256_castsi256_pd(_mm256_set1_epi64x(-1)), 4)),
            evensThenOdds);
        v[n] = _mm256_cvtps_pd(_mm256_castps256_ps128(pairs));
        v[n + 1] = _mm256_cvtps_pd(_mm256_extractf128_ps(pairs, 1));
        unknown = _mm256_or_pd(unknown, _mm256_or_pd(_mm256_cmp_pd(v[n], v[n], _CMP_UNORD_Q), _mm256_cmp_pd(v[n + 1], v[n + 1], _CMP_UNORD_Q)));
    }
    if (_mm256_movemask_pd(unknown) != 0) return false;
    LaneSamples<Doubles4> s;
    interpolateLanes(v, t, g.cell, s);
    alignas(32) double lanes[4][4];
    _mm256_store_pd(lanes[0], s.distance);
    _mm256_store_pd(lanes[1], s.gx);
    _mm256_store_pd(lanes[2], s.gy);
    _mm256_store_pd(lanes[3], s.gz);
    for (int i = 0; i < 4; ++i) {
        out[i].distance = lanes[0][i];
        out[i].gradient = Vec3(lanes[1][i], lanes[2][i], lanes[3][i]);
    }
    return true;
}

// The whole groups of four of `points`, by sampleFour; a group with a corner not computed
// yet goes to one(k) point by point. Returns the points done.
template <class One>
FLEXFIT_AVX2 std::size_t sampleFours(const Vec3& min, const std::array<int, 3>& dims, double cell, const float* values,
                                     std::span<const Vec3> points, std::span<SignedDistanceField::Interpolated> out, One one) {
    GridLanes g;
    for (int d = 0; d < 3; ++d) {
        g.min[d] = _mm256_set1_pd(min[d]);
        g.hi[d] = _mm256_set1_pd(double(dims[std::size_t(d)] - 2));
    }
    g.cell = _mm256_set1_pd(cell);
    g.dx = _mm_set1_epi32(dims[0]);
    g.dy = _mm_set1_epi32(dims[1]);
    g.values = values;
    std::size_t i = 0;
    for (; i + 4 <= points.size(); i += 4)
        if (!sampleFour(g, &points[i], &out[i]))
            for (std::size_t k = i; k < i + 4; ++k) one(k);
    return i;
}

// ---------------------------------------------------------------- AVX-512: eight a vector
// sampleFour's operations in 8 lanes (the same instructions' 512-bit forms, each correctly
// rounded as before, no fused multiply-add: the same bits).
#define FLEXFIT_AVX512 __attribute__((target("avx512f")))
// GCC 12's AVX-512 intrinsics seed results with _mm512_undefined_pd() (`__m512d __Y = __Y;`),
// which -W(maybe-)uninitialized reports at inlined calls: a known false positive.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"

struct GridLanes8 {
    __m512d min[3], hi[3], cell;
    __m256i dx, dy;
    const float* values;
};

// Coordinate d of 8 consecutive points (24 doubles apart by 3).
FLEXFIT_AVX512 inline __m512d lanesOf8(const Vec3* p, int d) {
    return _mm512_i32gather_pd(_mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21), &p[0][d], 8);
}

FLEXFIT_AVX512 inline __m512d clampLanes8(__m512d v, __m512d lo, __m512d hi) {
    const __m512d high = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(hi, v, _CMP_LT_OQ), v, hi);
    return _mm512_mask_blend_pd(_mm512_cmp_pd_mask(v, lo, _CMP_LT_OQ), high, lo);
}

FLEXFIT_AVX512 bool sampleEight(const GridLanes8& g, const Vec3* p, SignedDistanceField::Interpolated* out) {
    const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0);
    Doubles8 t[3];
    __m256i base[3];
    for (int d = 0; d < 3; ++d) {
        const __m512d x = _mm512_div_pd(_mm512_sub_pd(lanesOf8(p, d), g.min[d]), g.cell);
        base[d] = _mm512_cvttpd_epi32(clampLanes8(_mm512_roundscale_pd(x, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC), zero, g.hi[d]));
        t[d] = clampLanes8(_mm512_sub_pd(x, _mm512_cvtepi32_pd(base[d])), zero, one);
    }
    const __m256i node =
        _mm256_add_epi32(_mm256_mullo_epi32(_mm256_add_epi32(_mm256_mullo_epi32(base[2], g.dy), base[1]), g.dx), base[0]);
    const __m256i sy = g.dx, sz = _mm256_mullo_epi32(g.dx, g.dy), sx = _mm256_set1_epi32(1);
    const __m256i offset[8] = {_mm256_setzero_si256(), sx, sy, _mm256_add_epi32(sx, sy), sz, _mm256_add_epi32(sz, sx),
                               _mm256_add_epi32(sz, sy), _mm256_add_epi32(_mm256_add_epi32(sz, sx), sy)};
    // Corners n and n + 1 (x and x + 1) are adjacent floats: one 64-bit gather fetches both,
    // half the elements of gathering each (the same values, so the same bits).
    Doubles8 v[8];
    __mmask8 unknown = 0;
    const __m512i evens = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 0, 0, 0, 0, 0, 0, 0, 0);
    const __m512i odds = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 0, 0, 0, 0, 0, 0, 0, 0);
    for (int n = 0; n < 8; n += 2) {
        const __m512 pairs = _mm512_castpd_ps(_mm512_i32gather_pd(_mm256_add_epi32(node, offset[n]), g.values, 4));
        v[n] = _mm512_cvtps_pd(_mm512_castps512_ps256(_mm512_permutexvar_ps(evens, pairs)));
        v[n + 1] = _mm512_cvtps_pd(_mm512_castps512_ps256(_mm512_permutexvar_ps(odds, pairs)));
        unknown |= _mm512_cmp_pd_mask(v[n], v[n], _CMP_UNORD_Q) | _mm512_cmp_pd_mask(v[n + 1], v[n + 1], _CMP_UNORD_Q);
    }
    if (unknown != 0) return false;
    LaneSamples<Doubles8> s;
    interpolateLanes(v, t, g.cell, s);
    // Interpolated is 4 doubles (distance, gradient): each point's as lane i of the 4 vectors.
    static_assert(sizeof(SignedDistanceField::Interpolated) == 4 * sizeof(double));
    const __m512i at = _mm512_setr_epi64(0, 4, 8, 12, 16, 20, 24, 28);
    double* o = &out[0].distance;
    _mm512_i64scatter_pd(o, at, s.distance, 8);
    _mm512_i64scatter_pd(o + 1, at, s.gx, 8);
    _mm512_i64scatter_pd(o + 2, at, s.gy, 8);
    _mm512_i64scatter_pd(o + 3, at, s.gz, 8);
    return true;
}

template <class One>
FLEXFIT_AVX512 std::size_t sampleEights(const Vec3& min, const std::array<int, 3>& dims, double cell, const float* values,
                                        std::span<const Vec3> points, std::span<SignedDistanceField::Interpolated> out, One one) {
    GridLanes8 g;
    for (int d = 0; d < 3; ++d) {
        g.min[d] = _mm512_set1_pd(min[d]);
        g.hi[d] = _mm512_set1_pd(double(dims[std::size_t(d)] - 2));
    }
    g.cell = _mm512_set1_pd(cell);
    g.dx = _mm256_set1_epi32(dims[0]);
    g.dy = _mm256_set1_epi32(dims[1]);
    g.values = values;
    std::size_t i = 0;
    for (; i + 8 <= points.size(); i += 8)
        if (!sampleEight(g, &points[i], &out[i]))
            for (std::size_t k = i; k < i + 8; ++k) one(k);
    return i;
}
#pragma GCC diagnostic pop

}  // namespace
#endif

// The value the sample at a ball's centre must exceed for no point of the ball to sample <= 0,
// the centre `outside` the grid by that much (clamped into it). Two bounds on how far the
// sample can fall over the ball: the interpolant's slope (sqrt(3) per unit), or the exact
// distance's (1 per unit) plus the sample's error at both ends (sqrt(3) cells each). The float
// node values' rounding (relative 6e-8) is covered by roundingReach, the double arithmetic's
// by the factor 1 + 1e-9.
std::pair<Vec3, double> SignedDistanceField::clampedInto(const Grid& grid, const Vec3& p) {
    const Vec3 clamped = p.cwiseMax(grid.box.min).cwiseMin(grid.box.max);
    return {clamped, clamped == p ? 0.0 : (p - clamped).norm()};
}

double SignedDistanceField::clearReach(const Grid& grid, double radius, double outside, double slack) {
    const double fall = std::min(std::sqrt(3.0) * (radius + outside), radius + outside + 2.0 * std::sqrt(3.0) * grid.cell);
    return fall * (1.0 + 1e-9) + slack + grid.roundingReach;
}

bool SignedDistanceField::clearOf(const Vec3& centre, double radius) const {
    if (radius > 2.0 * fine_.cell) {
        // Large balls first on the coarse grid, with both grids' sample errors as slack.
        // The fine grid's box lies inside the coarse one's, so "outside the coarse grid" also
        // means "outside the fine one".
        const auto [clamped, outside] = clampedInto(coarse_, centre);
        if (outside > radius) return true;  // wholly outside the grid, where nothing is sampled
        const double gap = std::sqrt(3.0) * (coarse_.cell + fine_.cell);
        const double coarse = lowerBound(coarse_, clamped);  // every coarse node is computed when built: the sample itself
        if (coarse > clearReach(coarse_, radius, outside, gap)) return true;
        // The fine sample exceeds the coarse one by at most `gap` and both grids' rounding.
        // Where even that cannot clear the ball, the answer is no without the fine sample: at
        // the top of a point-shell walk those samples fall far apart in the fine grid, a cache
        // miss each. The answer is the same either way. (Inside the fine grid both grids
        // sample the centre itself: the coarse box holds the fine one.)
        const double ceiling = coarse + gap * (1.0 + 1e-9) + coarse_.roundingReach + fine_.roundingReach;
        if (inGrid(centre) && ceiling <= clearReach(fine_, radius, 0.0, 0.0)) return false;
    }
    const auto [clamped, outside] = clampedInto(fine_, centre);
    if (outside > radius) return true;
    return lowerBound(fine_, clamped) > clearReach(fine_, radius, outside, 0.0);
}

namespace detail {
namespace {
std::atomic<int> scalarSamplingScopes{0};  // ScopedScalarSampling: alive, nested or on other threads
std::atomic<int> fourLaneSamplingScopes{0};  // ScopedFourLaneSampling
}  // namespace

bool vectorSamplingEnabled() {
#if defined(FLEXFIT_SDF_AVX2)
    static const bool avx2 = __builtin_cpu_supports("avx2");
    return avx2 && scalarSamplingScopes.load(std::memory_order_relaxed) == 0;
#else
    return false;
#endif
}

bool eightLaneSamplingEnabled() {
#if defined(FLEXFIT_SDF_AVX2)
    static const bool avx512 = __builtin_cpu_supports("avx512f");
    return avx512 && vectorSamplingEnabled() && fourLaneSamplingScopes.load(std::memory_order_relaxed) == 0;
#else
    return false;
#endif
}

ScopedScalarSampling::ScopedScalarSampling() { scalarSamplingScopes.fetch_add(1, std::memory_order_relaxed); }
ScopedScalarSampling::~ScopedScalarSampling() { scalarSamplingScopes.fetch_sub(1, std::memory_order_relaxed); }
ScopedFourLaneSampling::ScopedFourLaneSampling() { fourLaneSamplingScopes.fetch_add(1, std::memory_order_relaxed); }
ScopedFourLaneSampling::~ScopedFourLaneSampling() { fourLaneSamplingScopes.fetch_sub(1, std::memory_order_relaxed); }
}  // namespace detail

// The points' samples into `out`, each lane by the vector kernels where every corner of its
// group is computed, else one(k) for point k (also for the points the kernels leave over).
template <class One>
void SignedDistanceField::sampleEach(std::span<const Vec3> points, std::span<Interpolated> out, One one) const {
    std::size_t i = 0;
#if defined(FLEXFIT_SDF_AVX2)
    if (detail::vectorSamplingEnabled()) {
        const std::size_t eights = detail::eightLaneSamplingEnabled() ? sampleEights(fine_.box.min, fine_.dims, fine_.cell, fine_.values.data(), points, out, one) : 0;
        i = eights + sampleFours(fine_.box.min, fine_.dims, fine_.cell, fine_.values.data(), points.subspan(eights), out.subspan(eights),
                                 [&](std::size_t k) { one(eights + k); });
    }
#endif
    for (; i < points.size(); ++i) one(i);
}

void SignedDistanceField::sampleMany(std::span<const Vec3> points, std::span<Interpolated> out) const {
    if (out.size() < points.size())
        throw std::invalid_argument("signed distance field: sampleMany needs an output per point (" + std::to_string(points.size()) +
                                    " points, " + std::to_string(out.size()) + " outputs)");
    sampleEach(points, out, [&](std::size_t k) { out[k] = sample(fine_, points[k]); });
}

void SignedDistanceField::sampleLowerBounds(std::span<const Vec3> points, std::span<double> out) const {
    if (out.size() < points.size())
        throw std::invalid_argument("signed distance field: sampleLowerBounds needs an output per point (" + std::to_string(points.size()) +
                                    " points, " + std::to_string(out.size()) + " outputs)");
    thread_local std::vector<Interpolated> samples;  // the kernels' lanes (their gradients unused)
    samples.resize(points.size());
    sampleEach(points, std::span<Interpolated>(samples), [&](std::size_t k) { samples[k].distance = lowerBound(fine_, points[k]); });
    for (std::size_t k = 0; k < points.size(); ++k) out[k] = samples[k].distance;
}

}  // namespace flexfit
