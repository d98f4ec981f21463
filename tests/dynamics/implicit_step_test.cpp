// The implicit Euler step (src/dynamics/implicit_step.cpp) against independent references: the
// energy of an unforced system (never increases), the analytic damped frequency of a
// one-mass oscillator (and backward Euler's own amplification factor), and a direct sparse
// solve of K x = f (Eigen's SimplicialLDLT) for the static deflection.
#include "flexfit/flexfit.hpp"
#include "golden.hpp"

#include <Eigen/Sparse>
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <random>

using namespace flexfit;

namespace {

SimulationSettings implicitSettings(double h) {
    SimulationSettings s;
    s.timeStep = h;
    s.integrator = Integrator::ImplicitEuler;
    s.restoration.method = RestorationMethod::None;
    s.implicit.tolerance = 1e-12;
    s.implicit.maxIterations = 500;
    return s;
}

ActiveRegion firstMasses(const PartModel& model, Index count) {
    ActiveRegion region(model);
    for (Index m = 0; m < count; ++m) region.cover(m);
    return region;
}

// Moving masses displaced by up to `amplitude` along random directions.
PartState perturbed(const PartModel& model, const ActiveRegion* region, double amplitude, unsigned seed) {
    PartState state = PartState::atRest(model);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (Index m = 0; m < model.massCount(); ++m)
        if (region == nullptr || region->moves(m)) state.positions[m] += amplitude * Vec3(u(rng), u(rng), u(rng));
    return state;
}

void step(const PartModel& model, const SimulationSettings& s, const ActiveRegion* region, PartState& state,
          StepCounters* counters = nullptr) {
    if (region == nullptr)
        stepFullModel(model, s, {}, state, counters);
    else
        stepActiveRegion(model, s, *region, state, counters);
}

}  // namespace

// From soft to very stiff (k h^2 / m from 1e-4 to 1e7: the explicit steps diverge past ~4),
// light and heavy masses, no damping and no external work: the total energy never increases
// and stays finite, in the full step and in a region step with the other masses held.
TEST(ImplicitStep, EnergyNeverIncreasesWhateverTheStiffness) {
    const TriMesh mesh = makeIcoSphere(1.0, 0);  // 12 masses, 30 springs: a rigid framework
    for (const double k : {1e2, 1e7})
        for (const double mass : {1e-3, 1.0})
            for (const bool inRegion : {false, true}) {
                SCOPED_TRACE("k " + std::to_string(k) + " m " + std::to_string(mass) + (inRegion ? " region" : " full"));
                const auto model = buildPartModel(mesh, {Material{k, 0.0}, mass, {}, {}, {}, {}});
                const ActiveRegion region = firstMasses(*model, 6);
                const ActiveRegion* r = inRegion ? &region : nullptr;
                const SimulationSettings s = implicitSettings(1e-3);
                PartState state = perturbed(*model, r, 0.02, 3);
                double energy = totalEnergy(*model, s, state);
                ASSERT_GT(energy, 0.0);
                const double initial = energy;
                for (int i = 0; i < 10000; ++i) {
                    step(*model, s, r, state);
                    const double next = totalEnergy(*model, s, state);
                    ASSERT_TRUE(std::isfinite(next)) << "step " << i;
                    ASSERT_LE(next, energy * (1.0 + 1e-12) + 1e-18 * initial) << "step " << i;
                    energy = next;
                }
                EXPECT_LT(energy, initial);
            }
}

// One mass on two springs to held masses (an equilateral triangle), displaced along the
// bisector by 1e-6: a linear damped oscillator with k_eff = 1.5 k, c_eff = 1.5 c. Backward Euler
// maps each step by mu = 1 / (1 - h lambda), lambda = -zeta w +- i w_d the continuous
// eigenvalue: the measured frequency and decay follow mu, and mu's frequency
// atan(h w_d / (1 + h zeta w)) / h is the analytic w_d to within its known error,
// w_d (h zeta w + (h w)^2 / 3) to first order.
TEST(ImplicitStep, OscillatesAtTheDampedFrequency) {
    TriMesh triangle;
    triangle.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, std::sqrt(3.0) / 2.0, 0)};
    triangle.faces = {{0, 1, 2}};
    const double k = 100.0, c = 0.4, m = 1.0, h = 1e-3;
    const auto model = buildPartModel(triangle, {Material{k, c}, m, {}, {}, {}, {}});
    ActiveRegion region(*model);
    region.cover(2);
    SimulationSettings s = implicitSettings(h);
    PartState state = PartState::atRest(*model);
    const double y0 = state.positions[2].y(), amplitude = 1e-6;
    state.positions[2].y() += amplitude;

    const double kEff = 1.5 * k, cEff = 1.5 * c;
    const double omega0 = std::sqrt(kEff / m), zetaOmega = cEff / (2.0 * m);
    const double omegaDamped = std::sqrt(omega0 * omega0 - zetaOmega * zetaOmega);
    const std::complex<double> lambda(-zetaOmega, omegaDamped);
    const std::complex<double> mu = 1.0 / (1.0 - h * lambda);
    const double omegaMethod = std::arg(mu) / h, decayMethod = -std::log(std::abs(mu)) / h;
    const double knownError = omegaDamped * (h * zetaOmega + (h * omega0) * (h * omega0) / 3.0);
    EXPECT_NEAR(omegaMethod, omegaDamped, 1.05 * knownError);
    EXPECT_LT(std::abs(omegaMethod - omegaDamped), 5e-4 * omegaDamped);

    // Upward zero crossings of y - y0, interpolated; the energy's decay.
    std::vector<double> crossings;
    double previous = amplitude;
    const int steps = 6000;
    for (int i = 1; i <= steps; ++i) {
        stepActiveRegion(*model, s, region, state);
        const double y = state.positions[2].y() - y0;
        if (previous < 0.0 && y >= 0.0) crossings.push_back(h * (i - 1) + h * (-previous) / (y - previous));
        previous = y;
        EXPECT_NEAR(state.positions[2].x(), 0.5, 1e-15);  // symmetric: no sideways motion
    }
    ASSERT_GE(crossings.size(), 8u);
    const double period = (crossings.back() - crossings.front()) / double(crossings.size() - 1);
    EXPECT_NEAR(2.0 * M_PI / period, omegaMethod, 1e-3 * omegaMethod);
    // Oscillator energy against |mu|^(2n) (it swings by about the damping ratio within a period).
    const double y = state.positions[2].y() - y0, v = state.velocities[2].y();
    const double energy = 0.5 * m * v * v + 0.5 * kEff * y * y, initial = 0.5 * kEff * amplitude * amplitude;
    EXPECT_NEAR(energy / initial, std::exp(-2.0 * decayMethod * steps * h), 0.1 * std::exp(-2.0 * decayMethod * steps * h));
}

