// Signed distance to a closed triangle mesh: exact queries, and a lazily filled grid of them
// that bounds the distance cheaply. The narrow phase's point-shell query (collision.hpp) tests
// the masses of a deformable part against the field of a rigid part, as point-shell haptic
// rendering does (McNeely et al. 1999, voxel-point shells), but with exact distances.
//
// query(p): the closest point on the mesh (a face hierarchy searched depth-first, nearer child
// first, pruned by box distance) and the sign from the angle-weighted pseudonormal of the
// closest feature (Baerentzen and Aanaes 2005): face normal, edge normal (sum of its two face
// normals) or vertex normal (incident face normals weighted by their angles). Exact for a
// closed, manifold, consistently and outward oriented mesh; the constructor throws
// std::invalid_argument for an edge not shared by exactly two faces, two faces using an edge
// in the same direction, or a negative enclosed volume. (A vertex where two surface sheets
// touch passes these checks and may give a wrong sign next to it.)
//
// sample(p): trilinear interpolation of the exact signed distances at the nodes of a grid
// (cell about an eighth of the mesh's mean edge), and its gradient. The narrow phase uses it
// as the contact distance: one cache-friendly lookup instead of a hierarchy search. Where the
// distance is linear (near a face) it is exact; near edges and corners it rounds the mesh by
// a fraction of a cell (convex edges of dihedral angle 180 - a: about cell * a / 4). The band
// of nodes within six cells of the surface is computed when the field is built (with three,
// the ball-torus haptic scene filled 17,800 nodes while in contact, 2 to 3 us each, the worst
// of its step times; with six, 2,900, for 47,000 more at build; 568 on 2026-12-04, about
// 1.4 us each, at most 18 in one step); nodes further away the first time they are read
// (deterministic: a value depends only on the node's position, so the band is computed on
// every usable core, core/parallel.hpp, and is the same grid on any number of them).
//
// clearOf(centre, radius): node values are 1-Lipschitz, so each partial derivative of the
// interpolant is at most 1 and its gradient at most sqrt(3): no point of the ball has a
// sampled distance <= 0 when the sample at the centre (clamped into the grid) exceeds
// sqrt(3) (radius + distance to the grid). The point-shell query prunes subtrees with it.
// Large balls are first tested on a coarse grid (8 fine cells a cell, more when its node
// cap needs it; filled when built):
// the fine sample differs from the exact distance by at most sqrt(3) fine cells, and so does
// the coarse one by sqrt(3) coarse cells, which the test adds to its reach. Where the coarse
// sample shows the fine one cannot clear the ball either, no fine sample is read (the same
// answer, without a cache miss in the fine grid).
//
// Not thread-safe: sample() may fill grid nodes. Memory: at most about 2^21 nodes (8 MB of
// floats); the cell grows when the mesh's box needs more.
#pragma once

#include "flexfit/bounding_volume.hpp"
#include "flexfit/bvh.hpp"
#include "flexfit/mesh.hpp"
#include "flexfit/topology.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace flexfit {

class SignedDistanceField {
public:
    struct Sample {
        double distance = 0.0;       // negative inside
        Vec3 closest = Vec3::Zero(); // closest point on the mesh
        Vec3 normal = Vec3::UnitY(); // unit, outward at the closest point: p = closest + distance * normal
    };

    // cellSize <= 0 picks an eighth of the mean edge length; a NaN one, or one beyond the
    // mesh's extent, is std::invalid_argument.
    SignedDistanceField(const TriMesh& mesh, const Topology& topology, double cellSize = 0.0);

    // Exact signed distance, closest point and normal.
    Sample query(const Vec3& p) const;

