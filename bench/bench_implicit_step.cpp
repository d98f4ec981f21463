// The implicit region step (issue 17) against the explicit one on the same zone, in one run:
// a band of about 2,000 moving masses of the heart (its springs to the held masses included),
// stepped by symplectic Euler and by implicit Euler at fixed budgets of 5 and 20
// conjugate-gradient iterations (tolerance 0: a deterministic cost). Counters: time per
// computed spring, and the residual the budget reached. The stiff case is issue 17's goal: the
// same zone with k = 1e6 N/m and 1 g masses at 1 kHz (explicit Euler diverges there), under a
// pressing load.
#include "flexfit/flexfit.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>

namespace {

using namespace flexfit;

constexpr Index kZoneMasses = 2000;

std::shared_ptr<const PartModel> heart(double stiffness, double mass) {
    return buildPartModel(makeHeart(), {Material{stiffness, 0.01 * std::sqrt(stiffness * mass)}, mass, {}, {}, {}, {}});
}

// 0: symplectic Euler; otherwise implicit Euler with that many iterations. Range 1: 0 for the
// elastic preset at 1 kg, 1 for k = 1e6 at 1 g.
void BM_ZoneStep(benchmark::State& state) {
    const int iterations = int(state.range(0));
    const bool stiff = state.range(1) != 0;
    const auto model = stiff ? heart(1e6, 1e-3) : heart(Material::elastic().stiffness, 1.0);
    ActiveRegion region(*model);
    for (Index m = 2000; m < 2000 + kZoneMasses; ++m) region.cover(m);
    SimulationSettings s;
    s.timeStep = 1e-3;
    s.restoration.method = RestorationMethod::Constraint;
    s.integrator = iterations == 0 ? Integrator::SemiImplicitEuler : Integrator::ImplicitEuler;
    s.implicit.maxIterations = std::max(iterations, 1);
    s.implicit.tolerance = 0.0;
    if (iterations == 0 && analyzeStability(*model, s).certainlyUnstable) {
        state.SkipWithError("the explicit step diverges at this stiffness and time step");
        return;
    }
    PartState partState = PartState::atRest(*model);
    StepCounters counters;
    const Index loaded = 3000;
    for (auto _ : state) {
        partState.forces[loaded] += Vec3(0.0, stiff ? 50.0 : 0.05, 0.0);
        stepActiveRegion(*model, s, region, partState, &counters);
        benchmark::DoNotOptimize(partState.positions.data());
    }
    state.counters["ns_per_computed_spring"] = benchmark::Counter(
        double(state.iterations()) * double(region.springs().size()), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
    state.counters["computed_springs"] = double(region.springs().size());
    state.counters["moving_masses"] = double(region.masses().size());
    state.counters["last_residual"] = counters.solverResidual;
    state.SetLabel(std::string(iterations == 0 ? "symplectic Euler" : "implicit Euler") + (stiff ? ", k 1e6 m 1g" : ", elastic 1 kg"));
}

BENCHMARK(BM_ZoneStep)->Args({0, 0})->Args({5, 0})->Args({20, 0})->Args({0, 1})->Args({5, 1})->Args({20, 1})
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
