#include "flexfit/activity.hpp"

#include <cmath>
#include <string>

namespace flexfit {

namespace {
void requirePositions(const PartModel& model, std::size_t count, const char* what) {
    if (count != model.massCount())
        throw InputError("activity", 0, std::string(what) + ": " + std::to_string(count) + " positions for a model of " +
                                            std::to_string(model.massCount()) + " masses");
}
}  // namespace

std::size_t countActiveSprings(const PartModel& model, std::span<const Vec3> positions, double threshold) {
    requirePositions(model, positions.size(), "countActiveSprings");
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
    requireObservable(model, state);
    activeNow_ = 0;
    for (Index e = 0; e < model.springCount(); ++e) countIfActive(model, state, e);
    return finishObservation(state);
}

std::size_t ActivityTracker::observe(const PartModel& model, const PartState& state, std::span<const Index> springs) {
    requireObservable(model, state);
    for (Index e : springs)
        if (e >= model.springCount())
            throw InputError("activity", 0, "observe: spring " + std::to_string(e) + " does not exist (the model has " +
                                                std::to_string(model.springCount()) + " springs)");
    activeNow_ = 0;
    for (Index e : springs) countIfActive(model, state, e);
    return finishObservation(state);
}

void ActivityTracker::requireObservable(const PartModel& model, const PartState& state) const {
    requirePositions(model, state.positions.size(), "observe");
    if (everActive_.size() != model.springCount())
        throw InputError("activity", 0, "observe: the tracker was made for a model of " + std::to_string(everActive_.size()) +
                                            " springs, this one has " + std::to_string(model.springCount()));
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
