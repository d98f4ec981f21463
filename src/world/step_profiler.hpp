// Internal to src/world: charges a world step's time to its stages (profile.hpp).
//
// One clock reading per switch of stage: the reading that ends a stage starts the next, so no
// instant between the first reading and the last is charged twice or dropped, and the stages
// add up to the step (in whole nanoseconds, exactly). Work of one stage done inside another
// (the rigid motion's sub-step queries) enters its own stage and then the outer one again, so
// it is charged once, to itself.
#pragma once

#include "flexfit/profile.hpp"

#include <chrono>

namespace flexfit::detail {

class StepProfiler {
public:
    // The step starts now, in `first`.
    StepProfiler(Profile& profile, Stage first) : profile_(profile), running_(first), start_(Clock::now()), switched_(start_) {}
    StepProfiler(const StepProfiler&) = delete;
    StepProfiler& operator=(const StepProfiler&) = delete;

    // Charges the time since the last switch to the running stage; `stage` runs from now.
    void enter(Stage stage) {
        const Clock::time_point now = Clock::now();
        nanoseconds_[std::size_t(running_)] += (now - switched_).count();
        switched_ = now;
        running_ = stage;
    }
    Stage running() const { return running_; }

    // Charges the running stage and writes the step into the profile.
    void finish() {
        enter(running_);
        const double scale = 1e-9;
        for (std::size_t s = 0; s < kStageCount; ++s) {
            profile_.lastSeconds[s] = double(nanoseconds_[s]) * scale;
            profile_.totalSeconds[s] += profile_.lastSeconds[s];
        }
        profile_.lastStepSeconds = double((switched_ - start_).count()) * scale;
        profile_.totalStepSeconds += profile_.lastStepSeconds;
    }

private:
    using Clock = std::chrono::steady_clock;
    using Nanoseconds = std::chrono::nanoseconds::rep;
    static_assert(std::is_same_v<Clock::duration, std::chrono::nanoseconds>, "the profile counts whole nanoseconds");

    Profile& profile_;
    Stage running_;
    Clock::time_point start_, switched_;
    std::array<Nanoseconds, kStageCount> nanoseconds_{};
};

}  // namespace flexfit::detail
