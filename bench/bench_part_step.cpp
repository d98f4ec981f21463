// Rigid-deformable part steps (issue: cost proportional to the active region), side by side in
// one run: the full MSD step, one zone at level 1, zones covering the whole mesh, and untouched
// parts of different sizes. Every stepping case loads one mass per step (an operator force).
#include "flexfit/flexfit.hpp"
#include "part_bench_support.hpp"

#include <benchmark/benchmark.h>


namespace {

using namespace flexfit;

using flexfit::bench::modelByIndex;
using flexfit::bench::settings;

void stepLoaded(benchmark::State& state, Part& part) {
    StepCounters counters;
    for (auto _ : state) {
        part.applyForce(0, Vec3(0, 0.05, 0));
        part.step(&counters);
    }
    state.SetLabel(part.model().name);
    state.counters["moving_masses"] = double(part.movingMasses().size());
    state.counters["computed_springs"] = double(part.computedSprings().size());
    state.counters["springs_per_step"] = double(counters.springsEvaluated) / double(state.iterations());
}

void BM_FullDeformable(benchmark::State& state) {
    Part part(modelByIndex(int(state.range(0))), settings(PartMode::FullDeformable));
    stepLoaded(state, part);
}

void BM_OneZoneLevel1(benchmark::State& state) {
    Part part(modelByIndex(int(state.range(0))), settings(PartMode::RigidDeformable));
    part.openZone(ZoneSeed::mass(0), 1);
    stepLoaded(state, part);
}

void BM_ZonesCoverWholeMesh(benchmark::State& state) {
    Part part(modelByIndex(int(state.range(0))), settings(PartMode::RigidDeformable));
    part.openZone(ZoneSeed::mass(0), 255);
    if (part.movingMasses().size() != part.model().massCount()) state.SkipWithError("zone does not cover the mesh");
    stepLoaded(state, part);
}

void BM_Untouched(benchmark::State& state) {
    Part part(modelByIndex(int(state.range(0))), settings(PartMode::RigidDeformable));
    StepCounters counters;
    for (auto _ : state) {
        part.step(&counters);
        benchmark::DoNotOptimize(part.state().stepCount);
    }
    state.SetLabel(part.model().name);
    // The same counters as the other cases (the CSV reporter needs one set per run).
    state.counters["moving_masses"] = double(part.movingMasses().size());
    state.counters["computed_springs"] = double(part.computedSprings().size());
    state.counters["springs_per_step"] = double(counters.springsEvaluated) / double(state.iterations());
}

BENCHMARK(BM_FullDeformable)->Arg(1);
BENCHMARK(BM_OneZoneLevel1)->Arg(1);
BENCHMARK(BM_ZonesCoverWholeMesh)->Arg(1);
BENCHMARK(BM_FullDeformable)->Arg(0);
BENCHMARK(BM_ZonesCoverWholeMesh)->Arg(0);
BENCHMARK(BM_Untouched)->Arg(0);
BENCHMARK(BM_Untouched)->Arg(1);

}  // namespace

BENCHMARK_MAIN();
