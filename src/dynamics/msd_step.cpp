// One step of the full mass-spring-damper model: by spring blocks when the model has them
// (block_step.cpp), else a single sweep over the masses.
#include "flexfit/simulation.hpp"
#include "divergence.hpp"
#include "flush_denormals.hpp"
#include "full_step.hpp"

#include <cmath>

namespace flexfit {
namespace detail {

// The whole step is one pass over the masses in index order. Springs are sorted by their first
// (smaller) mass a, so visiting mass a evaluates springs (a, b > a): g goes to a in a register
// and to f[b] in memory. When the pass reaches a mass, every spring touching it has been
// evaluated (those with a smaller first mass earlier, its own now) and nothing later reads its
// position or velocity, so it is integrated at once. One sweep over memory, no scratch arrays.
//
// f_a = (pending external force) + sum_j g_aj + m_a g - drag v_a - k_a (x_a - rest_a)
// g_ab = -(k (|d| - L) + b (v_a - v_b).u) u,  d = x_a - x_b, u = d/|d|
void sweepFullModel(const PartModel& model, const MassUpdate& p, PartState& state) {
    const std::size_t masses = model.massCount();
    const Index* springAdr = model.springAdr.data();
    const Index* springB = model.springB.data();
    const double* restLength = model.restLength.data();
    const double* k = model.stiffness.data();
    const double* c = model.damping.data();
    const double* mass = model.mass.data();
    const double* invMass = model.inverseMass.data();
    const Vec3* rest = model.restPositions.data();
    Vec3* __restrict x = state.positions.data();
    Vec3* __restrict v = state.velocities.data();
    Vec3* __restrict f = state.forces.data();
    for (std::size_t a = 0; a < masses; ++a) {
        Vec3 fa = f[a] + p.bodyForce(mass[a], x[a], v[a], rest[a]);
        for (Index e = springAdr[a]; e < springAdr[a + 1]; ++e) {
            const Index b = springB[e];
            const Vec3 g = springForceOnFirst(k[e], c[e], restLength[e], x[a], x[b], v[a], v[b]);
            fa += g;
            f[b] -= g;
        }
        f[a] = Vec3::Zero();  // consumed: the next step starts with no pending force
        p.integrate(invMass[a], fa, rest[a], x[a], v[a]);
    }
}

}  // namespace detail

void validateSettings(const SimulationSettings& s) {
    const std::string source = "simulation settings";
    if (!std::isfinite(s.timeStep) || s.timeStep <= 0.0) throw InputError(source, 0, "time step must be finite and > 0");
    if (!s.gravity.allFinite()) throw InputError(source, 0, "gravity must be finite");
    if (!std::isfinite(s.globalDamping) || s.globalDamping < 0.0)
        throw InputError(source, 0, "global damping must be finite and >= 0");
    const RestorationSettings& r = s.restoration;
    if (!std::isfinite(r.anchorStiffness) || r.anchorStiffness < 0.0)
        throw InputError(source, 0, "anchor stiffness must be finite and >= 0");
    if (!std::isfinite(r.anchorDamping) || r.anchorDamping < 0.0)
        throw InputError(source, 0, "anchor damping must be finite and >= 0");
    if (r.method == RestorationMethod::Constraint && !(r.constraintFraction > 0.0 && r.constraintFraction <= 1.0))
        throw InputError(source, 0, "restoration constraint fraction must be in (0, 1]");
}

void stepFullModel(const PartModel& model, const SimulationSettings& settings, std::span<const PointLoad> loads,
                   PartState& state, StepCounters* counters) {
    const detail::FlushDenormals flush;
    const double start = state.time;
    for (const PointLoad& load : loads) state.forces[load.mass] += load.force;
    const detail::MassUpdate update = detail::MassUpdate::from(settings);
    if (!model.hasSpringBlocks())
        detail::sweepFullModel(model, update, state);
    else
        detail::stepSpringBlocks(model, update, state, detail::fullStepKernel());
    state.time += settings.timeStep;
    ++state.stepCount;
    if (counters != nullptr) {
        counters->springsEvaluated += model.springCount();
        counters->massesIntegrated += model.massCount();
    }
    detail::checkAllMassesFinite(model, settings, state, std::nullopt, start);  // every mass was touched anyway
}

double totalEnergy(const PartModel& model, const SimulationSettings& settings, const PartState& state) {
    double energy = 0.0;
    for (std::size_t i = 0; i < model.massCount(); ++i) energy += 0.5 * model.mass[i] * state.velocities[i].squaredNorm();
    for (std::size_t e = 0; e < model.springCount(); ++e) {
        const double stretch = (state.positions[model.springA[e]] - state.positions[model.springB[e]]).norm() - model.restLength[e];
        energy += 0.5 * model.stiffness[e] * stretch * stretch;
    }
    if (settings.restoration.method == RestorationMethod::AnchorSprings)
        for (std::size_t i = 0; i < model.massCount(); ++i)
            energy += 0.5 * settings.restoration.anchorStiffness * (state.positions[i] - model.restPositions[i]).squaredNorm();
    return energy;
}

Vec3 linearMomentum(const PartModel& model, const PartState& state) {
    Vec3 momentum = Vec3::Zero();
    for (std::size_t i = 0; i < model.massCount(); ++i) momentum += model.mass[i] * state.velocities[i];
    return momentum;
}

}  // namespace flexfit