// A small constant load on a torus held by anchor springs, stepped implicitly with a long time
// step (each step then is a Newton step of the statics) until it settles: the deflection
// matches K^-1 f from Eigen's SimplicialLDLT on the stiffness assembled at rest (the load is
// small enough that the nonlinearity is below 1e-7), for the whole part and for a region.
TEST(ImplicitStep, StaticDeflectionMatchesADirectSparseSolve) {
    const TriMesh mesh = makeTorus1();
    const double k = 2.0, ka = 0.1;
    const auto model = buildPartModel(mesh, {Material{k, 0.05}, 1.0, {}, {}, {}, {}});
    for (const bool inRegion : {false, true}) {
        SCOPED_TRACE(inRegion ? "region" : "full");
        const ActiveRegion region = firstMasses(*model, 300);
        const ActiveRegion* r = inRegion ? &region : nullptr;
        SimulationSettings s = implicitSettings(100.0);
        s.restoration.method = RestorationMethod::AnchorSprings;
        s.restoration.anchorStiffness = ka;
        s.restoration.anchorDamping = 0.0;
        s.implicit.maxIterations = 5000;
        const Index loaded = 120;
        const Vec3 load(1e-8, -2e-8, 0.5e-8);
        PartState state = PartState::atRest(*model);
        for (int i = 0; i < 30; ++i) {
            state.forces[loaded] += load;
            step(*model, s, r, state);
        }
        // Unknowns: the moving masses, 3 each.
        std::vector<int> unknown(model->massCount(), -1);
        int n = 0;
        for (Index m = 0; m < model->massCount(); ++m)
            if (r == nullptr || r->moves(m)) unknown[m] = n++;
        std::vector<Eigen::Triplet<double>> entries;
        auto add = [&](Index p, Index q, const Eigen::Matrix3d& block) {
            if (unknown[p] < 0 || unknown[q] < 0) return;
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j) entries.emplace_back(3 * unknown[p] + i, 3 * unknown[q] + j, block(i, j));
        };
        for (Index m = 0; m < model->massCount(); ++m) add(m, m, ka * Eigen::Matrix3d::Identity());
        for (std::size_t e = 0; e < model->springCount(); ++e) {
            const Index a = model->springA[e], b = model->springB[e];
            const Vec3 u = (model->restPositions[a] - model->restPositions[b]).normalized();
            const Eigen::Matrix3d block = k * u * u.transpose();
            add(a, a, block);
            add(b, b, block);
            add(a, b, -block);
            add(b, a, -block);
        }
        Eigen::SparseMatrix<double> stiffness(3 * n, 3 * n);
        stiffness.setFromTriplets(entries.begin(), entries.end());
        Eigen::VectorXd force = Eigen::VectorXd::Zero(3 * n);
        force.segment<3>(3 * unknown[loaded]) = load;
        const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> direct(stiffness);
        ASSERT_EQ(direct.info(), Eigen::Success);
        const Eigen::VectorXd expected = direct.solve(force);
        Eigen::VectorXd deflection(3 * n);
        for (Index m = 0; m < model->massCount(); ++m)
            if (unknown[m] >= 0) deflection.segment<3>(3 * unknown[m]) = state.positions[m] - model->restPositions[m];
        EXPECT_LT((deflection - expected).norm(), 1e-6 * expected.norm());
        for (Index m = 0; m < model->massCount(); ++m)
            if (unknown[m] < 0) {
                EXPECT_EQ(state.positions[m], model->restPositions[m]);
            }
    }
}

