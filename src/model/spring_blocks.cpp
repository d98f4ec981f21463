#include "model/spring_blocks.hpp"

#include <algorithm>
#include <numeric>

namespace flexfit {
namespace {

// Lane i of a new block: spring e, or an empty lane (zero constants) for e == kNoSpring.
constexpr std::size_t kNoSpring = ~std::size_t(0);
void appendLane(SpringBlocks& blocks, std::size_t e, std::span<const double> restLength, std::span<const double> stiffness,
                std::span<const double> damping) {
    const bool empty = e == kNoSpring;
    if (!empty) blocks.laneOfSpring[e] = Index(blocks.laneSpring.size());
    blocks.laneSpring.push_back(empty ? SpringBlocks::kNoLane : Index(e));
    blocks.restLength.push_back(empty ? 0.0 : restLength[e]);
    blocks.stiffness.push_back(empty ? 0.0 : stiffness[e]);
    blocks.damping.push_back(empty ? 0.0 : damping[e]);
}

}  // namespace

SpringBlocks buildSpringBlocks(std::span<const Index> springA, std::span<const Index> springB,
                               std::span<const double> restLength, std::span<const double> stiffness,
                               std::span<const double> damping, std::size_t massCount) {
    constexpr std::size_t W = SpringBlocks::kWidth;
    const std::size_t springs = springA.size();
    // Springs by (offset, a): each offset's springs with nearby first masses become contiguous.
    std::vector<std::size_t> order(springs);
    std::iota(order.begin(), order.end(), std::size_t{0});
    auto key = [&](std::size_t e) { return std::pair(springB[e] - springA[e], springA[e]); };
    std::sort(order.begin(), order.end(), [&](std::size_t p, std::size_t q) { return key(p) < key(q); });

    SpringBlocks blocks;
    blocks.laneOfSpring.assign(springs, SpringBlocks::kNoLane);
    for (std::size_t start = 0; start < springs;) {
        const auto [offset, a0] = key(order[start]);
        std::size_t end = start + 1;  // the springs of this offset with first masses a0 .. a0 + 7
        while (end < springs && key(order[end]).first == offset && key(order[end]).second < a0 + W) ++end;
        const bool fits = std::size_t(a0) + W + offset <= massCount;  // every lane's ends are masses
        if (end - start < SpringBlocks::kMinimumLanes || !fits) {
            ++start;  // order[start] stays in the remainder
            continue;
        }
        blocks.first.push_back(a0);
        blocks.offset.push_back(offset);
        for (std::size_t i = 0, next = start; i < W; ++i) {
            const bool present = next < end && key(order[next]).second == a0 + i;
            appendLane(blocks, present ? order[next++] : kNoSpring, restLength, stiffness, damping);
        }
        start = end;
    }
    for (std::size_t e = 0; e < springs; ++e)
        if (blocks.laneOfSpring[e] == SpringBlocks::kNoLane) {
            blocks.remainder.push_back(Index(e));
            blocks.remainderSprings.append(springA[e], springB[e], restLength[e], stiffness[e], damping[e]);
        }
    return blocks;
}

}  // namespace flexfit
