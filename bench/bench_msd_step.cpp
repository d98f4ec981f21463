// One full-MSD step of torus1, torus2 and heart, the heart with its vertices shuffled (as given,
// and renumbered by the model build's VertexOrder::Locality), and a third-party mesh (Debian's
// assimp-testmodels Wuson, as the file orders its vertices, renumbered by VertexOrder::Locality,
// and remeshed at 0.5 % of its size in CGAL's order and renumbered): Flexfit's step against the
// thesis-style naive array-of-structs reference (tests/support/naive_msd.hpp), same physics, in
// one run. The naive reference steps the mesh as given (the file's order): a renumbered row is
// what a user with that file gets. Also the step with its scalar and AVX2 kernels forced
// (stepFullModel itself uses AVX-512 where the CPU has it).
// Counters: steps/s and spring updates/s. Single thread.
#include "dynamics/flush_denormals.hpp"
#include "dynamics/full_step.hpp"
#include "flexfit/flexfit.hpp"
#include "naive_from_mesh.hpp"
#include "shuffled_mesh.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <vector>

namespace {

using flexfit::TriMesh;

constexpr const char* kThirdParty = "/usr/share/assimp/models/OFF/Wuson.off";

TriMesh thirdParty() {
    return std::filesystem::exists(kThirdParty) ? flexfit::readMesh(kThirdParty).mesh : TriMesh{};
}

TriMesh named(TriMesh mesh, const std::string& name) {
    mesh.name = name;
    return mesh;
}

// Empty when the third-party file is not installed.
const TriMesh& meshByIndex(int which) {
    static const std::array<TriMesh, 9> meshes = [] {
        const TriMesh shuffledHeart = named(flexfit::testing::shuffledVertices(flexfit::makeHeart(), 3), "heart shuffled");
        const TriMesh wuson = thirdParty();
        const double diagonal = wuson.vertices.empty() ? 0.0 : flexfit::Aabb::around(wuson.vertices).size();
        const TriMesh remeshed = wuson.vertices.empty() ? TriMesh{}
            : named(flexfit::remeshForSimulation(wuson, {0.005 * diagonal}, kThirdParty).mesh, "Wuson remeshed 0.5%");
        return std::array<TriMesh, 9>{flexfit::makeTorus1(), flexfit::makeTorus2(), flexfit::makeHeart(), shuffledHeart,
                                      named(shuffledHeart, "heart shuffled, locality order"), named(wuson, "Wuson"),
                                      named(wuson, "Wuson, locality order"), remeshed, named(remeshed, "Wuson remeshed 0.5%, locality order")};
    }();
    return meshes[std::size_t(which)];
}

// The rows whose model is built with VertexOrder::Locality (the naive reference keeps the order).
bool inLocalityOrder(int which) { return which == 4 || which == 6 || which == 8; }

std::shared_ptr<const flexfit::PartModel> flexfitModel(int which) {
    flexfit::PartModelSettings settings;  // the elastic preset, 1 kg masses
    if (inLocalityOrder(which)) settings.vertexOrder = flexfit::VertexOrder::Locality;
    return flexfit::buildPartModel(meshByIndex(which), settings);
}

bool skipMissing(benchmark::State& state, const TriMesh& mesh) {
    if (!mesh.faces.empty()) return false;
    state.SkipWithError("third-party mesh not installed (assimp-testmodels)");
    return true;
}

flexfit::SimulationSettings benchSettings() {
    flexfit::SimulationSettings s;
    s.timeStep = 1e-3;
    s.gravity = flexfit::Vec3(0, -9.81, 0);
    s.globalDamping = 0.1;
    s.restoration.method = flexfit::RestorationMethod::None;
    return s;
}

// Share of the model's springs in spring blocks (0 for the naive reference, which has none).
double blockedShare(const flexfit::PartModel& model) {
    return double(model.springBlocks->blockedSprings()) / double(model.springCount());
}

void setCounters(benchmark::State& state, std::size_t springs, double inBlocks) {
    state.counters["in_blocks"] = inBlocks;
    state.counters["steps_per_s"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["spring_updates_per_s"] =
        benchmark::Counter(double(state.iterations()) * double(springs), benchmark::Counter::kIsRate);
    state.counters["springs"] = double(springs);
}

void BM_FlexfitFullStep(benchmark::State& state) {
    const TriMesh& mesh = meshByIndex(int(state.range(0)));
    state.SetLabel(mesh.name);
    if (skipMissing(state, mesh)) return;
    const auto model = flexfitModel(int(state.range(0)));
    const flexfit::SimulationSettings settings = benchSettings();
    flexfit::PartState partState = flexfit::PartState::atRest(*model);
    for (auto _ : state) {
        flexfit::stepFullModel(*model, settings, {}, partState);
        benchmark::DoNotOptimize(partState.positions.data());
    }
    setCounters(state, model->springCount(), blockedShare(*model));
}

void BM_NaiveFullStep(benchmark::State& state) {
    const TriMesh& mesh = meshByIndex(int(state.range(0)));
    state.SetLabel(mesh.name);
    if (skipMissing(state, mesh)) return;
    const flexfit::Material m = flexfit::Material::elastic();
    const auto owned = naive::modelFromMesh(mesh, 1.0, m.stiffness, m.damping);
    naive::Model& model = *owned;
    for (auto _ : state) {
        model.step(1e-3, naive::Vector3D(0, -9.81, 0), 0.1);
        benchmark::DoNotOptimize(model.masses[0]->position.x);
    }
    setCounters(state, std::size_t(model.numOfSprings), 0.0);
}

// The full step with a kernel forced (stepFullModel picks the widest).
void runDetailStep(benchmark::State& state, flexfit::detail::BlockKernel kernel) {
    const TriMesh& mesh = meshByIndex(int(state.range(0)));
    state.SetLabel(mesh.name);
    if (skipMissing(state, mesh)) return;
    if (!flexfit::detail::blockKernelAvailable(kernel)) {
        state.SkipWithError("kernel not supported by this CPU");
        return;
    }
    const auto model = flexfitModel(int(state.range(0)));
    const auto update = flexfit::detail::MassUpdate::from(benchSettings());
    flexfit::PartState partState = flexfit::PartState::atRest(*model);
    const flexfit::detail::FlushDenormals flush;  // as stepFullModel
    for (auto _ : state) {
        flexfit::detail::stepSpringBlocks(*model, update, partState, kernel);
        benchmark::DoNotOptimize(partState.positions.data());
    }
    setCounters(state, model->springCount(), blockedShare(*model));
}

void BM_FlexfitScalar(benchmark::State& state) { runDetailStep(state, flexfit::detail::BlockKernel::Scalar); }
void BM_FlexfitAvx2(benchmark::State& state) { runDetailStep(state, flexfit::detail::BlockKernel::Avx2); }

// With repetitions, "_min" rows beside the median: each benchmark's fastest repetition, the
// work's own cost (the floor, as tools/tail_repeats.py's). A VM's stalls move a median (this
// one's Wuson ratio read 2.47x and 2.16x minutes apart); `tools/bench_ratios.py --statistic
// min` gives the ratios of the floors.
double fastest(const std::vector<double>& values) {
    return values.empty() ? 0.0 : *std::min_element(values.begin(), values.end());
}

// Interleaved per mesh so that all implementations see the same machine state.
#define FLEXFIT_MSD_BENCHMARKS(mesh)                                               \
    BENCHMARK(BM_FlexfitFullStep)->Arg(mesh)->ComputeStatistics("min", fastest);  \
    BENCHMARK(BM_NaiveFullStep)->Arg(mesh)->ComputeStatistics("min", fastest);    \
    BENCHMARK(BM_FlexfitAvx2)->Arg(mesh)->ComputeStatistics("min", fastest);      \
    BENCHMARK(BM_FlexfitScalar)->Arg(mesh)->ComputeStatistics("min", fastest)
FLEXFIT_MSD_BENCHMARKS(0);
FLEXFIT_MSD_BENCHMARKS(1);
FLEXFIT_MSD_BENCHMARKS(2);
FLEXFIT_MSD_BENCHMARKS(3);
FLEXFIT_MSD_BENCHMARKS(4);
FLEXFIT_MSD_BENCHMARKS(5);
FLEXFIT_MSD_BENCHMARKS(6);
FLEXFIT_MSD_BENCHMARKS(7);
FLEXFIT_MSD_BENCHMARKS(8);

}  // namespace

BENCHMARK_MAIN();