// Stiff steel-like springs on gram masses at 1 kHz: the explicit steps diverge (the stability
// check says so), the implicit one stays finite and the load deflects the part.
TEST(ImplicitStep, RunsStiffMaterialsTheExplicitStepsCannot) {
    const auto model = buildPartModel(makeTorus1(), {Material{1e6, 10.0}, 1e-3, {}, {}, {}, {}});
    SimulationSettings s = implicitSettings(1e-3);
    s.implicit.tolerance = 1e-6;
    s.implicit.maxIterations = 2000;
    SimulationSettings explicitSettings = s;
    explicitSettings.integrator = Integrator::SemiImplicitEuler;
    EXPECT_TRUE(analyzeStability(*model, explicitSettings).certainlyUnstable);
    const StabilityReport report = analyzeStability(*model, s);
    EXPECT_FALSE(report.possiblyUnstable);
    EXPECT_TRUE(report.message.empty()) << report.message;
    EXPECT_NE(analyzeStability(*model, explicitSettings).message.find("implicit"), std::string::npos);
    PartState state = PartState::atRest(*model);
    StepCounters counters;
    for (int i = 0; i < 50; ++i) {
        state.forces[7] += Vec3(0.0, 50.0, 0.0);
        stepFullModel(*model, s, {}, state, &counters);
    }
    EXPECT_GT((state.positions[7] - model->restPositions[7]).norm(), 1e-6);
    EXPECT_GT(counters.solverIterations, 50u);
    EXPECT_LE(counters.solverResidual, 1e-6);
}

// A fixed budget (tolerance 0) runs exactly that many iterations every step, and reports the
// residual it reached.
TEST(ImplicitStep, AFixedBudgetRunsExactlyItsIterations) {
    const auto model = buildPartModel(makeTorus1(), {Material{1e4, 1.0}, 1e-2, {}, {}, {}, {}});
    SimulationSettings s = implicitSettings(1e-3);
    s.implicit.tolerance = 0.0;
    s.implicit.maxIterations = 7;
    const ActiveRegion region = firstMasses(*model, 200);
    PartState state = PartState::atRest(*model);
    StepCounters counters;
    for (int i = 0; i < 10; ++i) {
        state.forces[50] += Vec3(1.0, 0.0, 0.0);
        stepActiveRegion(*model, s, region, state, &counters);
    }
    EXPECT_EQ(counters.solverIterations, 70u);
    EXPECT_GT(counters.solverResidual, 0.0);
    EXPECT_LT(counters.solverResidual, 1.0);
}

// The implicit step's trajectory, pinned (full model and a region; scalar code: the same bits on
// every CPU).
TEST(ImplicitStep, GoldenHash) {
    const auto model = buildPartModel(makeTorus1(), {Material{1e3, 0.5}, 0.01, {}, {}, {}, {}});
    SimulationSettings s = implicitSettings(1e-3);
    s.restoration.method = RestorationMethod::Constraint;
    s.gravity = Vec3(0, -9.81, 0);
    s.implicit.tolerance = 1e-8;
    s.implicit.maxIterations = 40;
    const ActiveRegion region = firstMasses(*model, 250);
    for (const bool inRegion : {false, true}) {
        PartState state = PartState::atRest(*model);
        for (int i = 0; i < 100; ++i) {
            state.forces[100] += Vec3(0.3, 0.2, -0.1);
            step(*model, s, inRegion ? &region : nullptr, state);
        }
        EXPECT_EQ(flexfit::testing::hex(stateHash(state)), inRegion ? "f93d07c51900ff18" : "9d77ee1b6f51cbc0");
    }
}

// A part with the implicit integrator steps its zones by the implicit region step even where the
// full step would cost less (the full step would not hold the region's edge), and a zone that
// covers every mass by the implicit full step.
TEST(ImplicitStep, PartsKeepTheRegionStepAtAnyCoverage) {
    const auto model = buildPartModel(makeTorus1(), {Material{1e3, 0.5}, 0.01, {}, {}, {}, {}});
    PartSettings settings;
    settings.mode = PartMode::RigidDeformable;
    settings.simulation = implicitSettings(1e-3);
    settings.simulation.implicit.tolerance = 1e-6;
    Part part(model, settings);
    part.openZone(ZoneSeed::mass(0), 13);
    ASSERT_GT(part.computedSprings().size(), model->springCount() / 2);
    ASSERT_LT(part.computedSprings().size(), model->springCount());
    ASSERT_TRUE(fullStepCostsLess(*model, RegionWork::of(part.region())));  // the explicit step would take the full step
    StepCounters counters;
    part.applyForce(0, Vec3(0, 1, 0));
    part.step(&counters);
    EXPECT_EQ(counters.springsEvaluated, part.computedSprings().size());
    EXPECT_GT(counters.solverIterations, 0u);
    part.openZone(ZoneSeed::mass(0), 40);
    ASSERT_EQ(part.movingMasses().size(), model->massCount());
    StepCounters whole;
    part.step(&whole);
    EXPECT_EQ(whole.springsEvaluated, model->springCount());
}
