// Shared by the part benchmarks: the models (torus1, heart), the part settings they step, and
// the paired timing that compares parts inside one benchmark.
#pragma once

#include "flexfit/flexfit.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <optional>
#include <vector>

namespace flexfit::bench {

// 0: torus1, 1: heart; built once.
inline const std::shared_ptr<const PartModel>& modelByIndex(int which) {
    static const std::shared_ptr<const PartModel> models[2] = {buildPartModel(makeTorus1()), buildPartModel(makeHeart())};
    return models[which];
}

// Elastic preset (the models' default), 1 ms steps, restoration constraint c = 0.001.
inline PartSettings settings(PartMode mode) {
    PartSettings s;
    s.mode = mode;
    s.simulation.timeStep = 1e-3;
    s.simulation.restoration.method = RestorationMethod::Constraint;
    s.simulation.restoration.constraintFraction = 1e-3;
    return s;
}

inline double median(std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
}

// What pairedChunkTimes measured: each part's median chunk time (s) in each copy of the set.
struct PairedTimes {
    std::vector<std::vector<double>> medians;  // [copy][part]
    // The time ratio of parts a and b: the geometric mean over the copies.
    double ratio(std::size_t a, std::size_t b) const { return overCopies([&](const auto& m) { return m[a] / m[b]; }); }
    double nsPerStep(std::size_t part, int chunk) const { return 1e9 * overCopies([&](const auto& m) { return m[part]; }) / chunk; }

private:
    // The geometric mean of value(copy's medians) over the copies.
    template <class Value>
    double overCopies(Value value) const {
        double logSum = 0.0;
        for (const auto& m : medians) logSum += std::log(value(m));
        return std::exp(logSum / double(medians.size()));
    }
};

// Chunks of `chunk` steps of every part alternate, each timed apart, so the slow drifts of a
// shared VM fall on all of them alike (separate benchmarks of identical code differed by up to
// 6 % here). Where the allocator puts a part's state moves the vector step's time by up to
// ~7 % (the heart, the same code in two parts: 1.063 with one built first, 0.996 with the
// other), so the set is built `copies` times, copy c in the given order for even c and in the
// reverse one for odd c, rotated by c / 2 (with 4 copies each pair of parts is built in either
// order twice), and ratios are geometric means over the copies.
// load[i]: part i gets a force on mass 0 before each step.
inline PairedTimes pairedChunkTimes(benchmark::State& state, const std::vector<std::function<Part()>>& make,
                                    const std::vector<bool>& load, int chunk, std::size_t copies = 2) {
    const std::size_t n = make.size();
    std::vector<std::vector<Part>> sets(copies);
    for (std::size_t c = 0; c < copies; ++c) {
        std::vector<std::size_t> order(n);
        for (std::size_t k = 0; k < n; ++k) order[k] = (k + c / 2) % n;
        if (c % 2 == 1) std::reverse(order.begin(), order.end());
        std::vector<std::optional<Part>> built(n);
        for (const std::size_t i : order) built[i].emplace(make[i]());
        sets[c].reserve(n);
        for (auto& part : built) sets[c].push_back(std::move(*part));
    }
    std::vector<std::vector<std::vector<double>>> times(copies, std::vector<std::vector<double>>(n));
    auto timeChunk = [chunk](Part& part, bool loaded) {
        const auto start = std::chrono::steady_clock::now();
        for (int i = 0; i < chunk; ++i) {
            if (loaded) part.applyForce(0, Vec3(0, 0.05, 0));
            part.step();
        }
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    for (auto _ : state)  // A B C A B C ...: each chunk follows another part's
        for (std::size_t c = 0; c < copies; ++c)
            for (std::size_t i = 0; i < n; ++i) times[c][i].push_back(timeChunk(sets[c][i], load[i]));
    PairedTimes t;
    for (const auto& copy : times) {
        t.medians.emplace_back();
        for (const auto& partTimes : copy) t.medians.back().push_back(median(partTimes));
    }
    return t;
}

}  // namespace flexfit::bench
