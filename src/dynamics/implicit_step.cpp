// The implicit (backward) Euler step: one Newton step of backward Euler, solved by conjugate
// gradient over the moving masses (Baraff & Witkin 1998, "Large steps in cloth simulation").
//
// Backward Euler: v+ = v + h M^-1 f(x + h v+, v+), x+ = x + h v+. Linearised at (x, v) with
// dv = v+ - v, it is the symmetric positive definite system
//   (M + h C + h^2 S) dv = h (f - h S v)
// where f is every force at (x, v) (springs, gravity, drag, anchors, pending loads), S = -df/dx
// and C = -df/dv. A spring (a, b) adds to S the blocks +-S_e with
//   S_e = alpha I + (k - alpha) u u^T,  alpha = k max(0, 1 - L/|d|)
// (its tangent stiffness with the transverse term clamped at zero under compression, which
// keeps S positive semi-definite: the usual choice, also Bullet's and Baraff-Witkin's), and to C
// the blocks +-c u u^T; drag gamma (+ b_a) adds gamma I per mass, anchor springs k_a I to S.
// Masses outside the region are held: they are not unknowns, and a spring to one adds only its
// diagonal block to the moving end (the fixed end's dv is zero).
//
// Why this method. It is unconditionally stable for the linear(ised) system whatever k, m and
// h, and needs only matrix-vector products, so a zone's solve costs O(springs) per iteration
// with no assembled matrix, and the zone's edge is held simply by not being an unknown. A fixed
// iteration budget (tolerance 0) bounds the cost for haptic loops; the relative residual is
// reported. Known limits: one Newton step per time step (large deformations in one step are
// damped more than the exact backward Euler would); the clamp makes buckling under compression
// slower than physical; backward Euler damps oscillations numerically (by 1/|1 - h lambda| per
// step: at h w = 0.1, 0.5 % per step); the code is scalar (about 20 ns per spring to assemble,
// 6-7 ns per spring and iteration on the reference machine) and the Jacobi preconditioner
// converges slowly when h^2 k / m is large (1,000: a residual of 0.64 after 20 iterations on a
// 2,000-mass zone, 494 iterations to 1e-6), where block-Jacobi, multigrid or Vertex Block
// Descent would do better.
// The order of every sum is fixed (lists in order), so a run's bits do not depend on the CPU.
#include "implicit_step.hpp"

#include "mass_update.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace flexfit::detail {
namespace {

// H_e = h^2 S_e + h C_e = iso I + axial u u^T, and the spring's ends as positions in the
// solve's compact arrays. A held end points at the held slot: one more position past the
// moving masses whose input stays zero and whose output nobody reads, so the passes over the
// springs need no branch (and add the same values as if the held end were skipped).
struct SpringJacobian {
    double u[3] = {0.0, 0.0, 0.0};
    double iso = 0.0, axial = 0.0;
    std::uint32_t a = 0, b = 0;
};

constexpr double kRoundingLevel = 1e-14;

// Scratch of the solve, per thread, grown to the largest problem stepped. The solve's vectors
// are compact: 3 doubles per moving mass, in the order of the mass list, so every vector pass
// streams, then the held slot's 3; `slot` maps a mass to its position (written for the moving
// masses each step).
struct Workspace {
    std::vector<double> dv, r, z, p, ap, diagonal, massTerm;
    std::vector<SpringJacobian> jacobians;
    std::vector<std::uint32_t> slot;
    std::vector<Index> identity;  // 0, 1, 2, ... for the full model's lists

