// The active region's bookkeeping (active_region.hpp).
#include "flexfit/active_region.hpp"

#include "model/spring_blocks.hpp"

namespace flexfit {

void ActiveRegion::WholeGroups::reset(std::size_t groups, std::size_t members) {
    count.assign(groups, 0);
    whole.reset(groups);
    loose.reset(members);
}

template <class MemberOf>
void ActiveRegion::WholeGroups::join(Index member, Index group, MemberOf memberOf) {
    if (group == kNoGroup || ++count[group] < 8) {
        loose.insert(member);
        return;
    }
    whole.insert(group);  // its last member joined: the group runs whole
    for (Index i = 0; i < 8; ++i)
        if (memberOf(group, i) != member) loose.erase(memberOf(group, i));
}

template <class MemberOf>
void ActiveRegion::WholeGroups::leave(Index member, Index group, MemberOf memberOf) {
    if (group == kNoGroup || count[group]-- < 8) {
        loose.erase(member);
        return;
    }
    whole.erase(group);  // the group breaks up: its other members are loose again
    for (Index i = 0; i < 8; ++i)
        if (memberOf(group, i) != member) loose.insert(memberOf(group, i));
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
    octets_.reset(model.massCount() / 8, model.massCount());
    if (!model.hasSpringBlocks()) return;
    blocks_ = model.springBlocks.get();
    blockGroups_.reset(blocks_->blockCount(), model.springCount());
}

bool ActiveRegion::cover(Index mass) {
    if (coverCount_[mass]++ != 0) return false;
    masses_.insert(mass);
    octets_.join(mass, octetOf(mass), massOfOctet);
    for (Index e : model_->springsAt(mass))
        if (movingEnds_[e]++ == 0) springJoins(e);
    return true;
}

bool ActiveRegion::uncover(Index mass) {
    if (--coverCount_[mass] != 0) return false;
    masses_.erase(mass);
    octets_.leave(mass, octetOf(mass), massOfOctet);
    for (Index e : model_->springsAt(mass))
        if (--movingEnds_[e] == 0) springLeaves(e);
    return true;
}

Index ActiveRegion::blockOf(Index spring) const {
    const Index lane = blocks_->laneOfSpring[spring];
    return lane == SpringBlocks::kNoLane ? kNoGroup : lane / SpringBlocks::kWidth;
}

void ActiveRegion::springJoins(Index e) {
    springs_.insert(e);
    if (blocks_ != nullptr) blockGroups_.join(e, blockOf(e), [this](Index q, Index i) { return springOfBlock(q, i); });
}

void ActiveRegion::springLeaves(Index e) {
    springs_.erase(e);
    if (blocks_ != nullptr) blockGroups_.leave(e, blockOf(e), [this](Index q, Index i) { return springOfBlock(q, i); });
}

Index ActiveRegion::springOfBlock(Index block, Index i) const { return blocks_->laneSpring[SpringBlocks::kWidth * block + i]; }

}  // namespace flexfit
