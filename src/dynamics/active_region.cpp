// The active region's bookkeeping (active_region.hpp).
#include "flexfit/active_region.hpp"

#include "model/spring_blocks.hpp"

#include <limits>
#include <string>

namespace flexfit {

void ActiveRegion::LooseSprings::reset(const PartModel& m) {
    model = &m;
    set.reset(m.springCount());
    list.clear();
}

void ActiveRegion::LooseSprings::insert(Index e) {
    if (set.insert(e)) list.append(*model, e);
}

void ActiveRegion::LooseSprings::erase(Index e) {
    if (!set.contains(e)) return;
    list.moveLastTo(set.slotOf(e));  // as the set's swap-remove moves its last member
    set.erase(e);
}

template <class Loose>
void ActiveRegion::VectorGroups<Loose>::reset(std::size_t groups, std::uint8_t minimumMembers) {
    minimum = minimumMembers;
    count.assign(groups, 0);
    vector.reset(groups);
}

template <class Loose>
template <class MemberOf>
void ActiveRegion::VectorGroups<Loose>::join(Index member, Index group, MemberOf memberOf) {
    if (group == kNoGroup || ++count[group] < minimum) {
        loose.insert(member);
        return;
    }
    if (count[group] > minimum) return;  // the group already runs in the vector kernel
    vector.insert(group);  // it reached the minimum: its members in the region leave the loose list
    for (Index i = 0; i < 8; ++i)
        if (const Index m = memberOf(group, i); m != kNoGroup) loose.erase(m);
}

template <class Loose>
template <class MemberOf, class InRegion>
void ActiveRegion::VectorGroups<Loose>::leave(Index member, Index group, MemberOf memberOf, InRegion inRegion) {
    if (group == kNoGroup || count[group]-- < minimum) {
        loose.erase(member);
        return;
    }
    if (count[group] >= minimum) return;  // it still runs in the vector kernel
    vector.erase(group);  // below the minimum: its members still in the region are loose again
    for (Index i = 0; i < 8; ++i)
        if (const Index m = memberOf(group, i); m != kNoGroup && inRegion(m)) loose.insert(m);
}

namespace {
Index massOfOctet(Index octet, Index i) { return 8 * octet + i; }
}  // namespace

ActiveRegion::ActiveRegion(const PartModel& model)
    : model_(&model),
      coverCount_(model.massCount(), 0),
      movingEnds_(model.springCount(), 0),
      masses_(model.massCount()),
      springs_(model.springCount()) {
    octets_.reset(model.massCount() / 8, kMinimumOctetMasses);
    octets_.loose.reset(model.massCount());
    if (model.hasSpringBlocks()) blocks_ = model.springBlocks.get();
    blockGroups_.reset(blocks_ != nullptr ? blocks_->blockCount() : 0, kMinimumBlockSprings);
    blockGroups_.loose.reset(model);
}

void ActiveRegion::reserveWholeModel() {
    if (model_ == nullptr) return;
    masses_.reserve(model_->massCount());
    springs_.reserve(model_->springCount());
    octets_.vector.reserve(octets_.count.size());
    octets_.loose.reserve(model_->massCount());
    blockGroups_.vector.reserve(blockGroups_.count.size());
    blockGroups_.loose.set.reserve(model_->springCount());
    blockGroups_.loose.list.reserve(model_->springCount());
}

void ActiveRegion::requireMass(Index mass, const char* what) const {
    if (mass >= coverCount_.size())
        throw InputError("active region", 0, std::string(what) + ": mass " + std::to_string(mass) + " does not exist (the region has " +
                                                 std::to_string(coverCount_.size()) + " masses)");
}

bool ActiveRegion::cover(Index mass) {
    requireMass(mass, "cover");
    if (coverCount_[mass] == std::numeric_limits<std::uint16_t>::max())
        throw InputError("active region", 0, "cover: mass " + std::to_string(mass) + " is covered by 65,535 zones already");
    if (coverCount_[mass]++ != 0) return false;
    masses_.insert(mass);
    octets_.join(mass, octetOf(mass), massOfOctet);
    for (Index e : model_->springsAt(mass))
        if (movingEnds_[e]++ == 0) springJoins(e);
    return true;
}

bool ActiveRegion::uncover(Index mass) {
    requireMass(mass, "uncover");
    if (coverCount_[mass] == 0) throw InputError("active region", 0, "uncover: mass " + std::to_string(mass) + " is not covered");
    if (--coverCount_[mass] != 0) return false;
    masses_.erase(mass);
    octets_.leave(mass, octetOf(mass), massOfOctet, [this](Index m) { return moves(m); });
    for (Index e : model_->springsAt(mass))
        if (--movingEnds_[e] == 0) springLeaves(e);
    return true;
}

bool ActiveRegion::uncoverUnlessLast(Index mass) {
    if (coverCount_[mass] == 1) return true;
    --coverCount_[mass];
    return false;
}

void ActiveRegion::clear() {
    for (Index m : masses_) {
        coverCount_[m] = 0;
        if (const Index octet = octetOf(m); octet != kNoGroup) octets_.count[octet] = 0;
    }
    for (Index e : springs_) {
        movingEnds_[e] = 0;
        if (const Index block = blockOf(e); block != kNoGroup) blockGroups_.count[block] = 0;
    }
    masses_.clear();
    springs_.clear();
    octets_.vector.clear();
    octets_.loose.clear();
    blockGroups_.vector.clear();
    blockGroups_.loose.set.clear();
    blockGroups_.loose.list.clear();
}

Index ActiveRegion::blockOf(Index spring) const {
    if (blocks_ == nullptr) return kNoGroup;
    const Index lane = blocks_->laneOfSpring[spring];
    return lane == SpringBlocks::kNoLane ? kNoGroup : lane / SpringBlocks::kWidth;
}

void ActiveRegion::springJoins(Index e) {
    springs_.insert(e);
    blockGroups_.join(e, blockOf(e), [this](Index q, Index i) { return springOfBlock(q, i); });
}

void ActiveRegion::springLeaves(Index e) {
    springs_.erase(e);
    blockGroups_.leave(e, blockOf(e), [this](Index q, Index i) { return springOfBlock(q, i); },
                       [this](Index spring) { return movingEnds_[spring] != 0; });
}

Index ActiveRegion::springOfBlock(Index block, Index i) const {
    const Index spring = blocks_->laneSpring[SpringBlocks::kWidth * block + i];
    return spring == SpringBlocks::kNoLane ? kNoGroup : spring;
}

}  // namespace flexfit
