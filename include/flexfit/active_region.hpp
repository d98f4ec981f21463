// The active region of a rigid-deformable part (SPEC 5, thesis 4.2): the masses that move and
// the springs computed around them, kept as compact index sets (index_set.hpp) so that a step
// iterates what moves and nothing else, like Box2D's awake set.
//
// A mass moves while at least one zone covers it: cover() and uncover() count the zones. When
// a mass joins, every spring touching it becomes computed; a spring stays computed while one of
// its ends moves. Each call costs the valence of the mass, so opening, growing, shrinking or
// retiring a zone costs what it changes. Members keep the order in which they joined until one
// leaves (swap-remove), so the same calls always give the same order (determinism).
//
// Known limit: a mass can be covered by at most 65,535 zones at once (the count is 16-bit, to
// keep the per-mass mask that the region step reads small).
#pragma once

#include "flexfit/index_set.hpp"
#include "flexfit/part_model.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace flexfit {

class ActiveRegion {
public:
    ActiveRegion() = default;
    // An empty region over the model's masses and springs; the model must outlive the region.
    explicit ActiveRegion(const PartModel& model);

    // One zone more covers `mass`. At the first, the mass moves and its springs are computed;
    // returns true then.
    bool cover(Index mass);
    // One zone fewer covers `mass` (which must be covered). At the last, the mass stops moving
    // and its springs with no other moving end stop being computed; returns true then.
    bool uncover(Index mass);

    bool moves(Index mass) const { return coverCount_[mass] != 0; }
    bool empty() const { return masses_.empty(); }
    bool coversEveryMass() const { return masses_.size() == coverCount_.size(); }
    const IndexSet& masses() const { return masses_; }    // the moving masses
    const IndexSet& springs() const { return springs_; }  // the computed springs
    // (V) the zones covering each mass: non-zero exactly for the moving masses.
    std::span<const std::uint16_t> coverCounts() const { return coverCount_; }

private:
    const Topology* topology_ = nullptr;
    std::vector<std::uint16_t> coverCount_;  // (V)
    std::vector<std::uint8_t> movingEnds_;   // (E) 0, 1 or 2
    IndexSet masses_;                        // (V)
    IndexSet springs_;                       // (E)
};

}  // namespace flexfit