    struct Interpolated {
        double distance = 0.0;
        Vec3 gradient = Vec3::Zero();
    };
    // The grid's interpolation at p (clamped into the grid; a NaN coordinate gives NaN values).
    Interpolated sample(const Vec3& p) const;
    // sample() at each of `points` (each must be inGrid, so finite), into `out` (at least as
    // many; std::invalid_argument otherwise): the same values bit for bit. On CPUs with AVX2, four points a vector (the same operations in the same order, each
    // correctly rounded, so a lane equals sample()); a group with a corner not yet computed
    // goes through sample(), which computes it.
    void sampleMany(std::span<const Vec3> points, std::span<Interpolated> out) const;
    // Lower bounds of the distances sampleMany gives, without computing a node: the same value
    // where a point's cell is computed (every cell within the band is), else lowerBound's. For
    // walks that only prune or skip on a distance (the point shell's rest-mass lists): a sample
    // out of the band costs a node's exact query, 1-3 us, the time of a whole step's walk slice.
    void sampleLowerBounds(std::span<const Vec3> points, std::span<double> out) const;
    bool inGrid(const Vec3& p) const {
        return (p.array() >= fine_.box.min.array()).all() && (p.array() <= fine_.box.max.array()).all();
    }
    // The squared distance from p to the grid (0 inside): a point outside stays outside while
    // it moves less than that.
    double squaredDistanceToGrid(const Vec3& p) const {
        return (p - p.cwiseMax(fine_.box.min).cwiseMin(fine_.box.max)).squaredNorm();
    }
    // True when no point within `radius` of `centre` samples a distance <= 0.
    bool clearOf(const Vec3& centre, double radius) const;
    // True when no point within `moved` of one that sampled `distance` samples <= 0 (the
    // interpolant's slope is at most sqrt(3); the float nodes' rounding is covered as in clearOf).
    bool staysClear(double distance, double moved) const { return distance > clearDistance(moved); }
    // The distance above which a sample stays clear over a motion of `moved` (staysClear).
    double clearDistance(double moved) const { return fine_.roundingReach + kSlope * moved; }
    // The square of the motion below which a point that sampled `distance` stays clear (the
    // same bound solved for the motion, squared so a caller needs no square root); -1 when
    // none does.
    double squaredClearReach(double distance) const {
        const double reach = (distance - fine_.roundingReach) / kSlope;
        return reach > 0.0 ? reach * reach : -1.0;
    }
    double cellSize() const { return fine_.cell; }
    // Nodes of the fine grid computed so far (the band at build, more as samples reach them).
    std::size_t computedNodes() const;
    // 64-bit FNV-1a of both grids' node values, bit for bit (a node not computed yet is NaN):
    // equal hashes, the same field so far.
    std::uint64_t gridHash() const;

private:
    // Node (i, j, k) at box.min + cell (i, j, k); values NaN until computed.
    struct Grid {
        double cell = 1.0;
        std::array<int, 3> dims{0, 0, 0};
        Aabb box;
        std::vector<float> values;
        double roundingReach = 0.0;  // the float nodes' rounding as a distance: 1e-6 of the box's diagonal
        double unfilledReach = 0.0;  // below the distance of any node out of the band (markOutside)
        float& node(int i, int j, int k) {
            return values[(std::size_t(k) * std::size_t(dims[1]) + std::size_t(j)) * std::size_t(dims[0]) + std::size_t(i)];
        }
    };
    void setUpGrid(Grid& grid, double cell, std::size_t maxNodes) const;
    void fill(Grid& grid, int i, int j, int k) const;
    void fillBand(Grid& grid, int cells) const;
    void fillNodes(Grid& grid, std::span<const std::size_t> nodes) const;
    // The 8 node values of p's cell (x fastest) and p's fractions in it; nodes not computed yet
    // are computed first, or with fillMissing false left NaN.
    struct Cell {
        double v[8];
        double t[3];
    };
    Cell cellAt(Grid& grid, const Vec3& p, bool fillMissing) const;
    // Trilinear, and its gradient when asked (the distance alone skips three divisions).
    static Interpolated interpolate(const Cell& cell, double cellSize, bool withGradient);
    Interpolated sample(Grid& grid, const Vec3& p) const;
    // sample(grid, p).distance where p's cell is computed; else a lower bound of it that
    // computes no node (a node out of the band counts as unfilledReach when it lies outside,
    // and gives minus infinity when it may lie inside: markOutside).
    double lowerBound(Grid& grid, const Vec3& p) const;
    static void markOutside(Grid& grid, int cells);
    template <class One>
    void sampleEach(std::span<const Vec3> points, std::span<Interpolated> out, One one) const;
    // p clamped into the grid's box, and how far p is from it.
    static std::pair<Vec3, double> clampedInto(const Grid& grid, const Vec3& p);
    static double clearReach(const Grid& grid, double radius, double outside, double slack);

    std::vector<Vec3> vertices_;
    std::vector<Face> faces_;
    std::vector<Vec3> faceNormal_;                  // (F) unit
    std::vector<std::array<Vec3, 3>> edgeNormal_;   // (F) edge e joins corners e and e+1
    std::vector<Vec3> vertexNormal_;                // (V)
    Bvh<Aabb> bvh_;
    mutable Grid fine_, coarse_;
    // staysClear's bound: the interpolant's slope with room for rounding (and the fine grid's
    // roundingReach).
    static constexpr double kSlope = 1.7320508075688772 * (1.0 + 1e-9);
};

}  // namespace flexfit
