// Springs as parallel arrays in the order of a list: each spring's two masses and its constants
// side by side, so a pass over the list reads them in order, with no spring index to follow
// first (the listed-spring kernels then load only the ends' state). The active region keeps its
// loose springs so, slot for slot beside their index set (O(1) per spring joining or leaving),
// and the spring blocks their remainder.
#pragma once

#include "flexfit/core.hpp"

#include <cstddef>
#include <span>
#include <vector>

namespace flexfit {

struct PartModel;

struct SpringList {
    std::vector<Index> springA, springB;  // the two masses of each listed spring
    std::vector<double> restLength, stiffness, damping;

    std::size_t size() const { return springA.size(); }
    bool empty() const { return springA.empty(); }
    void clear();
    void reserve(std::size_t springs);
    // Appends a spring at the end of the list.
    void append(Index a, Index b, double rest, double k, double c);
    // Model spring e at the end of the list.
    void append(const PartModel& model, Index e);
    // The last spring moved into `slot` and the list one shorter (IndexSet::erase's swap-remove).
    void moveLastTo(std::size_t slot);
};

// The model's springs `springs`, in that order.
SpringList springListOf(const PartModel& model, std::span<const Index> springs);

}  // namespace flexfit
