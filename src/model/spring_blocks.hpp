// Spring blocks: the full step's vector layout of a model's springs (a diagonal format).
//
// A block is 8 springs (a0 + i, a0 + i + offset), i = 0..7: the same offset b - a, consecutive
// first masses. Its 8 first ends and its 8 second ends are each 24 contiguous doubles of the
// state, so a block loads with 3 + 3 contiguous vector loads per array and needs no gather.
// Meshes whose vertices come in rows (the torus, UV-sphere and heart generators, many parametric
// or scanned surfaces) put nearly all springs in a few offsets: the heart 97% of its springs in
// blocks, torus2 94%, torus1 88%, a 16 x 16 UV sphere 80%. The springs that fit no block are the
// remainder: the vector kernels load each end's x y z as one vector and transpose 4 springs to
// lanes (block_step_x86.cpp), nearly as fast as blocks on this machine (the heart's remainder
// kernel alone: 1.3x its block kernel's time), so meshes in any vertex order (files as exporters
// write them, icospheres in subdivision order) need no blocks to be fast. A model keeps every
// block it finds: even at 43 % of the springs (the shuffled heart renumbered breadth-first)
// blocks plus remainder beat the remainder alone (91 against 108 us a step).
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

#include <span>
#include <vector>

namespace flexfit {

struct SpringBlocks {
    static constexpr int kWidth = 8;

    std::vector<Index> first;   // (B) a0
    std::vector<Index> offset;  // (B) b - a of all its springs, >= 1
    // (8B) constants of lane i of block q at 8q + i.
    std::vector<double> restLength, stiffness, damping;
    std::vector<Index> remainder;  // springs in no block, ascending
    // Lane 8q + i of block q is spring laneSpring[8q + i]; laneOfSpring[e] is its lane, or
    // kNoLane for a remainder spring (the active region tracks its blocks with them).
    static constexpr Index kNoLane = ~Index(0);
    std::vector<Index> laneSpring;    // (8B)
    std::vector<Index> laneOfSpring;  // (E)

    std::size_t blockCount() const { return first.size(); }
    bool empty() const { return first.empty(); }
    // Whether block q continues the offset-1 row of block q - 1.
    bool continuesRow(std::size_t q) const {
        return q > 0 && offset[q] == 1 && offset[q - 1] == 1 && first[q - 1] + kWidth == first[q];
    }
};

// Groups springs (a = springA[e] < springB[e], per-spring constants) into blocks: by offset in
// increasing order, then by a; each maximal run of consecutive a gives floor(run / 8) blocks.
// Every other spring goes to the remainder (all of them when no run reaches 8).
SpringBlocks buildSpringBlocks(std::span<const Index> springA, std::span<const Index> springB,
                               std::span<const double> restLength, std::span<const double> stiffness,
                               std::span<const double> damping);

}  // namespace flexfit
