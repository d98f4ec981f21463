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
// For the region step's vector kernels the region also keeps its groups of 8 that the vector
// kernels run: the spring blocks (the full step's vector layout, on models that have them) with
// at least kMinimumBlockSprings of their springs computed (a block holds 5 to 8), and the octets
// of masses 8k..8k+7 with at least kMinimumOctetMasses moving (the kernel puts the others back at
// rest, where they are: the same bits as leaving them). The block kernel evaluates all 8 lanes
// of a block and adds each force only to the ends that move: a spring that is not computed has
// no moving end, so it adds nothing, and an empty lane's force is +-0 (spring_blocks.hpp).
// A block costs about 20 ns however many of its springs are computed (the kernels are bound by
// each lane's square root and division). The minimum was measured, 2 to 5 against 8 (whole
// blocks only), on torus1, torus2, the heart and the renumbered shuffled heart at levels 4-16:
// with AVX-512, 3-5 made the region step as fast or faster at every partial coverage (5: by
// 0-14 %), but with AVX2, whose loose springs are relatively cheaper, 2 / 3 / 4 made it up to
// 1.34 / 1.19 / 1.16x slower at low coverage, and 5 was the smallest within noise of 8 or
// faster. The step runs the other ("loose") springs by the listed-spring kernel, from their ends
// and constants kept beside them (looseSpringList), and the loose masses as a list. O(8) more
// per joining or leaving spring or mass.
//
// Known limit: a mass can be covered by at most 65,535 zones at once (the count is 16-bit, to
// keep the per-mass mask that the region step reads small).
#pragma once

#include "flexfit/index_set.hpp"
#include "flexfit/part_model.hpp"
#include "flexfit/spring_list.hpp"

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
    // returns true then. InputError for a mass out of range or covered 65,535 times already.
    bool cover(Index mass);
    // One zone fewer covers `mass` (InputError unless covered). At the last, the mass stops
    // moving and its springs with no other moving end stop being computed; returns true then.
    bool uncover(Index mass);

    // One zone fewer covers `mass`, unless it is the last: then nothing changes and it returns
    // true, and the caller uncovers it later (uncover) or empties the region (clear). A batch of
    // retiring zones defers its region bookkeeping so: the masses whose last zone retires are
    // uncovered afterwards in the same order, which makes the same lists as uncovering each at
    // once (every test the lists make reads the counts of masses not yet uncovered as non-zero).
    bool uncoverUnlessLast(Index mass);
    // Empties the region: every mass stops moving, every list is empty (a new region's state,
    // the room kept). O(its masses and springs).
    void clear();

    // Room in every list for the whole model (its masses, springs and groups: about 45 bytes a
    // spring), so that covering and uncovering never allocate (Part::reserveZones).
    void reserveWholeModel();

    bool moves(Index mass) const { return coverCount_[mass] != 0; }  // mass < the model's count (unchecked: hot)
    bool builtFor(const PartModel& model) const { return model_ == &model; }
    bool empty() const { return masses_.empty(); }
    bool coversEveryMass() const { return masses_.size() == coverCount_.size(); }
    const IndexSet& masses() const { return masses_; }    // the moving masses
    const IndexSet& springs() const { return springs_; }  // the computed springs
    // (V) the zones covering each mass: non-zero exactly for the moving masses.
    std::span<const std::uint16_t> coverCounts() const { return coverCount_; }
    // Blocks (indices into the model's spring blocks) with at least kMinimumBlockSprings of their
    // springs computed, and the computed springs in no such block; without blocks, every
    // computed spring is loose.
    static constexpr std::uint8_t kMinimumBlockSprings = 5;
    const IndexSet& vectorBlocks() const { return blockGroups_.vector; }
    const IndexSet& looseSprings() const { return blockGroups_.loose.set; }
    // The loose springs' ends and constants, slot for slot beside looseSprings() (what the
    // region step's listed-spring kernels read).
    const SpringList& looseSpringList() const { return blockGroups_.loose.list; }
    // Octets k (masses 8k..8k+7) with at least kMinimumOctetMasses moving masses, which the
    // vector kernel integrates whole (its other masses held at rest), and the moving masses in no
    // such octet. 3 measured against 1, 2, 4, 6 and 8 (bench/results/vector_octets_1206.csv):
    // the region step 0.80-1.08x of its time with whole octets only, 0.95x on geometric mean.
    static constexpr std::uint8_t kMinimumOctetMasses = 3;
    const IndexSet& vectorOctets() const { return octets_.vector; }
    const IndexSet& looseMasses() const { return octets_.loose; }

private:
    // The loose springs: their set, and their ends and constants beside it slot for slot.
    struct LooseSprings {
        const PartModel* model = nullptr;
        IndexSet set;
        SpringList list;
        void reset(const PartModel& m);
        void insert(Index e);
        void erase(Index e);
    };
    // Members (springs, masses) in groups of 8: which groups have at least `minimum` members in
    // the region, and which members of the region are in no such group (`loose`: an IndexSet
    // of masses, or LooseSprings, which the caller resets).
    template <class Loose>
    struct VectorGroups {
        std::uint8_t minimum = 8;
        std::vector<std::uint8_t> count;  // (groups) members in the region
        IndexSet vector;                  // (groups) those with at least `minimum`
        Loose loose;                      // (members)
        void reset(std::size_t groups, std::uint8_t minimumMembers);
        // `group` is kNoGroup for a member of no group; memberOf(group, i) is its i-th member, or
        // kNoGroup for an empty place (a spring block's empty lane).
        // Called after the member joined or left; inRegion(m) says whether m is in the region.
        template <class MemberOf>
        void join(Index member, Index group, MemberOf memberOf);
        template <class MemberOf, class InRegion>
        void leave(Index member, Index group, MemberOf memberOf, InRegion inRegion);
    };
    static constexpr Index kNoGroup = ~Index(0);
    void requireMass(Index mass, const char* what) const;  // InputError naming `what` when out of range
    void springJoins(Index spring);
    void springLeaves(Index spring);
    Index blockOf(Index spring) const;                 // its block, or kNoGroup
    Index springOfBlock(Index block, Index i) const;   // lane i's spring, or kNoGroup (empty)
    Index octetOf(Index mass) const { return mass < coverCount_.size() / 8 * 8 ? mass / 8 : kNoGroup; }

    const PartModel* model_ = nullptr;
    std::vector<std::uint16_t> coverCount_;  // (V)
    std::vector<std::uint8_t> movingEnds_;   // (E) 0, 1 or 2
    IndexSet masses_;                        // (V)
    IndexSet springs_;                       // (E)
    const SpringBlocks* blocks_ = nullptr;   // the model's, when it has any
    VectorGroups<LooseSprings> blockGroups_; // spring blocks (none without blocks_: all loose)
    VectorGroups<IndexSet> octets_;          // mass octets
};

}  // namespace flexfit
