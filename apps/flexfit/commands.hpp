// The `flexfit` command's subcommands. Each registers its options on the CLI11 app and runs
// through a callback; errors in user input surface as flexfit::InputError and are printed by
// main() with the file, line and problem, and a simulation that diverged as
// flexfit::DivergenceError (the body, the time, the likely cause): both exit with status 2.
#pragma once

#include <CLI/CLI.hpp>

namespace flexfit::cli {

void registerInfo(CLI::App& app);
void registerConvert(CLI::App& app);
void registerGen(CLI::App& app);
void registerSimulate(CLI::App& app);
void registerCollide(CLI::App& app);
void registerRun(CLI::App& app);
void registerSweep(CLI::App& app);
void registerRemesh(CLI::App& app);
void registerExperimentContact(CLI::App& experiment);
void registerExperimentBallTorus(CLI::App& experiment);
void registerExperimentRestoration(CLI::App& experiment);
void registerExperimentZones(CLI::App& experiment);

}  // namespace flexfit::cli
