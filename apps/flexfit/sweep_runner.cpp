#include "sweep_runner.hpp"

#include "cli_common.hpp"
#include "progress.hpp"
#include "scene_runner.hpp"

#include <fmt/core.h>

#include <atomic>
#include <exception>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

namespace flexfit::cli {
namespace {

// A CSV field: quoted when it holds a comma, a quote or a line break.
std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

std::string optional(const std::optional<double>& v) { return v ? fmt::format("{:.6f}", *v) : ""; }

std::string header(const Sweep& sweep, const Scene& scene) {
    std::string h = "run";
    for (const SweepParameter& p : sweep.parameters) h += "," + csvField(p.name);
    h += ",status,steps,simulated_seconds,contact_steps,max_contacts,max_zones,max_moving_masses,max_computed_springs,max_deformation,"
         "last_contact,restored_at,max_coupling_force,assembled_at,assembly_events";
    for (const ScenePart& part : scene.parts) {  // every part's final centre (loadSweep: the same parts in every run)
        const std::string& n = part.name;
        h += "," + csvField(n + "_x") + "," + csvField(n + "_y") + "," + csvField(n + "_z");
    }
    return h + ",state_hash,message\n";
}

std::string rowStart(const Sweep& sweep, std::size_t run) {
    std::string row = sweep.runs[run].id;
    for (const std::string& label : sweep.labels(run)) row += "," + csvField(label);
    return row;
}

std::string resultRow(const Sweep& sweep, std::size_t run, const Scene& scene, const RunSummary& s) {
    std::string row = rowStart(sweep, run);
    row += fmt::format(",ok,{},{:.6f},{},{},{},{},{},{:.9g},{},{},{:.9g},{},{}", s.steps, s.simulatedSeconds, s.contactSteps, s.maxContacts, s.maxZones,
                       s.maxMovingMasses, s.maxComputedSprings, s.maxDeformation, optional(s.lastContact), optional(s.restored),
                       s.maxCouplingForce, s.events.empty() ? std::string() : fmt::format("{:.6f}", s.events.front().time), s.events.size());
    for (std::size_t i = 0; i < scene.parts.size(); ++i)
        row += fmt::format(",{:.9g},{:.9g},{:.9g}", s.finalCentres[i].x(), s.finalCentres[i].y(), s.finalCentres[i].z());
    return row + fmt::format(",{:016x},\n", s.stateHash);
}

std::string failedRow(const Sweep& sweep, std::size_t run, const Scene& scene, const std::string& status, const std::string& message) {
    std::string row = rowStart(sweep, run) + "," + status + std::string(13, ',');
    row += std::string(3 * scene.parts.size(), ',');
    return row + ",," + csvField(message) + "\n";  // no state hash
}

std::filesystem::path rowPath(const Sweep& sweep, std::size_t run, const std::filesystem::path& out) {
    return sweepRunDirectory(sweep, run, out) / "row.csv";
}

}  // namespace

std::filesystem::path sweepRunDirectory(const Sweep& sweep, std::size_t run, const std::filesystem::path& out) {
    return out / "runs" / sweep.runs.at(run).id;
}

bool sweepRunDone(const Sweep& sweep, std::size_t run, const std::filesystem::path& out) {
    return std::filesystem::is_regular_file(rowPath(sweep, run, out));
}

std::vector<std::size_t> missingSweepRuns(const Sweep& sweep, const std::filesystem::path& out) {
    std::vector<std::size_t> missing;
    for (std::size_t r = 0; r < sweep.runs.size(); ++r)
        if (!sweepRunDone(sweep, r, out)) missing.push_back(r);
    return missing;
}

bool runSweepRun(const Sweep& sweep, std::size_t run, const std::filesystem::path& out) {
    if (sweepRunDone(sweep, run, out)) return false;
    const Scene scene = sweepScene(sweep, run);
    RunOptions options;
    options.out = sweepRunDirectory(sweep, run, out);
    options.progress = false;
    std::string row;
    try {
        row = resultRow(sweep, run, scene, runScene(scene, options));
    } catch (const DivergenceError& e) {
        makeDirectory(options.out);
        row = failedRow(sweep, run, scene, "diverged", e.what());
    }
    PendingFiles files;  // the row appears whole or not at all
    writeWholeFile(files.add(rowPath(sweep, run, out)), row);
    files.commit();
    return true;
}

std::vector<std::string> sweepRunsNotOk(const Sweep& sweep, const std::filesystem::path& out) {
    std::vector<std::string> ids;
    for (std::size_t r = 0; r < sweep.runs.size(); ++r) {
        std::ifstream in(rowPath(sweep, r, out), std::ios::binary);
        std::string row;
        if (!in || !std::getline(in, row)) continue;
        const std::string start = rowStart(sweep, r);
        if (row.compare(0, start.size() + 4, start + ",ok,") != 0) ids.push_back(sweep.runs[r].id);
    }
    return ids;
}

std::filesystem::path writeSweepTable(const Sweep& sweep, const std::filesystem::path& out) {
    std::string table = header(sweep, sweepScene(sweep, 0));
    for (std::size_t r = 0; r < sweep.runs.size(); ++r) {
        std::ifstream in(rowPath(sweep, r, out), std::ios::binary);
        if (!in) throw InputError(rowPath(sweep, r, out).string(), 0, "run " + sweep.runs[r].id + " is not done");
        std::ostringstream row;
        row << in.rdbuf();
        table += row.str();
    }
    const std::filesystem::path path = out / "results.csv";
    PendingFiles files;
    writeWholeFile(files.add(path), table);
    files.commit();
    return path;
}

std::vector<std::size_t> runSweep(const Sweep& sweep, const std::filesystem::path& out, int jobs, bool progress) {
    makeDirectory(out);
    const std::vector<std::size_t> missing = missingSweepRuns(sweep, out);
    std::atomic<std::size_t> next{0}, done{0};
    std::mutex failure;
    std::exception_ptr error;
    ProgressBar bar(fmt::format("sweep {} ({} runs)", sweep.file.filename().string(), missing.size()), progress);
    auto work = [&] {
        for (std::size_t i; (i = next++) < missing.size();) {
            try {
                runSweepRun(sweep, missing[i], out);
            } catch (...) {
                const std::lock_guard lock(failure);
                if (!error) error = std::current_exception();
                next = missing.size();  // the others stop after their current run
            }
            const std::size_t finished = ++done;
            if (progress) {
                const std::lock_guard lock(failure);
                bar.update(double(finished) / double(missing.size()));
            }
        }
    };
    if (jobs < 1 || jobs > 1024) throw InputError("jobs", 0, "must be 1 to 1024 (got " + std::to_string(jobs) + ")");
    std::vector<std::thread> threads;
    try {
        for (int t = 1; t < jobs; ++t) threads.emplace_back(work);
    } catch (...) {  // no more threads: stop the others after their current run
        next = missing.size();
        for (std::thread& t : threads) t.join();
        throw;
    }
    work();
    for (std::thread& t : threads) t.join();
    bar.finish();
    if (error) std::rethrow_exception(error);
    writeSweepTable(sweep, out);
    return missing;
}

}  // namespace flexfit::cli
