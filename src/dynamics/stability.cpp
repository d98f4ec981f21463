// Time-step stability bounds for the explicit integrators (derivation in simulation.hpp).
//
// Mass-normalised stiffness M^-1/2 K M^-1/2 at rest: each spring adds k u u^T blocks (norm k).
//   Gershgorin: w^2 <= max_i [ sum_e k_e (1/m_i + 1/sqrt(m_i m_j)) + k_a/m_i ]
//   Rayleigh (test vector +u at i, -u at j): w^2 >= max_e (4 k_e + 2 k_a) / (m_i + m_j)
// The same bounds hold for the damping matrix. Damping is treated as modal (exact when every
// spring has the same b/k ratio), which is the documented approximation of this check.
#include "flexfit/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace flexfit {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct ModeBounds {
    double omega2Upper = 0.0, omega2Lower = 0.0;  // stiffness
    double dampingUpper = 0.0;                      // largest modal damping rate c
    double betaMin = kInf, betaMax = 0.0;           // b/k ratios (stiffness-proportional damping)
    double alphaMin = kInf, alphaMax = 0.0;         // gamma/m (mass-proportional damping)
};

ModeBounds boundModes(const PartModel& model, const SimulationSettings& s) {
    const bool anchors = s.restoration.method == RestorationMethod::AnchorSprings;
    const double ka = anchors ? s.restoration.anchorStiffness : 0.0;
    const double ba = anchors ? s.restoration.anchorDamping : 0.0;
    const std::size_t n = model.massCount();
    std::vector<double> rowK(n, 0.0), rowB(n, 0.0);
    ModeBounds bounds;
    for (std::size_t e = 0; e < model.springCount(); ++e) {
        const Index i = model.springA[e], j = model.springB[e];
        const double cross = 1.0 / std::sqrt(model.mass[i] * model.mass[j]);
        const double k = model.stiffness[e], b = model.damping[e];
        rowK[i] += k * (model.inverseMass[i] + cross);
        rowK[j] += k * (model.inverseMass[j] + cross);
        rowB[i] += b * (model.inverseMass[i] + cross);
        rowB[j] += b * (model.inverseMass[j] + cross);
        bounds.omega2Lower = std::max(bounds.omega2Lower, (4.0 * k + 2.0 * ka) / (model.mass[i] + model.mass[j]));
        if (k > 0.0) {
            bounds.betaMin = std::min(bounds.betaMin, b / k);
            bounds.betaMax = std::max(bounds.betaMax, b / k);
        }
    }
    if (ka > 0.0) {
        bounds.betaMin = std::min(bounds.betaMin, ba / ka);
        bounds.betaMax = std::max(bounds.betaMax, ba / ka);
    }
    for (std::size_t i = 0; i < n; ++i) {
        bounds.omega2Upper = std::max(bounds.omega2Upper, rowK[i] + ka * model.inverseMass[i]);
        bounds.dampingUpper = std::max(bounds.dampingUpper, rowB[i] + (ba + s.globalDamping) * model.inverseMass[i]);
        bounds.alphaMin = std::min(bounds.alphaMin, s.globalDamping * model.inverseMass[i]);
        bounds.alphaMax = std::max(bounds.alphaMax, s.globalDamping * model.inverseMass[i]);
    }
    if (bounds.betaMin == kInf) bounds.betaMin = 0.0;
    if (bounds.alphaMin == kInf) bounds.alphaMin = 0.0;
    return bounds;
}

// Largest h with h^2 w^2 + 2 c h < 4.
double symplecticLimit(double omega2, double c) {
    if (omega2 <= 0.0) return c > 0.0 ? 2.0 / c : kInf;
    // (-c + sqrt(c^2 + 4 omega^2)) / omega^2, rationalised: with damping far above the stiffness
    // (a mass of 1e-100) the difference cancelled to 0, and beyond 1e154 c^2 overflowed to NaN.
    return 4.0 / (c + std::hypot(c, 2.0 * std::sqrt(omega2)));
}

}  // namespace

StabilityReport analyzeStability(const PartModel& model, const SimulationSettings& s) {
    const ModeBounds b = boundModes(model, s);
    StabilityReport report;
    report.omegaUpper = std::sqrt(b.omega2Upper);
    report.omegaLower = std::sqrt(b.omega2Lower);
    if (s.integrator == Integrator::SemiImplicitEuler) {
        report.safeTimeStep = symplecticLimit(b.omega2Upper, b.dampingUpper);
        report.unstableTimeStep = b.omega2Lower > 0.0 ? 2.0 / report.omegaLower : kInf;
    } else {
        // Stable iff h < c/w^2 = alpha/w^2 + beta for every mode.
        report.safeTimeStep = b.omega2Upper > 0.0 ? b.betaMin + b.alphaMin / b.omega2Upper : kInf;
        report.unstableTimeStep = b.omega2Lower > 0.0 ? b.betaMax + b.alphaMax / b.omega2Lower : kInf;
    }
    if (s.integrator == Integrator::ImplicitEuler) {  // unconditionally stable: no bound
        report.safeTimeStep = report.unstableTimeStep = kInf;
    }
    const double h = s.timeStep;
    report.certainlyUnstable = h > report.unstableTimeStep;
    report.possiblyUnstable = h > report.safeTimeStep;
    std::ostringstream text;
    if (report.certainlyUnstable) {
        text << "time step " << h << " s diverges with " << labelOf(s.integrator) << ": the fastest mode (>= "
             << report.omegaLower << " rad/s) is unstable above " << report.unstableTimeStep << " s";
        if (report.unstableTimeStep == 0.0)
            text << " (explicit Euler always blows up without damping); add damping or use the implicit integrator (unconditionally stable)";
        else if (!(report.safeTimeStep > 0.0))  // the bound underflowed: masses of 1e-300 against ordinary springs
            text << "; no time step this small is usable: use the implicit integrator (unconditionally stable) or masses that fit the springs";
        else
            text << "; use a time step below " << report.safeTimeStep << " s or the implicit integrator (unconditionally stable)";
    } else if (report.possiblyUnstable) {
        text << "time step " << h << " s may be unstable with " << labelOf(s.integrator)
             << ": stability is guaranteed below " << report.safeTimeStep << " s (modes up to " << report.omegaUpper
             << " rad/s; the implicit integrator has no bound)";
    }
    report.message = text.str();
    return report;
}

}  // namespace flexfit
