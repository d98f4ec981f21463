// Runs a sweep's runs (flexfit/sweep.hpp) and gathers their results in one table. Shared by
// `flexfit sweep` (threads on this machine) and the Python module's flexfit.sweep (a Dask
// cluster's workers each call runSweepRun).
//
// Layout under the output directory:
//   runs/<id>/metrics.csv, summary.json   what `flexfit run` writes, per run
//   runs/<id>/row.csv                     the run's row of the table, written last: a run is
//                                         done when it exists (a restart skips it)
//   results.csv                           every run's row in the sweep's order, under a header
// The table holds what a run computes (maxima, times, hashes), never wall times, so it is the
// same bit for bit whatever the number of workers and the order the runs finish in.
#pragma once

#include "flexfit/sweep.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace flexfit::cli {

std::filesystem::path sweepRunDirectory(const Sweep& sweep, std::size_t run, const std::filesystem::path& out);
bool sweepRunDone(const Sweep& sweep, std::size_t run, const std::filesystem::path& out);
// The runs without a row yet, in order.
std::vector<std::size_t> missingSweepRuns(const Sweep& sweep, const std::filesystem::path& out);

// Runs one run into its directory (a run that diverges is a row with status "diverged" and the
// message). Returns false, running nothing, when it was already done.
bool runSweepRun(const Sweep& sweep, std::size_t run, const std::filesystem::path& out);

// Writes out/results.csv from every run's row; throws InputError naming the first run not done.
std::filesystem::path writeSweepTable(const Sweep& sweep, const std::filesystem::path& out);

// The ids of the done runs whose status is not "ok" (diverged), in order.
std::vector<std::string> sweepRunsNotOk(const Sweep& sweep, const std::filesystem::path& out);

// Runs the missing runs on `jobs` threads, then writes the table. Returns the runs it ran.
std::vector<std::size_t> runSweep(const Sweep& sweep, const std::filesystem::path& out, int jobs, bool progress);

}  // namespace flexfit::cli
