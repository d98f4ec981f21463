// One full-MSD step of torus1, torus2 and heart: Flexfit's struct-of-arrays step against the
// thesis-style naive array-of-structs reference (tests/support/naive_msd.hpp), same physics,
// same meshes, in one run. Counters: steps/s and spring updates/s. Single thread.
#include "flexfit/flexfit.hpp"
#include "naive_msd.hpp"

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
    const auto model = flexfit::buildPartModel(mesh, {flexfit::Material::elastic(), 1.0, {}, {}});
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
    std::vector<double> vertices;
    std::vector<unsigned> faces;
    for (const auto& v : mesh.vertices) vertices.insert(vertices.end(), {v.x(), v.y(), v.z()});
    for (const auto& f : mesh.faces) faces.insert(faces.end(), {f[0], f[1], f[2]});
    const flexfit::Material m = flexfit::Material::elastic();
    naive::Model model(vertices, faces, 1.0, m.stiffness, m.damping);
    for (auto _ : state) {
        model.step(1e-3, naive::Vector3D(0, -9.81, 0), 0.1);
        benchmark::DoNotOptimize(model.masses[0]->position.x);
    }
    setCounters(state, std::size_t(model.numOfSprings));
}

// Interleaved per mesh so that both implementations see the same machine state.
BENCHMARK(BM_FlexfitFullStep)->Arg(0);
BENCHMARK(BM_NaiveFullStep)->Arg(0);
BENCHMARK(BM_FlexfitFullStep)->Arg(1);
BENCHMARK(BM_NaiveFullStep)->Arg(1);
BENCHMARK(BM_FlexfitFullStep)->Arg(2);
BENCHMARK(BM_NaiveFullStep)->Arg(2);

}  // namespace

BENCHMARK_MAIN();
