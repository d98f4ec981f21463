// analyzeStability against direct simulation: the reported limits bracket the time step at
// which a simulated oscillator actually diverges.
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace flexfit;

namespace {

// One mass on a spring to a practically immovable mass: a single mode, w^2 = k/m, c = b/m.
std::shared_ptr<const PartModel> oscillator(double k, double b) {
    TriMesh mesh;
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}};
    mesh.faces = {{0, 1, 2}};
    PartModelSettings settings;
    settings.vertexMasses = {1.0, 1e15, 1e15};
    settings.springMaterials = {{k, b}, {0, 0}, {0, 0}};
    return buildPartModel(mesh, settings);
}

// Largest displacement over 2,000 steps from a 0.01 stretch.
double simulatedAmplitude(const PartModel& model, const SimulationSettings& settings) {
    PartState state = PartState::atRest(model);
    state.positions[0].x() = -0.01;
    double amplitude = 0.0;
    for (int step = 0; step < 2000; ++step) {
        stepFullModel(model, settings, {}, state);
        amplitude = std::max(amplitude, std::abs(state.positions[0].x()));
        if (!(amplitude < 1e6)) break;
    }
    return amplitude;
}

SimulationSettings with(Integrator integrator, double dt) {
    SimulationSettings s;
    s.integrator = integrator;
    s.timeStep = dt;
    s.restoration.method = RestorationMethod::None;
    return s;
}

}  // namespace

TEST(Stability, SymplecticLimitMatchesSimulation) {
    const auto model = oscillator(100.0, 0.0);  // w = 10 rad/s: diverges above h = 0.2 s
    const StabilityReport report = analyzeStability(*model, with(Integrator::SemiImplicitEuler, 0.1));
    EXPECT_NEAR(report.omegaUpper, 10.0, 1e-6);
    EXPECT_LE(report.omegaLower, report.omegaUpper + 1e-9);
    EXPECT_NEAR(report.safeTimeStep, 0.2, 1e-6);
    EXPECT_FALSE(report.possiblyUnstable);
    EXPECT_LT(simulatedAmplitude(*model, with(Integrator::SemiImplicitEuler, 0.19)), 0.1);
    EXPECT_GT(simulatedAmplitude(*model, with(Integrator::SemiImplicitEuler, 0.21)), 1.0);
    EXPECT_TRUE(analyzeStability(*model, with(Integrator::SemiImplicitEuler, 0.21)).possiblyUnstable);
}

TEST(Stability, ExplicitEulerNeedsDampingAndStaysBelowBOverK) {
    const auto undamped = oscillator(1.0, 0.0);
    const StabilityReport r = analyzeStability(*undamped, with(Integrator::ExplicitEuler, 1e-4));
    EXPECT_TRUE(r.certainlyUnstable);
    EXPECT_FALSE(r.message.empty());

    const auto damped = oscillator(1.0, 0.1);  // h < b/k = 0.1 s
    const StabilityReport ok = analyzeStability(*damped, with(Integrator::ExplicitEuler, 0.05));
    EXPECT_FALSE(ok.possiblyUnstable);
    EXPECT_NEAR(ok.safeTimeStep, 0.1, 1e-6);
    EXPECT_LT(simulatedAmplitude(*damped, with(Integrator::ExplicitEuler, 0.08)), 0.02);
    EXPECT_GT(simulatedAmplitude(*damped, with(Integrator::ExplicitEuler, 0.2)), 1.0);
}

TEST(Stability, ThesisPresetsAreStableAtOneMillisecond) {
    for (const Material m : {Material::rigid(), Material::elastic(), Material::superelastic()}) {
        const auto model = buildPartModel(makeTorus1(), {m, 1.0, {}, {}, {}, {}});
        for (Integrator integrator : {Integrator::SemiImplicitEuler, Integrator::ExplicitEuler}) {
            const StabilityReport report = analyzeStability(*model, with(integrator, 1e-3));
            EXPECT_FALSE(report.possiblyUnstable) << report.message;
            EXPECT_TRUE(report.message.empty());
        }
    }
}

TEST(Stability, StiffMaterialIsRejectedAndItsBoundHolds) {
    const auto model = buildPartModel(makeTorus1(), {Material{1e6, 0.0}, 1.0, {}, {}, {}, {}});
    SimulationSettings settings = with(Integrator::SemiImplicitEuler, 1e-2);
    const StabilityReport report = analyzeStability(*model, settings);
    EXPECT_TRUE(report.certainlyUnstable);
    EXPECT_NE(report.message.find("diverges"), std::string::npos);
    // Just inside the guaranteed-safe step the torus stays bounded.
    settings.timeStep = 0.99 * report.safeTimeStep;
    PartState state = PartState::atRest(*model);
    state.positions[0].x() += 0.01;
    for (int step = 0; step < 3000; ++step) stepFullModel(*model, settings, {}, state);
    for (std::size_t i = 0; i < model->massCount(); ++i)
        ASSERT_LT((state.positions[i] - model->restPositions[i]).norm(), 1.0) << "mass " << i;
}

// Masses far below the springs' scale: the bound is damping-dominated, where (-c + sqrt(c^2 +
// 4 w^2)) / w^2 cancelled to 0 (mass 1e-100) or read NaN (1e-300: c^2 overflows). The bound
// stays finite and below the unstable step (positive where it can be), and no message prints a
// NaN.
TEST(Stability, TinyMassesGiveAFiniteBoundAndAMessageWithoutNaN) {
    for (const double mass : {1e-100, 1e-300}) {
        const auto model = buildPartModel(makeTorus1(), {Material{1.0, 0.1}, mass, {}, {}, {}, {}});
        const StabilityReport report = analyzeStability(*model, with(Integrator::SemiImplicitEuler, 1e-3));
        EXPECT_TRUE(report.certainlyUnstable) << mass;
        EXPECT_TRUE(std::isfinite(report.safeTimeStep)) << mass;
        EXPECT_LE(report.safeTimeStep, report.unstableTimeStep) << mass;
        if (mass == 1e-100) {
            EXPECT_GT(report.safeTimeStep, 0.0);
        }
        EXPECT_EQ(report.message.find("nan"), std::string::npos) << report.message;
    }
}
