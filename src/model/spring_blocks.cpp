#include "model/spring_blocks.hpp"

#include <algorithm>
#include <numeric>

namespace flexfit {
namespace {

void appendBlock(SpringBlocks& blocks, std::span<const std::size_t> lanes, std::span<const Index> springA,
                 std::span<const Index> springB, std::span<const double> restLength, std::span<const double> stiffness,
                 std::span<const double> damping) {
    blocks.first.push_back(springA[lanes[0]]);
    blocks.offset.push_back(springB[lanes[0]] - springA[lanes[0]]);
    for (std::size_t e : lanes) {
        blocks.laneOfSpring[e] = Index(blocks.laneSpring.size());
        blocks.laneSpring.push_back(Index(e));
        blocks.restLength.push_back(restLength[e]);
        blocks.stiffness.push_back(stiffness[e]);
        blocks.damping.push_back(damping[e]);
    }
}

}  // namespace

SpringBlocks buildSpringBlocks(std::span<const Index> springA, std::span<const Index> springB,
                               std::span<const double> restLength, std::span<const double> stiffness,
                               std::span<const double> damping) {
    constexpr std::size_t W = SpringBlocks::kWidth;
    const std::size_t springs = springA.size();
    // Springs by (offset, a): each offset's runs of consecutive a become contiguous.
    std::vector<std::size_t> order(springs);
    std::iota(order.begin(), order.end(), std::size_t{0});
    auto key = [&](std::size_t e) { return std::pair(springB[e] - springA[e], springA[e]); };
    std::sort(order.begin(), order.end(), [&](std::size_t p, std::size_t q) { return key(p) < key(q); });

    SpringBlocks blocks;
    blocks.laneOfSpring.assign(springs, SpringBlocks::kNoLane);
    std::vector<bool> blocked(springs, false);
    for (std::size_t start = 0; start < springs;) {
        std::size_t end = start + 1;
        while (end < springs && key(order[end]).first == key(order[start]).first &&
               key(order[end]).second == key(order[end - 1]).second + 1)
            ++end;
        for (std::size_t s = start; s + W <= end; s += W) {
            const std::span<const std::size_t> lanes(order.data() + s, W);
            appendBlock(blocks, lanes, springA, springB, restLength, stiffness, damping);
            for (std::size_t e : lanes) blocked[e] = true;
        }
        start = end;
    }
    for (std::size_t e = 0; e < springs; ++e)
        if (!blocked[e]) blocks.remainder.push_back(Index(e));
    return blocks;
}

}  // namespace flexfit
