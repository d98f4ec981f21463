// A set of indices [0, size) that empties in O(1), for the visited marks of queries, refits
// and steps that must cost what they touch, not what the mesh holds.
//
// Each index keeps the stamp of the pass that last inserted it; clear() starts a new pass by
// bumping the pass number, so an index is in the set when its stamp equals it. After 2^32 - 1
// passes the number wraps and the stamps are reset once, for real. Indices are not checked:
// callers pass indices below size(), as they do for the arrays the marks stand beside.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace flexfit {

class EpochMarks {
public:
    EpochMarks() = default;
    explicit EpochMarks(std::size_t size) : stamp_(size, 0u) {}

    std::size_t size() const { return stamp_.size(); }
    // Resizes and empties the set.
    void reset(std::size_t size) {
        stamp_.assign(size, 0u);
        epoch_ = 1;
    }
    // Grows to at least `size`, keeping the members (new indices are not in the set).
    void growTo(std::size_t size) {
        if (stamp_.size() < size) stamp_.resize(size, 0u);
    }
    // Empties the set.
    void clear() {
        if (++epoch_ == 0) {
            std::fill(stamp_.begin(), stamp_.end(), 0u);
            epoch_ = 1;
        }
    }
    bool contains(std::size_t index) const { return stamp_[index] == epoch_; }
    // Adds the index; true when it was not in the set.
    bool insert(std::size_t index) {
        if (stamp_[index] == epoch_) return false;
        stamp_[index] = epoch_;
        return true;
    }

private:
    std::vector<std::uint32_t> stamp_;  // pass that last inserted each index; 0 = never
    std::uint32_t epoch_ = 1;           // the current pass, never 0
};

}  // namespace flexfit
