#include "simulation_options.hpp"

#include "cli_common.hpp"

#include <fmt/core.h>

namespace flexfit::cli {

void SimulationOptions::addTo(CLI::App& cmd) {
    cmd.add_option("--material", material, "Spring material preset (thesis Table 4.1)")
        ->check(CLI::IsMember({"rigid", "elastic", "superelastic"}))->capture_default_str();
    cmd.add_option("--stiffness", stiffness, "Spring stiffness k (overrides the preset)")->check(CLI::NonNegativeNumber);
    cmd.add_option("--damping", damping, "Spring damping b (overrides the preset)")->check(CLI::NonNegativeNumber);
    cmd.add_option("--mass", vertexMass, "Mass of every vertex (kg)")->check(CLI::PositiveNumber)->capture_default_str();
    cmd.add_option("--restore", restore, "Shape restoration: " + nameList<RestorationMethod>())
        ->check(CLI::IsMember(enumChoices<RestorationMethod>()))->capture_default_str();
    cmd.add_option("--anchor-stiffness", anchorStiffness, "Anchor spring k_a (default: the material's k)")
        ->check(CLI::NonNegativeNumber);
    cmd.add_option("--anchor-damping", anchorDamping, "Anchor spring b_a (default: the material's b)")
        ->check(CLI::NonNegativeNumber);
    cmd.add_option("--constraint-fraction", constraintFraction, "Share of the separation restored per step (0, 1]")
        ->capture_default_str();
    cmd.add_option("--constraint-rate", constraintRate,
                   "Restoration as a rate (1/s), the same restoration time at any --dt; replaces --constraint-fraction")
        ->check(CLI::NonNegativeNumber);
    cmd.add_option("--integrator", integrator, "Time integrator: " + nameList<Integrator>())
        ->check(CLI::IsMember(enumChoices<Integrator>()))->capture_default_str();
    cmd.add_option("--implicit-iterations", implicitIterations, "Implicit integrator: conjugate-gradient iterations at most")
        ->check(CLI::PositiveNumber)->capture_default_str();
    cmd.add_option("--implicit-tolerance", implicitTolerance,
                   "Implicit integrator: relative residual to stop at (0: always run every iteration)")
        ->check(CLI::Range(0.0, 0.999999))->capture_default_str();
    cmd.add_option("--dt", timeStep, "Time step (s)")->capture_default_str();
    cmd.add_option("--gravity", gravity, "Gravity x,y,z (m/s^2)")->capture_default_str();
    cmd.add_option("--global-damping", globalDamping, "Global damping gamma (kg/s)")->capture_default_str();
    cmd.add_flag("--allow-unstable", allowUnstable, "Run even when the time step is certain to diverge");
}

Material SimulationOptions::resolvedMaterial() const {
    Material m = *materialPreset(material);
    if (stiffness >= 0.0) m.stiffness = stiffness;
    if (damping >= 0.0) m.damping = damping;
    return m;
}

PartModelSettings SimulationOptions::modelSettings() const {
    PartModelSettings s;
    s.material = resolvedMaterial();
    s.vertexMass = vertexMass;
    return s;
}

SimulationSettings SimulationOptions::simulationSettings(const PartModel& model) const {
    const Material m = resolvedMaterial();
    SimulationSettings s;
    s.timeStep = timeStep;
    s.integrator = enumOption<Integrator>(integrator, "option --integrator");
    s.implicit.maxIterations = implicitIterations;
    s.implicit.tolerance = implicitTolerance;
    s.gravity = parseVec3(gravity, "--gravity");
    s.globalDamping = globalDamping;
    s.restoration.method = enumOption<RestorationMethod>(restore, "option --restore");
    s.restoration.anchorStiffness = anchorStiffness >= 0.0 ? anchorStiffness : m.stiffness;
    s.restoration.anchorDamping = anchorDamping >= 0.0 ? anchorDamping : m.damping;
    s.restoration.constraintFraction = constraintFraction;
    s.restoration.constraintRate = constraintRate;
    validateSettings(s);
    const StabilityReport stability = analyzeStability(model, s);
    if (stability.certainlyUnstable && !allowUnstable)
        throw InputError("option --dt", 0, stability.message + " (or pass --allow-unstable)");
    if (!stability.message.empty()) fmt::print(stderr, "warning: {}\n", stability.message);
    return s;
}

}  // namespace flexfit::cli
