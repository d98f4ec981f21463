// One step of the full mass-spring-damper model. Three passes over compact arrays:
// masses (external and restoring forces), springs (g_ij), masses (integration + constraint).
#include "flexfit/simulation.hpp"

#include <cmath>

namespace flexfit {
namespace {

// f_i = m_i g - gamma v_i [- k_a (x_i - rest_i) - b_a v_i]
void initialiseForces(const PartModel& model, const SimulationSettings& s, PartState& state) {
    const std::size_t n = model.massCount();
    const Vec3* x = state.positions.data();
    const Vec3* v = state.velocities.data();
    const Vec3* rest = model.restPositions.data();
    const double* m = model.mass.data();
    Vec3* f = state.forces.data();
    const bool anchors = s.restoration.method == RestorationMethod::AnchorSprings;
    const double ka = anchors ? s.restoration.anchorStiffness : 0.0;
    const double drag = s.globalDamping + (anchors ? s.restoration.anchorDamping : 0.0);
    for (std::size_t i = 0; i < n; ++i) f[i] = m[i] * s.gravity - drag * v[i] - ka * (x[i] - rest[i]);
}

void applyLoads(std::span<const PointLoad> loads, PartState& state) {
    for (const PointLoad& load : loads) state.forces[load.mass] += load.force;
}

// g_ij = -(k (|d| - L) + b (v_i - v_j).u) u, added to i and subtracted from j.
void accumulateSpringForces(const PartModel& model, PartState& state) {
    const std::size_t springs = model.springCount();
    const Index* a = model.springA.data();
    const Index* b = model.springB.data();
    const double* rest = model.restLength.data();
    const double* k = model.stiffness.data();
    const double* c = model.damping.data();
    const Vec3* x = state.positions.data();
    const Vec3* v = state.velocities.data();
    Vec3* f = state.forces.data();
    for (std::size_t e = 0; e < springs; ++e) {
        const Index i = a[e], j = b[e];
        const Vec3 d = x[i] - x[j];
        const double length = d.norm();
        if (!(length > 0.0)) continue;  // coincident masses: no direction, no force
        const Vec3 u = d / length;
        const double magnitude = k[e] * (length - rest[e]) + c[e] * (v[i] - v[j]).dot(u);
        const Vec3 g = magnitude * u;
        f[i] -= g;
        f[j] += g;
    }
}

void integrate(const PartModel& model, const SimulationSettings& s, PartState& state) {
    const std::size_t n = model.massCount();
    const double h = s.timeStep;
    const double* invMass = model.inverseMass.data();
    const Vec3* f = state.forces.data();
    Vec3* x = state.positions.data();
    Vec3* v = state.velocities.data();
    if (s.integrator == Integrator::SemiImplicitEuler) {
        for (std::size_t i = 0; i < n; ++i) {
            v[i] += (h * invMass[i]) * f[i];
            x[i] += h * v[i];
        }
    } else {
        for (std::size_t i = 0; i < n; ++i) {
            x[i] += h * v[i];
            v[i] += (h * invMass[i]) * f[i];
        }
    }
}

// Moves each mass a fraction of the way back to its rest position; the velocity takes the
// correction so that it is not undone next step (position-based dynamics).
void applyRestorationConstraint(const PartModel& model, const SimulationSettings& s, PartState& state) {
    const std::size_t n = model.massCount();
    const double c = s.restoration.constraintFraction, invH = 1.0 / s.timeStep;
    const Vec3* rest = model.restPositions.data();
    Vec3* x = state.positions.data();
    Vec3* v = state.velocities.data();
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 correction = c * (rest[i] - x[i]);
        x[i] += correction;
        v[i] += invH * correction;
    }
}

}  // namespace

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
    initialiseForces(model, settings, state);
    applyLoads(loads, state);
    accumulateSpringForces(model, state);
    integrate(model, settings, state);
    if (settings.restoration.method == RestorationMethod::Constraint) applyRestorationConstraint(model, settings, state);
    state.time += settings.timeStep;
    ++state.stepCount;
    if (counters != nullptr) {
        counters->springsEvaluated += model.springCount();
        counters->massesIntegrated += model.massCount();
    }
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

const char* toString(Integrator integrator) {
    return integrator == Integrator::SemiImplicitEuler ? "semi-implicit-euler" : "explicit-euler";
}

const char* toString(RestorationMethod method) {
    switch (method) {
        case RestorationMethod::None: return "none";
        case RestorationMethod::AnchorSprings: return "anchor";
        case RestorationMethod::Constraint: return "constraint";
    }
    return "?";
}

}  // namespace flexfit
