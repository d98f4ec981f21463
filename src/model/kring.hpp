// k-rings over the mass graph (CSR neighbourhoods) by breadth-first search.
//
// The visited masses are an IndexSet: a query clears it in O(1), so after the first queries
// have sized the queue, a query allocates nothing and costs only what it visits, whatever the
// mesh size.
#pragma once

#include "flexfit/index_set.hpp"
#include "flexfit/topology.hpp"

#include <cstdint>
#include <vector>

namespace flexfit {

struct RingMember {
    Index mass;
    std::uint8_t depth;  // graph distance from the nearest seed (0 = seed)
};

class KRingWalker {
public:
    explicit KRingWalker(std::size_t vertexCount);

    // Every mass within graph distance `rings` of a seed, seeds first, then by depth. Seeds must
    // be < vertexCount; duplicates are ignored. rings is clamped to [0, 254].
    void collect(const Topology& topology, std::span<const Index> seeds, int rings, std::vector<RingMember>& out);

    std::size_t lastVisited() const { return lastVisited_; }  // masses touched by the last query
    // Room to visit `masses` masses with no allocation (Part::reserveZones).
    void reserve(std::size_t masses) { visited_.reserve(masses); }

private:
    IndexSet visited_;  // (V)
    std::size_t lastVisited_ = 0;
};

}  // namespace flexfit
