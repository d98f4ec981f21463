// The step profiler (src/world/step_profiler.hpp): a stage's time is the time it ran, a stage
// entered twice adds up, work nested in another stage is charged to itself, and the stages
// add up to the step exactly.
#include "world/step_profiler.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <chrono>

using namespace flexfit;

namespace {

// Runs for at least `seconds` by the same clock as the profiler.
void busy(double seconds) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                              std::chrono::duration<double>(seconds));
    while (std::chrono::steady_clock::now() < until) {
    }
}

double at(const Profile& p, Stage s) { return p.lastSeconds[std::size_t(s)]; }

}  // namespace

TEST(StepProfiler, StagesAreChargedWhatTheyRanAndAddUpToTheStep) {
    Profile profile;
    {
        detail::StepProfiler profiler(profile, Stage::RigidMotion);
        busy(2e-3);
        profiler.enter(Stage::NarrowPhase);  // nested in the rigid motion, then back to it
        busy(1e-3);
        profiler.enter(Stage::RigidMotion);
        busy(1e-3);
        profiler.enter(Stage::Assembly);
        profiler.finish();
    }
    EXPECT_GE(at(profile, Stage::RigidMotion), 3e-3);
    EXPECT_GE(at(profile, Stage::NarrowPhase), 1e-3);
    EXPECT_LT(at(profile, Stage::NarrowPhase), at(profile, Stage::RigidMotion));
    EXPECT_EQ(at(profile, Stage::BroadPhase), 0.0);  // never entered
    double sum = 0.0;
    for (double s : profile.lastSeconds) sum += s;
    EXPECT_NEAR(sum, profile.lastStepSeconds, 1e-12);
    EXPECT_GE(profile.lastStepSeconds, 4e-3);
}

TEST(StepProfiler, LastHoldsOneStepAndTotalEvery) {
    Profile profile;
    double lasts = 0.0;
    for (int step = 0; step < 3; ++step) {
        detail::StepProfiler profiler(profile, Stage::ZoneDynamics);
        busy(1e-3);
        profiler.enter(Stage::ZoneRetirement);
        profiler.finish();
        EXPECT_GE(at(profile, Stage::ZoneDynamics), 1e-3);
        EXPECT_NEAR(at(profile, Stage::ZoneDynamics) + at(profile, Stage::ZoneRetirement), profile.lastStepSeconds, 1e-12);
        lasts += profile.lastStepSeconds;
    }
    EXPECT_NEAR(profile.totalStepSeconds, lasts, 1e-12);
    EXPECT_NEAR(profile.totalStepSeconds,
                profile.totalSeconds[std::size_t(Stage::ZoneDynamics)] + profile.totalSeconds[std::size_t(Stage::ZoneRetirement)], 1e-12);
    EXPECT_GE(profile.totalSeconds[std::size_t(Stage::ZoneDynamics)], 3e-3);
}

TEST(StepProfiler, NearestRankPercentileAgainstItsDefinition) {
    // The smallest value v of the list with at least p % of the values <= v, found by brute
    // force over every value and compared with the function, on random lists with ties.
    std::mt19937 rng(7);
    for (int trial = 0; trial < 200; ++trial) {
        std::vector<double> values(std::size_t(1 + rng() % 50));
        for (double& v : values) v = double(rng() % 20);
        for (double p : {1.0, 50.0, 99.0, 100.0, 33.3}) {
            double expected = std::numeric_limits<double>::infinity();
            for (double candidate : values) {
                const auto atMost = std::count_if(values.begin(), values.end(), [&](double v) { return v <= candidate; });
                if (double(atMost) >= p / 100.0 * double(values.size()) - 1e-12) expected = std::min(expected, candidate);
            }
            EXPECT_EQ(nearestRankPercentile(values, p), expected) << "p " << p << " n " << values.size();
        }
    }
    EXPECT_TRUE(std::isnan(nearestRankPercentile({}, 50.0)));
    EXPECT_TRUE(std::isnan(nearestRankPercentile({1.0}, 0.0)));
    EXPECT_EQ(nearestRankPercentile({3.0, 1.0, 2.0}, 100.0), 3.0);
}
