#include "model/kring.hpp"

#include <algorithm>

namespace flexfit {

KRingWalker::KRingWalker(std::size_t vertexCount) : visited_(vertexCount) {}

void KRingWalker::collect(const Topology& topology, std::span<const Index> seeds, int rings, std::vector<RingMember>& out) {
    out.clear();
    rings = std::clamp(rings, 0, 254);
    visited_.clear();
    for (Index s : seeds)
        if (visited_.insert(s)) out.push_back({s, 0});
    // `out` doubles as the BFS queue: members are appended in depth order.
    for (std::size_t head = 0; head < out.size(); ++head) {
        const RingMember current = out[head];
        if (current.depth >= rings) continue;
        for (Index n : topology.neighborsOf(current.mass))
            if (visited_.insert(n)) out.push_back({n, std::uint8_t(current.depth + 1)});
    }
    lastVisited_ = out.size();
}

}  // namespace flexfit
