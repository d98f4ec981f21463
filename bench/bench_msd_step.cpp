// One full-MSD step of torus1, torus2 and heart: Flexfit's struct-of-arrays step against the
// thesis-style naive array-of-structs reference (tests/support/naive_msd.hpp), same physics,
// same meshes, in one run; and the load/store floor of such a step (see BM_LoadStoreFloor).
// Counters: steps/s and spring updates/s. Single thread.
#include "flexfit/flexfit.hpp"
#include "naive_msd.hpp"

#include <benchmark/benchmark.h>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

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

// Not a simulator: the loads and stores that any full step over this state must do, with the
// spring force replaced by a plain sum (no sqrt, no divide, no constants). For every spring it
// reads both ends' positions and velocities and updates both ends' forces; then it integrates
// every mass. Any real step does at least this memory work, so naive / floor bounds the
// speed-up that code can reach over the naive reference on this machine with double-precision
// Vec3 state. The sign makes it a damped diffusion, so values stay bounded over any run.
void loadStoreFloorStep(const flexfit::PartModel& model, double h, flexfit::PartState& state) {
    const std::size_t springs = model.springCount(), masses = model.massCount();
    const flexfit::Index* springA = model.springA.data();
    const flexfit::Index* springB = model.springB.data();
    double* __restrict x = state.positions.data()->data();
    double* __restrict v = state.velocities.data()->data();
    double* __restrict f = state.forces.data()->data();
    for (std::size_t e = 0; e < springs; ++e) {
        const std::size_t a = 3 * std::size_t(springA[e]), b = 3 * std::size_t(springB[e]);
        for (std::size_t c = 0; c < 3; ++c) {
            const double g = (x[b + c] - x[a + c]) + (v[b + c] - v[a + c]);
            f[a + c] += g;
            f[b + c] -= g;
        }
    }
    for (std::size_t j = 0; j < 3 * masses; ++j) {
        v[j] += h * f[j];
        f[j] = 0.0;
        x[j] += h * v[j];
    }
}

void BM_LoadStoreFloor(benchmark::State& state) {
    const TriMesh& mesh = meshByIndex(int(state.range(0)));
    state.SetLabel(mesh.name);
    const auto model = flexfit::buildPartModel(mesh, {flexfit::Material::elastic(), 1.0, {}, {}});
    flexfit::PartState partState = flexfit::PartState::atRest(*model);
    partState.velocities[0] = flexfit::Vec3(1.0, 0.0, 0.0);
#if defined(__SSE2__)
    const unsigned savedMode = _mm_getcsr();  // flush denormals, as the library's step does
    _mm_setcsr(savedMode | 0x8040u);
#endif
    for (auto _ : state) {
        loadStoreFloorStep(*model, 1e-3, partState);
        benchmark::DoNotOptimize(partState.positions.data());
    }
#if defined(__SSE2__)
    _mm_setcsr(savedMode);
#endif
    setCounters(state, model->springCount());
}

// Interleaved per mesh so that both implementations see the same machine state.
BENCHMARK(BM_FlexfitFullStep)->Arg(0);
BENCHMARK(BM_NaiveFullStep)->Arg(0);
BENCHMARK(BM_LoadStoreFloor)->Arg(0);
BENCHMARK(BM_FlexfitFullStep)->Arg(1);
BENCHMARK(BM_NaiveFullStep)->Arg(1);
BENCHMARK(BM_LoadStoreFloor)->Arg(1);
BENCHMARK(BM_FlexfitFullStep)->Arg(2);
BENCHMARK(BM_NaiveFullStep)->Arg(2);
BENCHMARK(BM_LoadStoreFloor)->Arg(2);

}  // namespace

BENCHMARK_MAIN();
