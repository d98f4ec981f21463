// Internal to src/dynamics: the per-mass half of a step, shared by the full step and the
// active-region step so that both integrate bit for bit alike.
#pragma once

#include "flexfit/simulation.hpp"

#include <cmath>

namespace flexfit::detail {

// Per-step constants of the mass update, resolved once from the settings.
struct MassUpdate {
    double h, invH;
    Vec3 gravity;
    double drag;             // gamma (+ b_a with anchor springs)
    double anchorStiffness;  // k_a, 0 unless anchor springs
    double constraint;       // restoration constraint fraction, 0 unless the constraint method
    bool semiImplicit;

    static MassUpdate from(const SimulationSettings& s) {
        const bool anchors = s.restoration.method == RestorationMethod::AnchorSprings;
        const bool constraint = s.restoration.method == RestorationMethod::Constraint;
        return {s.timeStep,
                1.0 / s.timeStep,
                s.gravity,
                s.globalDamping + (anchors ? s.restoration.anchorDamping : 0.0),
                anchors ? s.restoration.anchorStiffness : 0.0,
                constraint ? constraintFractionFor(s.restoration, s.timeStep) : 0.0,
                s.integrator == Integrator::SemiImplicitEuler};
    }

    // Forces on a mass other than its springs: m g - drag v (- k_a (x - rest) with anchors; left
    // out, not multiplied by 0, without them, which the vector kernels rely on to skip rest).
    Vec3 bodyForce(double mass, const Vec3& x, const Vec3& v, const Vec3& rest) const {
        const Vec3 free = mass * gravity - drag * v;
        return anchorStiffness != 0.0 ? Vec3(free - anchorStiffness * (x - rest)) : free;
    }
    bool readsRest() const { return anchorStiffness != 0.0 || constraint > 0.0; }

    // Integrates one mass under total force f, then applies the restoration constraint.
    void integrate(double inverseMass, const Vec3& f, const Vec3& rest, Vec3& x, Vec3& v) const {
        Vec3 xNew, vNew;
        if (semiImplicit) {
            vNew = v + (h * inverseMass) * f;
            xNew = x + h * vNew;
        } else {
            xNew = x + h * v;
            vNew = v + (h * inverseMass) * f;
        }
        restore(rest, xNew, vNew);
        x = xNew;
        v = vNew;
    }

    // The restoration constraint after integration (every integrator): position-based, a
    // fraction back towards rest; the velocity takes the correction.
    void restore(const Vec3& rest, Vec3& xNew, Vec3& vNew) const {
        if (constraint > 0.0) {
            const Vec3 correction = constraint * (rest - xNew);
            xNew += correction;
            vNew += invH * correction;
        }
    }
};

// One mass's update: its pending force plus body forces, integrated; the pending force consumed.
inline void integrateMass(const PartModel& model, const MassUpdate& p, PartState& state, std::size_t i) {
    Vec3& f = state.forces[i];
    const Vec3 total = f + p.bodyForce(model.mass[i], state.positions[i], state.velocities[i], model.restPositions[i]);
    f = Vec3::Zero();
    p.integrate(model.inverseMass[i], total, model.restPositions[i], state.positions[i], state.velocities[i]);
}

// Force of a spring on its first mass a (the second mass b receives the opposite):
// -(k (|d| - L) + c (v_a - v_b).u) u with d = x_a - x_b, u = d/|d|; zero for coincident masses.
// Every step kernel, scalar or vector, evaluates it in exactly this order (no fused multiply-add:
// the library builds with -ffp-contract=off), so all of them give the same bits.
inline void springForce(double k, double c, double restLength, const double* xa, const double* xb, const double* va,
                        const double* vb, double* g) {
    const double dx = xa[0] - xb[0], dy = xa[1] - xb[1], dz = xa[2] - xb[2];
    const double wx = va[0] - vb[0], wy = va[1] - vb[1], wz = va[2] - vb[2];
    const double length = std::sqrt((dx * dx + dy * dy) + dz * dz);
    const double inverse = length > 0.0 ? 1.0 / length : 0.0;
    const double dot = (wx * dx + wy * dy) + wz * dz;
    const double s = -((k * (length - restLength) + (c * dot) * inverse) * inverse);
    g[0] = s * dx;
    g[1] = s * dy;
    g[2] = s * dz;
}

inline Vec3 springForceOnFirst(double k, double c, double restLength, const Vec3& xa, const Vec3& xb, const Vec3& va,
                               const Vec3& vb) {
    Vec3 g;
    springForce(k, c, restLength, xa.data(), xb.data(), va.data(), vb.data(), g.data());
    return g;
}

}  // namespace flexfit::detail
