// The step of an active region (rigid-deformable parts): springs, then moving masses.
#include "flexfit/simulation.hpp"
#include "flush_denormals.hpp"
#include "mass_update.hpp"

namespace flexfit {

void stepActiveRegion(const PartModel& model, const SimulationSettings& settings, const ActiveRegion& region,
                      PartState& state, StepCounters* counters) {
    const detail::FlushDenormals flush;
    const detail::MassUpdate p = detail::MassUpdate::from(settings);
    const Index* springA = model.springA.data();
    const Index* springB = model.springB.data();
    Vec3* __restrict x = state.positions.data();
    Vec3* __restrict v = state.velocities.data();
    Vec3* __restrict f = state.forces.data();
    const std::uint16_t* mask = region.coverCounts().data();
    const std::span<const Index> computed = region.springs().members(), moving = region.masses().members();

    // Springs: forces reach only the moving ends (a fixed end is held by the rigid body).
    for (Index e : computed) {
        const Index a = springA[e], b = springB[e];
        const Vec3 g =
            detail::springForceOnFirst(model.stiffness[e], model.damping[e], model.restLength[e], x[a], x[b], v[a], v[b]);
        if (mask[a] != 0) f[a] += g;
        if (mask[b] != 0) f[b] -= g;
    }
    // Moving masses: body forces, integration, restoration; pending forces consumed.
    for (Index i : moving) {
        const Vec3 total = f[i] + p.bodyForce(model.mass[i], x[i], v[i], model.restPositions[i]);
        f[i] = Vec3::Zero();
        p.integrate(model.inverseMass[i], total, model.restPositions[i], x[i], v[i]);
    }
    state.time += settings.timeStep;
    ++state.stepCount;
    if (counters != nullptr) {
        counters->springsEvaluated += computed.size();
        counters->massesIntegrated += moving.size();
    }
}

}  // namespace flexfit
