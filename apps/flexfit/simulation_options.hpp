// Command-line options that build a PartModel and SimulationSettings (shared by subcommands).
#pragma once

#include "flexfit/flexfit.hpp"

#include <CLI/CLI.hpp>

#include <memory>
#include <string>

namespace flexfit::cli {

struct SimulationOptions {
    std::string material = "elastic";
    double stiffness = -1.0, damping = -1.0;  // < 0: the material's
    double vertexMass = 1.0;
    ShellMaterial shell;  // used when youngsModulus > 0 (--youngs-modulus)
    std::string restore = "constraint";
    double anchorStiffness = -1.0, anchorDamping = -1.0;  // < 0: the material's k and b
    double constraintFraction = 1e-3;
    double constraintRate = 0.0;  // > 0 replaces the fraction
    std::string integrator = "semi-implicit";
    int implicitIterations = 50;
    double implicitTolerance = 1e-6;
    double timeStep = 1e-3;
    std::string gravity = "0,0,0";
    double globalDamping = 0.0;
    bool allowUnstable = false;
    CLI::Option* fractionOption = nullptr;  // --constraint-fraction and --constraint-rate: given or not
    CLI::Option* rateOption = nullptr;

    void addTo(CLI::App& cmd);
    Material resolvedMaterial() const;
    PartModelSettings modelSettings() const;
    // Validated settings; prints a stability warning or throws InputError when the step is
    // certain to diverge (unless allowUnstable), and a warning when the restoration constraint
    // takes its default fraction (per step, chosen for 1 ms) at another --dt.
    SimulationSettings simulationSettings(const PartModel& model) const;
};

}  // namespace flexfit::cli
