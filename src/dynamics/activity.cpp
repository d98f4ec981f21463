#include "flexfit/activity.hpp"

#include <cmath>

namespace flexfit {

std::size_t countActiveSprings(const PartModel& model, std::span<const Vec3> positions, double threshold) {
    std::size_t active = 0;
    for (std::size_t e = 0; e < model.springCount(); ++e) {
        const double length = (positions[model.springA[e]] - positions[model.springB[e]]).norm();
        active += std::abs(length - model.restLength[e]) > threshold ? 1 : 0;
    }
    return active;
}

ActivityTracker::ActivityTracker(const PartModel& model, double threshold)
    : threshold_(threshold), everActive_(model.springCount(), 0) {
    if (!(threshold > 0.0) || !std::isfinite(threshold))
        throw InputError("activity settings", 0, "activity threshold must be finite and > 0");
}

std::size_t ActivityTracker::observe(const PartModel& model, const PartState& state) {
    activeNow_ = 0;
    for (Index e = 0; e < model.springCount(); ++e) countIfActive(model, state, e);
    return finishObservation(state);
}

std::size_t ActivityTracker::observe(const PartModel& model, const PartState& state, std::span<const Index> springs) {
    activeNow_ = 0;
    for (Index e : springs) countIfActive(model, state, e);
    return finishObservation(state);
}

void ActivityTracker::countIfActive(const PartModel& model, const PartState& state, Index e) {
    const double length = (state.positions[model.springA[e]] - state.positions[model.springB[e]]).norm();
    if (!(std::abs(length - model.restLength[e]) > threshold_)) return;
    ++activeNow_;
    if (everActive_[e] == 0) {
        everActive_[e] = 1;
        ++totalDistinct_;
    }
}

std::size_t ActivityTracker::finishObservation(const PartState& state) {
    maxActive_ = std::max(maxActive_, activeNow_);
    if (activeNow_ > 0) activeSinceRelease_ = true;
    if (releaseTime_ && !restorationTime_ && activeNow_ == 0 && (activeSinceRelease_ || !awaitActivity_))
        restorationTime_ = state.time - *releaseTime_;
    return activeNow_;
}

void ActivityTracker::markRelease(double time) {
    releaseTime_ = time;
    restorationTime_.reset();
    awaitActivity_ = false;
    if (activeNow_ == 0) restorationTime_ = 0.0;  // nothing was deformed at the release
}

void ActivityTracker::markKick(double time) {
    releaseTime_ = time;
    restorationTime_.reset();
    awaitActivity_ = true;
    activeSinceRelease_ = activeNow_ > 0;
}

}  // namespace flexfit