    void reserve(std::size_t modelMasses, std::size_t masses, std::size_t springs) {
        for (std::vector<double>* v : {&dv, &r, &z, &p, &ap, &diagonal})
            if (v->size() < 3 * (masses + 1)) v->resize(3 * (masses + 1));
        if (massTerm.size() < masses) massTerm.resize(masses);
        if (jacobians.size() < springs) jacobians.resize(springs);
        if (slot.size() < modelMasses) slot.resize(modelMasses);
        if (identity.size() < std::max(modelMasses, springs)) {
            const std::size_t old = identity.size();
            identity.resize(std::max(modelMasses, springs));
            for (std::size_t i = old; i < identity.size(); ++i) identity[i] = Index(i);
        }
    }
};

thread_local Workspace workspace;

struct Problem {
    const PartModel& model;
    const MassUpdate& update;
    std::span<const Index> masses, springs;
    const std::uint16_t* cover;  // null: every mass moves
    bool moves(Index m) const { return cover == nullptr || cover[m] != 0; }
};

// Right-hand side h (f - h S v) into ws.r, the system's diagonal into ws.diagonal, the springs'
// H_e into ws.jacobians; pending forces consumed.
void assemble(const Problem& q, PartState& state, Workspace& ws) {
    const MassUpdate& p = q.update;
    const double h = p.h;
    for (std::size_t k = 0; k < q.masses.size(); ++k) {
        const Index i = q.masses[k];
        ws.slot[i] = std::uint32_t(k);
        const Vec3 force = state.forces[i] + p.bodyForce(q.model.mass[i], state.positions[i], state.velocities[i],
                                                         q.model.restPositions[i]);
        const Vec3 rhs = h * (force - (h * p.anchorStiffness) * state.velocities[i]);
        ws.massTerm[k] = q.model.mass[i] + h * p.drag + h * h * p.anchorStiffness;
        for (int c = 0; c < 3; ++c) {
            ws.r[3 * k + c] = rhs[c];
            ws.diagonal[3 * k + c] = ws.massTerm[k];
        }
        state.forces[i] = Vec3::Zero();
    }
    const std::size_t held = q.masses.size();
    for (int c = 0; c < 3; ++c) ws.r[3 * held + c] = ws.diagonal[3 * held + c] = 0.0;  // scratch, never read
    for (std::size_t s = 0; s < q.springs.size(); ++s) {
        const Index e = q.springs[s], a = q.model.springA[e], b = q.model.springB[e];
        SpringJacobian& jacobian = ws.jacobians[s];
        jacobian = {};
        jacobian.a = q.moves(a) ? ws.slot[a] : std::uint32_t(held);
        jacobian.b = q.moves(b) ? ws.slot[b] : std::uint32_t(held);
        const Vec3 d = state.positions[a] - state.positions[b];
        const double length = d.norm();
        if (!(length > 0.0)) continue;  // coincident ends: no force, no direction (as the explicit steps)
        const double k = q.model.stiffness[e], c = q.model.damping[e], restLength = q.model.restLength[e];
        const double inverse = 1.0 / length;
        const double alpha = k * std::max(0.0, 1.0 - restLength * inverse);
        const Vec3 u = d * inverse;
        jacobian.iso = h * h * alpha;
        jacobian.axial = h * h * (k - alpha) + h * c;
        for (int i = 0; i < 3; ++i) jacobian.u[i] = u[i];
        const Vec3 w = state.velocities[a] - state.velocities[b];
        const double wu = u.dot(w);
        const Vec3 g = -(k * (length - restLength) + c * wu) * u;  // the spring force on a
        const Vec3 stiffnessTimesW = h * h * (alpha * w + ((k - alpha) * wu) * u);  // h^2 S_e w
        const Vec3 change = h * g - stiffnessTimesW;
        for (int i = 0; i < 3; ++i) {
            const double diagonal = jacobian.iso + jacobian.axial * u[i] * u[i];
            ws.r[3 * jacobian.a + i] += change[i];
            ws.diagonal[3 * jacobian.a + i] += diagonal;
            ws.r[3 * jacobian.b + i] -= change[i];
            ws.diagonal[3 * jacobian.b + i] += diagonal;
        }
    }
}

// out = (M + h C + h^2 S) in over the moving masses (`in`'s held slot is zero; `out`'s is
// scratch).
void multiply(std::size_t masses, std::size_t springs, const Workspace& ws, const double* in, double* out) {
    for (std::size_t k = 0; k < masses; ++k)
        for (int c = 0; c < 3; ++c) out[3 * k + c] = ws.massTerm[k] * in[3 * k + c];
    for (int c = 0; c < 3; ++c) out[3 * masses + c] = 0.0;
    for (std::size_t s = 0; s < springs; ++s) {
        const SpringJacobian& j = ws.jacobians[s];
        double difference[3];
        for (int c = 0; c < 3; ++c) difference[c] = in[3 * j.a + c] - in[3 * j.b + c];
        const double along = j.axial * ((j.u[0] * difference[0] + j.u[1] * difference[1]) + j.u[2] * difference[2]);
        for (int c = 0; c < 3; ++c) {
            const double t = j.iso * difference[c] + along * j.u[c];
            out[3 * j.a + c] += t;
            out[3 * j.b + c] -= t;
        }
    }
}

// Sum of a_i b_i over n doubles, in four running sums added in a fixed order (no chain of
// dependent additions through every element; the same bits on every CPU).
double dot(std::size_t n, const double* a, const double* b) {
    double sum[4] = {0.0, 0.0, 0.0, 0.0};
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4)
        for (int l = 0; l < 4; ++l) sum[l] += a[i + l] * b[i + l];
    for (; i < n; ++i) sum[0] += a[i] * b[i];
    return (sum[0] + sum[1]) + (sum[2] + sum[3]);
}

