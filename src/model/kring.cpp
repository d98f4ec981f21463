#include "flexfit/kring.hpp"

#include <algorithm>

namespace flexfit {

KRingWalker::KRingWalker(std::size_t vertexCount) : mark_(vertexCount, 0) {}

void KRingWalker::collect(const Topology& topology, std::span<const Index> seeds, int rings, std::vector<RingMember>& out) {
    out.clear();
    rings = std::clamp(rings, 0, 254);
    if (++epoch_ == 0) {  // wrapped after 4 billion queries: clear once
        std::fill(mark_.begin(), mark_.end(), 0u);
        epoch_ = 1;
    }
    for (Index s : seeds) {
        if (mark_[s] == epoch_) continue;
        mark_[s] = epoch_;
        out.push_back({s, 0});
    }
    // `out` doubles as the BFS queue: members are appended in depth order.
    for (std::size_t head = 0; head < out.size(); ++head) {
        const RingMember current = out[head];
        if (current.depth >= rings) continue;
        for (Index n : topology.neighborsOf(current.mass)) {
            if (mark_[n] == epoch_) continue;
            mark_[n] = epoch_;
            out.push_back({n, std::uint8_t(current.depth + 1)});
        }
    }
    lastVisited_ = out.size();
}

}  // namespace flexfit
