// The largest stiffness each integrator runs at 1 kHz (issue 17's performance report):
// bench/results/stiffness_limit.csv. Its own binary: Google Benchmark's CSV wants the same
// counters in every row.
#include "flexfit/flexfit.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

namespace {

using namespace flexfit;

// The largest stiffness each integrator runs at h = 1 ms: torus1 (576 masses, 1,728 springs, spring
// damping 1 % of critical), one mass kicked at 0.01 m/s, 3,000 full steps; a stiffness runs when
// every value stays finite and the energy (kinetic + springs) stays within twice the kick's
// (an unstable mode grows without bound). Stiffnesses 10^(e/2) N/m, e = 2..16. Range 0: 0
// explicit, 1 symplectic, 2 implicit with 20 iterations; range 1: 0 for 1 g masses, 1 for 1 kg.
// One iteration: the counters are the result, not the time.
double springEnergy(const PartModel& model, const PartState& state) {
    double energy = 0.0;
    for (std::size_t v = 0; v < model.massCount(); ++v) energy += 0.5 * model.mass[v] * state.velocities[v].squaredNorm();
    for (std::size_t e = 0; e < model.springCount(); ++e) {
        const double stretch = (state.positions[model.springA[e]] - state.positions[model.springB[e]]).norm() - model.restLength[e];
        energy += 0.5 * model.stiffness[e] * stretch * stretch;
    }
    return energy;
}

bool runsAt(double stiffness, double mass, Integrator integrator) {
    const auto model = buildPartModel(makeTorus1(), {Material{stiffness, 0.01 * std::sqrt(stiffness * mass)}, mass, {}, {}, {}, {}});
    SimulationSettings s;
    s.timeStep = 1e-3;
    s.integrator = integrator;
    s.implicit.maxIterations = 20;
    s.implicit.tolerance = 0.0;
    s.restoration.method = RestorationMethod::None;
    PartState state = PartState::atRest(*model);
    state.velocities[0] = Vec3(0.01, 0.0, 0.0);
    const double kicked = springEnergy(*model, state);
    for (int step = 0; step < 3000; ++step) {
        try {
            stepFullModel(*model, s, {}, state);
        } catch (const DivergenceError&) {
            return false;
        }
        if (step % 100 == 99 && !(springEnergy(*model, state) <= 2.0 * kicked)) return false;
    }
    return springEnergy(*model, state) <= 2.0 * kicked;
}

void BM_LargestStiffnessAt1kHz(benchmark::State& state) {
    const Integrator integrators[3] = {Integrator::ExplicitEuler, Integrator::SemiImplicitEuler, Integrator::ImplicitEuler};
    const Integrator integrator = integrators[state.range(0)];
    const double mass = state.range(1) == 0 ? 1e-3 : 1.0;
    double largest = 0.0;
    for (auto _ : state)
        for (int e = 2; e <= 16; ++e) {
            const double k = std::pow(10.0, 0.5 * e);
            if (runsAt(k, mass, integrator)) largest = k;
        }
    state.counters["largest_stiffness_N_per_m"] = largest;
    state.counters["mass_kg"] = mass;
    state.SetLabel(std::string(toString(integrator)) + (mass < 0.5 ? ", 1 g masses" : ", 1 kg masses"));
}

BENCHMARK(BM_LargestStiffnessAt1kHz)->ArgsProduct({{0, 1, 2}, {0, 1}})->Iterations(1)->Repetitions(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
