// flexfit: the command-line front end of the Flexfit library.
#include "commands.hpp"

#include "flexfit/core.hpp"

#include <fmt/core.h>

int main(int argc, char** argv) {
    CLI::App app{"flexfit: rigid-deformable parts for virtual assembly"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "flexfit 0.1.0");
    flexfit::cli::registerInfo(app);
    flexfit::cli::registerConvert(app);
    flexfit::cli::registerGen(app);
    flexfit::cli::registerSimulate(app);
    flexfit::cli::registerCollide(app);
    flexfit::cli::registerRun(app);
    flexfit::cli::registerSweep(app);
    flexfit::cli::registerRemesh(app);
    CLI::App* experiment = app.add_subcommand("experiment", "Reproduce the thesis's experiments");
    experiment->require_subcommand(1);
    flexfit::cli::registerExperimentRestoration(*experiment);
    flexfit::cli::registerExperimentZones(*experiment);
    flexfit::cli::registerExperimentContact(*experiment);
    flexfit::cli::registerExperimentBallTorus(*experiment);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help prints and succeeds; a usage error (an unknown option, a value out of range)
        // exits 2 like every other input error.
        return app.exit(e) == 0 ? 0 : 2;
    } catch (const flexfit::InputError& e) {
        fmt::print(stderr, "error: {}\n", e.what());
        return 2;
    } catch (const flexfit::DivergenceError& e) {  // the run wrote nothing (PendingFiles)
        fmt::print(stderr, "error: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        fmt::print(stderr, "error: {}\n", e.what());
        return 1;
    }
    return 0;
}