// Jacobi-preconditioned conjugate gradient for dv (starting from zero); returns the iterations.
int solve(std::size_t masses, std::size_t springs, const ImplicitSettings& settings, Workspace& ws,
          double& relativeResidual) {
    const std::size_t n = 3 * masses;
    double* dv = ws.dv.data();
    double* r = ws.r.data();
    double* z = ws.z.data();
    double* p = ws.p.data();
    double* ap = ws.ap.data();
    double* inverseDiagonal = ws.diagonal.data();  // inverted in place: one division per unknown a step
    for (std::size_t i = 0; i < n; ++i) {
        inverseDiagonal[i] = 1.0 / inverseDiagonal[i];
        dv[i] = 0.0;
        z[i] = r[i] * inverseDiagonal[i];
        p[i] = z[i];
    }
    for (std::size_t i = n; i < n + 3; ++i) p[i] = 0.0;  // the held slot: held masses do not move
    const double rhsNorm = std::sqrt(dot(n, r, r));
    relativeResidual = 0.0;
    if (!std::isfinite(rhsNorm)) {
        // A non-finite force or state: kept in the velocity change of the masses it is in, so
        // the divergence check names them (a dv of 0 would drop a NaN force silently). A norm
        // that only overflowed (every entry finite) goes on to the solve as before.
        bool nonFinite = false;
        for (std::size_t i = 0; i < n; ++i)
            if (!std::isfinite(r[i])) {
                dv[i] = r[i];
                nonFinite = true;
            }
        if (nonFinite) return 0;
    }
    if (!(rhsNorm > 0.0)) return 0;  // nothing acts: dv = 0
    double rz = dot(n, r, z);
    int iterations = 0;
    relativeResidual = 1.0;
    while (iterations < settings.maxIterations) {
        multiply(masses, springs, ws, p, ap);
        const double curvature = dot(n, p, ap);
        if (!(curvature > 0.0)) break;
        const double step = rz / curvature;
        for (std::size_t i = 0; i < n; ++i) {
            dv[i] += step * p[i];
            r[i] -= step * ap[i];
        }
        ++iterations;
        relativeResidual = std::sqrt(dot(n, r, r)) / rhsNorm;
        // Past rounding level the iterates only gather noise: stop there even on a fixed budget.
        if (relativeResidual <= std::max(settings.tolerance, kRoundingLevel)) break;
        for (std::size_t i = 0; i < n; ++i) z[i] = r[i] * inverseDiagonal[i];
        const double rzNext = dot(n, r, z);
        const double beta = rzNext / rz;
        rz = rzNext;
        for (std::size_t i = 0; i < n; ++i) p[i] = z[i] + beta * p[i];
    }
    return iterations;
}

// v+ = v + dv, x+ = x + h v+, then the restoration constraint (MassUpdate::restore).
void integrate(const Problem& q, const Workspace& ws, PartState& state) {
    const MassUpdate& p = q.update;
    for (std::size_t k = 0; k < q.masses.size(); ++k) {
        const Index i = q.masses[k];
        Vec3 vNew = state.velocities[i] + Vec3(ws.dv[3 * k], ws.dv[3 * k + 1], ws.dv[3 * k + 2]);
        Vec3 xNew = state.positions[i] + p.h * vNew;
        p.restore(q.model.restPositions[i], xNew, vNew);
        state.positions[i] = xNew;
        state.velocities[i] = vNew;
    }
}

}  // namespace

void stepImplicit(const PartModel& model, const SimulationSettings& settings, const ActiveRegion* region,
                  PartState& state, StepCounters* counters) {
    const MassUpdate update = MassUpdate::from(settings);
    Workspace& ws = workspace;
    ws.reserve(model.massCount(), region != nullptr ? region->masses().size() : model.massCount(),
               region != nullptr ? region->springs().size() : model.springCount());
    const Problem problem{model, update,
                          region != nullptr ? region->masses().members()
                                            : std::span<const Index>(ws.identity.data(), model.massCount()),
                          region != nullptr ? region->springs().members()
                                            : std::span<const Index>(ws.identity.data(), model.springCount()),
                          region != nullptr ? region->coverCounts().data() : nullptr};
    assemble(problem, state, ws);
    double residual = 0.0;
    const int iterations = solve(problem.masses.size(), problem.springs.size(), settings.implicit, ws, residual);
    integrate(problem, ws, state);
    state.time += settings.timeStep;
    ++state.stepCount;
    if (counters != nullptr) {
        counters->springsEvaluated += problem.springs.size();
        counters->massesIntegrated += problem.masses.size();
        counters->solverIterations += std::size_t(iterations);
        counters->solverResidual = std::max(counters->solverResidual, residual);
    }
}

}  // namespace flexfit::detail
