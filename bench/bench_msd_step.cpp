// One full-MSD step of torus1, torus2 and heart: Flexfit's step against the thesis-style naive
// array-of-structs reference (tests/support/naive_msd.hpp), same physics, same meshes, in one
// run. Also each way of the step forced: the per-mass sweep, and the spring blocks with the
// scalar and AVX2 kernels (stepFullModel itself uses AVX-512 where the CPU has it).
// Counters: steps/s and spring updates/s. Single thread.
#include "dynamics/flush_denormals.hpp"
#include "dynamics/full_step.hpp"
#include "flexfit/flexfit.hpp"
#include "naive_from_mesh.hpp"

#include <benchmark/benchmark.h>

namespace {

using flexfit::TriMesh;

const TriMesh& meshByIndex(int which) {
    static const TriMesh meshes[3] = {flexfit::makeTorus1(), flexfit::makeTorus2(), flexfit::makeHeart()};
    return meshes[which];
}

flexfit::SimulationSettings benchSettings() {
    flexfit::SimulationSettings s;
    s.timeStep = 1e-3;
    s.gravity = flexfit::Vec3(0, -9.81, 0);
    s.globalDamping = 0.1;
    s.restoration.method = flexfit::RestorationMethod::None;
    return s;
}

void setCounters(benchmark::State& state, std::size_t springs) {
    state.counters["steps_per_s"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["spring_updates_per_s"] =
        benchmark::Counter(double(state.iterations()) * double(springs), benchmark::Counter::kIsRate);
    state.counters["springs"] = double(springs);
}

void BM_FlexfitFullStep(benchmark::State& state) {
    const TriMesh& mesh = meshByIndex(int(state.range(0)));
    state.SetLabel(mesh.name);
    const auto model = flexfit::buildPartModel(mesh, {flexfit::Material::elastic(), 1.0, {}, {}, {}});
    const flexfit::SimulationSettings settings = benchSettings();
    flexfit::PartState partState = flexfit::PartState::atRest(*model);
    for (auto _ : state) {
        flexfit::stepFullModel(*model, settings, {}, partState);
        benchmark::DoNotOptimize(partState.positions.data());
    }
    setCounters(state, model->springCount());
}

void BM_NaiveFullStep(benchmark::State& state) {
    const TriMesh& mesh = meshByIndex(int(state.range(0)));
    state.SetLabel(mesh.name);
    const flexfit::Material m = flexfit::Material::elastic();
    const auto owned = naive::modelFromMesh(mesh, 1.0, m.stiffness, m.damping);
    naive::Model& model = *owned;
    for (auto _ : state) {
        model.step(1e-3, naive::Vector3D(0, -9.81, 0), 0.1);
        benchmark::DoNotOptimize(model.masses[0]->position.x);
    }
    setCounters(state, std::size_t(model.numOfSprings));
}

// The two ways of the full step, forced (stepFullModel picks blocks and the widest kernel).
void runDetailStep(benchmark::State& state, bool sweep, flexfit::detail::BlockKernel kernel) {
    const TriMesh& mesh = meshByIndex(int(state.range(0)));
    state.SetLabel(mesh.name);
    if (!sweep && !flexfit::detail::blockKernelAvailable(kernel)) {
        state.SkipWithError("kernel not supported by this CPU");
        return;
    }
    const auto model = flexfit::buildPartModel(mesh, {flexfit::Material::elastic(), 1.0, {}, {}, {}});
    const auto update = flexfit::detail::MassUpdate::from(benchSettings());
    flexfit::PartState partState = flexfit::PartState::atRest(*model);
    const flexfit::detail::FlushDenormals flush;  // as stepFullModel
    for (auto _ : state) {
        if (sweep)
            flexfit::detail::sweepFullModel(*model, update, partState);
        else
            flexfit::detail::stepSpringBlocks(*model, update, partState, kernel);
        benchmark::DoNotOptimize(partState.positions.data());
    }
    setCounters(state, model->springCount());
}

void BM_FlexfitSweep(benchmark::State& state) { runDetailStep(state, true, flexfit::detail::BlockKernel::Scalar); }
void BM_FlexfitBlocksScalar(benchmark::State& state) {
    runDetailStep(state, false, flexfit::detail::BlockKernel::Scalar);
}
void BM_FlexfitBlocksAvx2(benchmark::State& state) { runDetailStep(state, false, flexfit::detail::BlockKernel::Avx2); }

// Interleaved per mesh so that all implementations see the same machine state.
#define FLEXFIT_MSD_BENCHMARKS(mesh)                     \
    BENCHMARK(BM_FlexfitFullStep)->Arg(mesh);            \
    BENCHMARK(BM_NaiveFullStep)->Arg(mesh);              \
    BENCHMARK(BM_FlexfitSweep)->Arg(mesh);               \
    BENCHMARK(BM_FlexfitBlocksAvx2)->Arg(mesh);          \
    BENCHMARK(BM_FlexfitBlocksScalar)->Arg(mesh)
FLEXFIT_MSD_BENCHMARKS(0);
FLEXFIT_MSD_BENCHMARKS(1);
FLEXFIT_MSD_BENCHMARKS(2);

}  // namespace

BENCHMARK_MAIN();
