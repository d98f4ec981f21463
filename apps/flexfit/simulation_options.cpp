#include "simulation_options.hpp"

#include "cli_common.hpp"

#include <fmt/core.h>

#include <algorithm>

namespace flexfit::cli {

void SimulationOptions::addTo(CLI::App& cmd) {
    auto* preset = cmd.add_option("--material", material, "Spring material preset (thesis Table 4.1)")
                       ->check(CLI::IsMember({"rigid", "elastic", "superelastic"}))->capture_default_str();
    auto* k = cmd.add_option("--stiffness", stiffness, "Spring stiffness k (overrides the preset)")->check(nonNegativeNumber);
    auto* b = cmd.add_option("--damping", damping, "Spring damping b (overrides the preset)")->check(nonNegativeNumber);
    auto* m = cmd.add_option("--mass", vertexMass, "Mass of every vertex (kg)")->check(positiveNumber)->capture_default_str();
    // A physical material (the mesh in metres): it gives the springs and the masses.
    auto* e = cmd.add_option("--youngs-modulus", shell.youngsModulus,
                             "Physical material: Young's modulus (Pa) of a shell of the surface; needs --thickness and --density")
                  ->check(positiveNumber);
    auto* t = cmd.add_option("--thickness", shell.thickness, "Physical material: shell thickness (m)")->check(positiveNumber);
    auto* rho = cmd.add_option("--density", shell.density, "Physical material: density (kg/m^3)")->check(positiveNumber);
    auto* nu = cmd.add_option("--poisson-ratio", shell.poissonRatio, "Physical material: Poisson's ratio [0, 0.5) (bending rigidity)")
                   ->check(CLI::Validator(
                       [](std::string& text) {
                           double v = 0.0;
                           if (!CLI::detail::lexical_cast(text, v) || !(v >= 0.0 && v < 0.5)) return std::string("must be in [0, 0.5)");
                           return std::string();
                       },
                       "FLOAT in [0, 0.5)"))
                   ->capture_default_str();
    auto* zeta = cmd.add_option("--damping-ratio", shell.dampingRatio, "Physical material: damping ratio of each spring")
                     ->check(nonNegativeNumber)->capture_default_str();
    auto* bend = cmd.add_flag("--bending-springs", shell.bendingSprings, "Physical material: a spring across each interior edge");
    e->needs(t)->needs(rho)->excludes(preset)->excludes(k)->excludes(b)->excludes(m);
    for (CLI::Option* o : {t, rho, nu, zeta, bend}) o->needs(e);
    cmd.add_option("--restore", restore, "Shape restoration: " + nameList<RestorationMethod>())
        ->check(CLI::IsMember(enumChoices<RestorationMethod>()))->capture_default_str();
    cmd.add_option("--anchor-stiffness", anchorStiffness, "Anchor spring k_a (default: the material's k; a physical material's mean spring k)")
        ->check(nonNegativeNumber);
    cmd.add_option("--anchor-damping", anchorDamping, "Anchor spring b_a (default: the material's b; a physical material's mean spring b)")
        ->check(nonNegativeNumber);
    fractionOption = cmd.add_option("--constraint-fraction", constraintFraction, "Share of the separation restored per step (0, 1]")
                         ->capture_default_str();
    rateOption = cmd.add_option("--constraint-rate", constraintRate,
                   "Restoration as a rate (1/s), the same restoration time at any --dt; replaces --constraint-fraction")
        ->check(nonNegativeNumber);
    cmd.add_option("--integrator", integrator, "Time integrator: " + nameList<Integrator>())
        ->check(CLI::IsMember(enumChoices<Integrator>()))->capture_default_str();
    cmd.add_option("--implicit-iterations", implicitIterations, "Implicit integrator: conjugate-gradient iterations at most")
        ->check(positiveNumber)->capture_default_str();
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
    if (shell.youngsModulus > 0.0) s.shell = shell;
    return s;
}

namespace {

// The model's mean spring constants: the anchors' default under a physical material.
Material meanSpring(const PartModel& model) {
    Material mean{0.0, 0.0};
    const double n = double(std::max<std::size_t>(model.springCount(), 1));
    for (std::size_t e = 0; e < model.springCount(); ++e) {
        mean.stiffness += model.stiffness[e] / n;
        mean.damping += model.damping[e] / n;
    }
    return mean;
}

}  // namespace

SimulationSettings SimulationOptions::simulationSettings(const PartModel& model) const {
    const Material m = shell.youngsModulus > 0.0 ? meanSpring(model) : resolvedMaterial();
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
    const bool defaultFraction = fractionOption == nullptr || fractionOption->count() == 0;
    const bool rateGiven = rateOption != nullptr && rateOption->count() > 0;
    if (defaultFraction && !rateGiven)
        if (const std::optional<DefaultFractionElsewhere> d = defaultFractionAt(s.restoration, timeStep))
            warn("option --dt: " + describe(*d, {"--dt ", "--constraint-rate ", "", "--restore anchors"}));
    return s;
}

}  // namespace flexfit::cli
