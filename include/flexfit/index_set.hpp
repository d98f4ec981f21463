// A set of indices in [0, capacity) kept as a compact list: marks + list + slots.
//
// members() lists the indices in the set; each index has a mark (the pass that inserted it)
// and a slot (where it sits in the list), in two arrays so that a scan of the marks reads 4
// bytes an index. clear() starts a new pass by bumping the pass number, so insert, erase,
// contains and clear are all O(1), membership is one load, and iterating costs the members,
// not the capacity. After 2^32 - 1 passes the number wraps and the marks are reset once, for
// real. This is the pattern of every "what was touched" list in Flexfit:
// the moving masses and computed springs of a part, its changed masses, the masses a contact
// response pushes, the faces a refit visits, the hierarchy nodes it merges, the masses a
// k-ring reaches.
//
// Order: members stay in insertion order until an erase moves the last member into the hole
// (swap-remove), so a sequence of operations always gives the same order (determinism).
// Indices are not range-checked: callers pass indices below capacity(), as they do for the
// arrays the set stands beside.
#pragma once

#include "flexfit/core.hpp"

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

namespace flexfit {

class IndexSet {
public:
    IndexSet() = default;
    explicit IndexSet(std::size_t capacity) : mark_(capacity, 0), slot_(capacity, 0) {}

    // Empties the set and sets its capacity.
    void reset(std::size_t capacity) {
        members_.clear();
        mark_.assign(capacity, 0);
        slot_.assign(capacity, 0);
        pass_ = 1;
    }
    // Grows the capacity to at least `capacity`, keeping the members.
    void growTo(std::size_t capacity) {
        if (mark_.size() >= capacity) return;
        mark_.resize(capacity, 0);
        slot_.resize(capacity, 0);
    }
    std::size_t capacity() const { return mark_.size(); }
    // Room for `members` members in the list, so that inserting up to that many allocates nothing.
    void reserve(std::size_t members) { members_.reserve(members); }
    std::size_t size() const { return members_.size(); }
    bool empty() const { return members_.empty(); }

    bool contains(Index i) const { return mark_[i] == pass_; }
    // Adds i at the end of the list; true when it was not a member.
    bool insert(Index i) {
        if (mark_[i] == pass_) return false;
        mark_[i] = pass_;
        slot_[i] = Index(members_.size());
        members_.push_back(i);
        return true;
    }
    // Removes i, moving the last member into its place; true when it was a member.
    bool erase(Index i) {
        if (mark_[i] != pass_) return false;
        mark_[i] = 0;
        const Index s = slot_[i], last = members_.back();
        members_[s] = last;
        slot_[last] = s;
        members_.pop_back();
        return true;
    }
    void clear() {
        members_.clear();
        if (++pass_ == 0) {  // wrapped: forget every mark for real, once in 2^32 - 1 passes
            std::fill(mark_.begin(), mark_.end(), 0u);
            pass_ = 1;
        }
    }
    // Where a member sits in members(): values kept beside the list are indexed by it.
    Index slotOf(Index member) const { return slot_[member]; }
    // Orders the members by index (O(size log size)), for passes that need them sorted.
    void sort() {
        std::sort(members_.begin(), members_.end());
        for (std::size_t s = 0; s < members_.size(); ++s) slot_[members_[s]] = Index(s);
    }

    std::span<const Index> members() const { return members_; }
    auto begin() const { return members_.begin(); }
    auto end() const { return members_.end(); }
    Index operator[](std::size_t s) const { return members_[s]; }

private:
    std::vector<Index> members_;       // the set, compact
    std::vector<std::uint32_t> mark_;  // (capacity) the pass that inserted each index; 0 = none
    std::vector<Index> slot_;          // (capacity) position in members_ of each member
    std::uint32_t pass_ = 1;           // the current pass, never 0
};

}  // namespace flexfit
