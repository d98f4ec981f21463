// The three ratios of the rigid-deformable issue, each measured as a pair inside one
// benchmark: chunks of steps of part A and part B alternate and are timed separately; the
// counter a_over_b is the ratio of their median chunk times. Both parts see the same machine
// state, so the slow drifts of a shared VM cancel out (separate benchmarks of identical code
// differed by up to 6 % here).
#include "flexfit/flexfit.hpp"
#include "part_bench_support.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

namespace {

using namespace flexfit;

using flexfit::bench::modelByIndex;
using flexfit::bench::settings;

double median(std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
}

// Parts A and B are built twice, once in each order: where the allocator puts a part's state
// moves the vector full step's time by up to ~7% (heart, the same code in both parts: 1.063
// with A built first, 0.996 with B first), so a_over_b is the geometric mean of both orders.
template <class MakeA, class MakeB>
void paired(benchmark::State& state, MakeA makeA, MakeB makeB, int chunk, bool loadA, bool loadB) {
    Part a1 = makeA(), b1 = makeB();
    Part b2 = makeB(), a2 = makeA();
    std::vector<double> ta1, tb1, ta2, tb2;
    auto timeChunk = [chunk](Part& part, bool load) {
        const auto start = std::chrono::steady_clock::now();
        for (int i = 0; i < chunk; ++i) {
            if (load) part.applyForce(0, Vec3(0, 0.05, 0));
            part.step();
        }
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    for (auto _ : state) {
        ta1.push_back(timeChunk(a1, loadA));
        tb1.push_back(timeChunk(b1, loadB));
        ta2.push_back(timeChunk(a2, loadA));
        tb2.push_back(timeChunk(b2, loadB));
    }
    const double first = median(ta1) / median(tb1), second = median(ta2) / median(tb2);
    state.counters["a_over_b"] = std::sqrt(first * second);
    state.counters["a_over_b_a_built_first"] = first;
    state.counters["a_over_b_b_built_first"] = second;
    state.counters["a_ns_per_step"] = 1e9 * std::sqrt(median(ta1) * median(ta2)) / chunk;
    state.counters["b_ns_per_step"] = 1e9 * std::sqrt(median(tb1) * median(tb2)) / chunk;
}

void BM_PairedFullOverOneZone(benchmark::State& state) {
    const auto heart = modelByIndex(1);
    paired(
        state, [&] { return Part(heart, settings(PartMode::FullDeformable)); },
        [&] {
            Part p(heart, settings(PartMode::RigidDeformable));
            p.openZone(ZoneSeed::mass(0), 1);
            return p;
        },
        1, true, true);
    state.SetLabel("heart: full MSD / one zone at level 1");
}

void BM_PairedWholeCoverOverFull(benchmark::State& state) {
    const auto model = modelByIndex(int(state.range(0)));
    paired(
        state,
        [&] {
            Part p(model, settings(PartMode::RigidDeformable));
            p.openZone(ZoneSeed::mass(0), 255);
            return p;
        },
        [&] { return Part(model, settings(PartMode::FullDeformable)); }, 4, true, true);
    state.SetLabel(model->name + ": zones covering the mesh / full MSD");
}

void BM_PairedUntouchedHeartOverTorus1(benchmark::State& state) {
    paired(
        state, [] { return Part(modelByIndex(1), settings(PartMode::RigidDeformable)); },
        [] { return Part(modelByIndex(0), settings(PartMode::RigidDeformable)); }, 1000, false, false);
    state.SetLabel("untouched heart / untouched torus1");
}

BENCHMARK(BM_PairedFullOverOneZone);
BENCHMARK(BM_PairedWholeCoverOverFull)->Arg(1)->Arg(0);
BENCHMARK(BM_PairedUntouchedHeartOverTorus1);
}  // namespace

BENCHMARK_MAIN();
