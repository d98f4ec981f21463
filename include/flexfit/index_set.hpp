// A set of indices in [0, capacity) kept as a compact list: a sparse set (Briggs and Torczon,
// "An efficient representation for sparse sets", 1993).
//
// members() lists the indices in the set, and slot[i] says where index i sits in that list.
// i is a member exactly when slot[i] < size() and members()[slot[i]] == i, so nothing has to be
// reset: insert, erase, contains and clear are all O(1), and iterating costs the members, not
// the capacity. This is the active-region pattern (marks + compact list + slots) in one place:
// the moving masses and computed springs of a part, the masses a contact response pushes, the
// faces a refit visits, the hierarchy nodes it merges.
//
// Order: members stay in insertion order until an erase moves the last member into the hole
// (swap-remove), so a sequence of operations always gives the same order (determinism).
// Indices are not range-checked: callers pass indices below capacity(), as they do for the
// arrays the set stands beside.
#pragma once

#include "flexfit/core.hpp"

#include <algorithm>
#include <span>
#include <vector>

namespace flexfit {

class IndexSet {
public:
    IndexSet() = default;
    explicit IndexSet(std::size_t capacity) : slot_(capacity, 0) {}

    // Empties the set and sets its capacity.
    void reset(std::size_t capacity) {
        members_.clear();
        slot_.assign(capacity, 0);
    }
    // Grows the capacity to at least `capacity`, keeping the members.
    void growTo(std::size_t capacity) {
        if (slot_.size() < capacity) slot_.resize(capacity, 0);
    }
    std::size_t capacity() const { return slot_.size(); }
    std::size_t size() const { return members_.size(); }
    bool empty() const { return members_.empty(); }

    bool contains(Index i) const {
        const Index s = slot_[i];
        return s < members_.size() && members_[s] == i;
    }
    // Adds i at the end of the list; true when it was not a member.
    bool insert(Index i) {
        if (contains(i)) return false;
        slot_[i] = Index(members_.size());
        members_.push_back(i);
        return true;
    }
    // Removes i, moving the last member into its place; true when it was a member.
    bool erase(Index i) {
        if (!contains(i)) return false;
        const Index s = slot_[i], last = members_.back();
        members_[s] = last;
        slot_[last] = s;
        members_.pop_back();
        return true;
    }
    void clear() { members_.clear(); }
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
    std::vector<Index> members_;  // the set, compact
    std::vector<Index> slot_;     // (capacity) position in members_; stale for non-members
};

}  // namespace flexfit
