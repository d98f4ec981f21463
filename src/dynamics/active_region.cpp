// The active region's bookkeeping (active_region.hpp).
#include "flexfit/active_region.hpp"

namespace flexfit {

ActiveRegion::ActiveRegion(const PartModel& model)
    : topology_(&model.topology),
      coverCount_(model.massCount(), 0),
      movingEnds_(model.springCount(), 0),
      masses_(model.massCount()),
      springs_(model.springCount()) {}

bool ActiveRegion::cover(Index mass) {
    if (coverCount_[mass]++ != 0) return false;
    masses_.insert(mass);
    for (Index e : topology_->edgesOf(mass))
        if (movingEnds_[e]++ == 0) springs_.insert(e);
    return true;
}

bool ActiveRegion::uncover(Index mass) {
    if (--coverCount_[mass] != 0) return false;
    masses_.erase(mass);
    for (Index e : topology_->edgesOf(mass))
        if (--movingEnds_[e] == 0) springs_.erase(e);
    return true;
}

}  // namespace flexfit
