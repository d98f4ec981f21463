// The three ratios of the rigid-deformable issue, each measured as a pair inside one
// benchmark: chunks of steps of part A and part B alternate and are timed separately; the
// counter a_over_b is the ratio of their median chunk times. Both parts see the same machine
// state, so the slow drifts of a shared VM cancel out (separate benchmarks of identical code
// differed by up to 6 % here).
#include "flexfit/flexfit.hpp"
#include "part_bench_support.hpp"

#include <benchmark/benchmark.h>

namespace {

using namespace flexfit;

using flexfit::bench::modelByIndex;
using flexfit::bench::settings;

// Parts A and B, in alternating chunks and built in both orders (pairedChunkTimes): a_over_b
// is the geometric mean of the two orders' ratios, each also reported.
template <class MakeA, class MakeB>
void paired(benchmark::State& state, MakeA makeA, MakeB makeB, int chunk, bool loadA, bool loadB) {
    const flexfit::bench::PairedTimes t = flexfit::bench::pairedChunkTimes(state, {makeA, makeB}, {loadA, loadB}, chunk);
    state.counters["a_over_b"] = t.ratio(0, 1);
    state.counters["a_over_b_a_built_first"] = t.medians[0][0] / t.medians[0][1];
    state.counters["a_over_b_b_built_first"] = t.medians[1][0] / t.medians[1][1];
    state.counters["a_ns_per_step"] = t.nsPerStep(0, chunk);
    state.counters["b_ns_per_step"] = t.nsPerStep(1, chunk);
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
