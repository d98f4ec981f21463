// flexfit sweep SWEEP.toml --out DIR: every run of a parameter sweep (flexfit/sweep.hpp) on this
// machine's cores, and one table of results (sweep_runner.hpp).
#include "cli_common.hpp"
#include "commands.hpp"
#include "sweep_runner.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <thread>

namespace flexfit::cli {

void registerSweep(CLI::App& app) {
    auto* cmd = app.add_subcommand("sweep", "Run every combination of a sweep file's parameters and gather one table (results.csv)");
    struct Options {
        std::string sweep, out;
        int jobs = 0;
        bool noProgress = false, list = false;
        SceneOptions read;
    };
    auto opt = std::make_shared<Options>();
    cmd->add_option("sweep", opt->sweep, "Sweep file (.toml): a base scene and the parameters to vary")->required();
    cmd->add_option("--out", opt->out, "Directory for runs/<id>/ and results.csv (a rerun runs only what is missing)")->required();
    cmd->add_option("--jobs", opt->jobs, "Runs at once (default: the machine's cores)")->check(CLI::Range(1, 1024));
    cmd->add_flag("--list", opt->list, "Print the runs (id and values) and whether each is done, run nothing");
    cmd->add_flag("--no-progress", opt->noProgress, "No progress bar");
    addSceneOptions(cmd, opt->read);
    cmd->callback([opt] {
        const Sweep sweep = loadSweep(opt->sweep, true, opt->read.read());
        printWarnings(sweep.scene.string(), sweep.warnings);
        if (opt->list) {
            for (std::size_t r = 0; r < sweep.runs.size(); ++r) {
                fmt::print("{} {}", sweep.runs[r].id, sweepRunDone(sweep, r, opt->out) ? "done   " : "missing");
                const auto labels = sweep.labels(r);
                for (std::size_t p = 0; p < labels.size(); ++p) fmt::print(" {}={}", sweep.parameters[p].name, labels[p]);
                fmt::print("\n");
            }
            return;
        }
        const int jobs = opt->jobs > 0 ? opt->jobs : int(std::max(1u, std::thread::hardware_concurrency()));
        const auto ran = runSweep(sweep, opt->out, jobs, !opt->noProgress);
        fmt::print("{}: {} runs ({} run now, {} done before) on {} threads; table {}\n", opt->sweep, sweep.runs.size(), ran.size(),
                   sweep.runs.size() - ran.size(), jobs, (std::filesystem::path(opt->out) / "results.csv").string());
        // A diverged run is a result (its row says so), but not one to pass unseen.
        if (const std::vector<std::string> notOk = sweepRunsNotOk(sweep, opt->out); !notOk.empty())
            fmt::print(stderr, "warning: {} of {} runs diverged ({}): results.csv has their status and message\n", notOk.size(),
                       sweep.runs.size(), fmt::join(notOk, ", "));
    });
}

}  // namespace flexfit::cli
