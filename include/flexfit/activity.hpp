// Activity metrics (SPEC 4, thesis 4.1.4 and Table 4.2).
//
// A spring is active when | |x_i - x_j| - L_ij | > threshold. Per step the tracker counts the
// active springs; over a run it keeps the maximum active at one time, the number of distinct
// springs ever active, and the restoration time: from the release of the load to the first
// step after it at which no spring is active.
#pragma once

#include "flexfit/part_state.hpp"

#include <optional>
#include <vector>

namespace flexfit {

// InputError unless there is one position per mass.
std::size_t countActiveSprings(const PartModel& model, std::span<const Vec3> positions, double threshold);

class ActivityTracker {
public:
    ActivityTracker(const PartModel& model, double threshold);

    // Counts the active springs of `state` and folds them into the run totals; returns the count.
    // InputError for a state, model or spring that does not fit the tracker's model.
    std::size_t observe(const PartModel& model, const PartState& state);
    // The same, checking only `springs`: for a rigid-deformable part, its computed springs
    // (every other spring joins two masses at rest and is inactive by construction).
    std::size_t observe(const PartModel& model, const PartState& state, std::span<const Index> springs);
    // The load is released at `time`: the restoration clock starts.
    void markRelease(double time);
    // A kick at `time` (Part::kickMass): the clock starts, and the part is restored at the first
    // observation with zero active springs after one with some (a kick deforms only in the
    // steps after it). A kick too weak to activate a spring leaves the part never restored:
    // check maxActive().
    void markKick(double time);

    double threshold() const { return threshold_; }
    std::size_t activeNow() const { return activeNow_; }
    std::size_t maxActive() const { return maxActive_; }
    std::size_t totalDistinct() const { return totalDistinct_; }
    // Seconds from the release to the first observation with zero active springs; nullopt
    // while not yet restored (or not released).
    std::optional<double> restorationTime() const { return restorationTime_; }

private:
    void countIfActive(const PartModel& model, const PartState& state, Index spring);
    // InputError unless the state and the tracker fit the model.
    void requireObservable(const PartModel& model, const PartState& state) const;
    std::size_t finishObservation(const PartState& state);

    double threshold_;
    std::vector<unsigned char> everActive_;  // (E)
    std::size_t activeNow_ = 0;
    std::size_t maxActive_ = 0;
    std::size_t totalDistinct_ = 0;
    std::optional<double> releaseTime_;
    std::optional<double> restorationTime_;
    bool awaitActivity_ = false;       // after a kick: restored only once something was active
    bool activeSinceRelease_ = false;
};

}  // namespace flexfit
