// Spring blocks: the full step's vector layout of a model's springs (a diagonal format).
//
// A block is 8 lanes (a0 + i, a0 + i + offset), i = 0..7: the same offset b - a, consecutive
// first masses. Its 8 first ends and its 8 second ends are each 24 contiguous doubles of the
// state, so a block loads with 3 + 3 contiguous vector loads per array and needs no gather.
// Meshes whose vertices come in rows (the torus, UV-sphere and heart generators, many parametric
// or scanned surfaces) put nearly all springs in a few offsets. Irregular meshes renumbered by
// fronts (vertex_order.hpp) line their fronts up only in short runs: a block then takes the
// springs of one offset whose first masses fall in a0..a0+7 when there are at least
// kMinimumLanes of them, and its other lanes are empty. An empty lane has zero constants and
// evaluates to a zero force (+-0: the kernels' length test keeps 1/0 out; NaN only where its
// masses' values already overflow), and every kernel evaluates it alike, so all three still give
// the same bits. Against the same springs listed instead, adding +-0 changes at most the sign of
// a zero sum (a sum starts at +0 and x - x is +0, but a denormal result flushed to zero keeps
// its sign: FlushDenormals). A block costs about the same whatever its lanes hold, so a block of
// 5 springs still beats 5 listed ones: with at least 5 of 8 (against whole blocks only), Wuson
// in locality order puts 71 % of its springs in blocks (33 %) and its full step ran 1.24x
// faster, the remeshed Wuson 1.52x (bench/results/masked_blocks_1206.csv; 4 and 6 of 8
// measured within noise of 5 in a scratch run).
// The springs that fit no block are the remainder: the vector kernels load each end's x y z as
// one vector and transpose 8 (AVX-512) or 4 (AVX2) springs to lanes (block_step_x86.cpp), so
// meshes in any vertex order need no blocks to be correct, only to be fast.
//
// Without AVX2 (or off x86-64) the scalar kernel runs: about the naive reference's speed. It is
// kept so that every CPU gives the same bits.
//
// Order of the forces, fixed so that every kernel (scalar, AVX2, AVX-512) gives the same bits:
//   1. blocks in order; block q with forces g_i on its first masses:
//      offset 1 (rows): f[a0+i] = (f[a0+i] + g_i) - g_{i-1}, where g_{-1} is the previous
//        block's g_7 when that block ends at a0 - 1 with offset 1 too, else 0; when the next
//        block does not continue the row this way, f[a0+8] -= g_7;
//      other offsets: f[a0+i] += g_i for i = 0..7, then f[a0+offset+i] -= g_i for i = 0..7;
//   2. remainder springs in ascending order: f[a] += g, f[b] -= g;
//   3. each mass: total = f + body forces, integrate, f = 0.
#pragma once

#include "flexfit/core.hpp"
#include "flexfit/spring_list.hpp"

#include <span>
#include <vector>

namespace flexfit {

struct SpringBlocks {
    static constexpr int kWidth = 8;
    static constexpr std::size_t kMinimumLanes = 5;  // springs a block holds at least

    std::vector<Index> first;   // (B) a0
    std::vector<Index> offset;  // (B) b - a of all its springs, >= 1
    // (8B) constants of lane i of block q at 8q + i.
    DoubleArray restLength, stiffness, damping;  // read 8 lanes at a time
    std::vector<Index> remainder;  // springs in no block, ascending
    SpringList remainderSprings;   // the same springs' ends and constants, in that order
    // Lane 8q + i of block q is spring laneSpring[8q + i], or kNoLane when empty; laneOfSpring[e]
    // is spring e's lane, or kNoLane for a remainder spring (the active region tracks its blocks
    // with them).
    static constexpr Index kNoLane = ~Index(0);
    std::vector<Index> laneSpring;    // (8B)
    std::vector<Index> laneOfSpring;  // (E)

    std::size_t blockCount() const { return first.size(); }
    std::size_t blockedSprings() const { return laneOfSpring.size() - remainder.size(); }
    bool empty() const { return first.empty(); }
    // Whether block q continues the offset-1 row of block q - 1.
    bool continuesRow(std::size_t q) const {
        return q > 0 && offset[q] == 1 && offset[q - 1] == 1 && first[q - 1] + kWidth == first[q];
    }
};

// Groups springs (a = springA[e] < springB[e] < massCount, per-spring constants) into blocks:
// by offset in increasing order, then by a; from each offset's lowest first mass a0 not yet
// placed, the springs with first masses a0..a0+7 become a block when there are at least
// kMinimumLanes of them and the block's lanes end at masses (a0 + 7 + offset < massCount).
// Every other spring goes to the remainder (all of them when no block forms).
SpringBlocks buildSpringBlocks(std::span<const Index> springA, std::span<const Index> springB,
                               std::span<const double> restLength, std::span<const double> stiffness,
                               std::span<const double> damping, std::size_t massCount);

}  // namespace flexfit
