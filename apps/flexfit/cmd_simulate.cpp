// flexfit simulate FILE: a full-deformable part under point loads, with per-step metrics.
#include "cli_common.hpp"
#include "commands.hpp"
#include "perturbation_run.hpp"
#include "progress.hpp"
#include "simulation_options.hpp"

#include <fmt/core.h>

#include <cmath>
#include <fstream>

namespace flexfit::cli {
namespace {

struct SimulateOptions {
    std::string file;
    MeshOptions mesh;
    SimulationOptions sim;
    std::vector<std::string> forces;
    std::vector<std::string> kicks;
    std::string vertexOrder = "locality";
    double forceDuration = 0.5, duration = 10.0;
    std::vector<double> thresholds{0.01, 0.1};
    std::string csv;
    int every = 1;
    std::vector<double> objTimes;
    std::string objPrefix = "frame";
    bool untilRestored = false;
    std::string mode = "full-deformable";
    std::vector<std::string> zones;
    int defaultLevel = 2;
};

// Writes the deformed mesh whenever the simulation crosses one of the requested times (as a
// pending file: moved into place when the run has finished).
class ObjFrames {
public:
    ObjFrames(const PartModel& model, std::vector<double> times, std::string prefix, PendingFiles& files)
        : model_(model), times_(std::move(times)), prefix_(std::move(prefix)), files_(files) {
        std::sort(times_.begin(), times_.end());
    }
    void observe(const Part& part) {
        while (next_ < times_.size() && part.time() + 1e-12 >= times_[next_]) {
            TriMesh mesh = model_.drawnMesh();
            part.drawnWorldPositions(mesh.vertices);
            const std::string path = fmt::format("{}_{:.4f}.obj", prefix_, times_[next_]);
            writeObj(mesh, files_.add(path));
            written_.push_back(fmt::format("wrote {} (t = {:.4f} s)", path, part.time()));
            ++next_;
        }
    }
    // What was written, once it is in place.
    void report() const {
        for (const std::string& line : written_) fmt::print("{}\n", line);
    }

private:
    const PartModel& model_;
    std::vector<double> times_;
    std::string prefix_;
    PendingFiles& files_;
    std::vector<std::string> written_;
    std::size_t next_ = 0;
};

void run(const SimulateOptions& opt) {
    const MeshReadResult read = loadMesh(opt.file, opt.mesh.read());
    PerturbationConfig config;
    PartModelSettings modelSettings = opt.sim.modelSettings();
    modelSettings.vertexOrder = opt.vertexOrder == "locality" ? VertexOrder::Locality : VertexOrder::AsGiven;
    modelSettings.fileVertices = read.fileVertices;
    config.model = buildPartModel(read.mesh, modelSettings);
    // MASS arguments name the file's vertices; the model's masses may be renumbered.
    const auto massOf = [&](Index vertex) { return config.model->massOf(vertex); };
    config.part.simulation = opt.sim.simulationSettings(*config.model);
    config.part.mode = enumOption<PartMode>(opt.mode, "option --mode");
    config.part.zones.defaultLevel = opt.defaultLevel;
    config.part.zones.activityThreshold = opt.thresholds.empty() ? 0.01 : opt.thresholds.front();
    for (const std::string& z : opt.zones) {
        ZoneRequest zone = parseZone(z, "--zone");
        if (zone.seed.kind == ZoneSeed::Kind::Mass) zone.seed.index = massOf(zone.seed.index);
        config.zones.push_back(zone);
    }
    for (const std::string& f : opt.forces) {
        PointLoad load = parseLoad(f, "--force");
        config.loads.push_back({massOf(load.mass), load.force});
    }
    for (const std::string& k : opt.kicks) {
        const PointLoad kick = parseLoad(k, "--kick");
        config.kicks.push_back({massOf(kick.mass), kick.force});
    }
    // Kicked and never pushed: the part is released (its restoration clock starts) at once.
    config.loadDuration = opt.forces.empty() && !opt.kicks.empty() ? 0.0 : opt.forceDuration;
    config.duration = opt.duration;
    if (const std::optional<std::string> problem = stepCountProblem(opt.duration, config.part.simulation.timeStep))
        throw InputError("options --duration and --dt", 0, *problem);
    config.stopWhenRestored = opt.untilRestored;
    config.thresholds = opt.thresholds;

    // The CSV and the frames are written under temporary names and moved into place at the end:
    // a run that diverges (DivergenceError) or fails leaves none of them half-written.
    PendingFiles files;
    std::ofstream csv;
    if (!opt.csv.empty()) {
        csv.open(files.add(opt.csv));
        if (!csv) throw InputError(opt.csv, 0, "cannot open the file for writing");
        csv << "step,time";
        for (double t : opt.thresholds) csv << ",active_" << t;
        csv << ",kinetic_energy,max_displacement,moving_masses,computed_springs,zones\n";
    }
    ObjFrames frames(*config.model, opt.objTimes, opt.objPrefix, files);
    const PartModel& model = *config.model;
    auto observer = [&](const Part& part, const std::vector<ActivityTracker>& trackers) {
        const PartState& state = part.state();
        frames.observe(part);
        if (!csv.is_open() || state.stepCount % std::uint64_t(opt.every) != 0) return;
        double kinetic = 0.0, displacement = 0.0;
        for (Index i : part.movingMasses()) {
            kinetic += 0.5 * model.mass[i] * state.velocities[i].squaredNorm();
            displacement = std::max(displacement, (state.positions[i] - model.restPositions[i]).norm());
        }
        // A state whose positions stay finite while its energy overflows (a uniform load far
        // beyond the model's scale: every mass moves together, which the part's spread check does
        // not see) is a divergence, not a row of inf.
        if (!std::isfinite(kinetic) || !std::isfinite(displacement))
            throw DivergenceError(std::nullopt, state.time,
                                  "its kinetic energy or largest displacement overflows a double: a load, gravity or speed far beyond "
                                  "the model's scale",
                                  model.name);
        csv << state.stepCount << "," << fmt::format("{:.6f}", state.time);
        for (const ActivityTracker& t : trackers) csv << "," << t.activeNow();
        csv << "," << fmt::format("{:.9g},{:.9g}", kinetic, displacement) << "," << part.movingMasses().size() << ","
            << part.computedSprings().size() << "," << part.zoneCount() << "\n";
    };
    ProgressBar bar("simulate");
    const PerturbationResult result = runPerturbation(config, observer, [&](double f) { bar.update(f); });
    bar.finish();
    if (csv.is_open()) {
        csv.close();
        if (!csv) throw InputError(opt.csv, 0, "write failed");
    }
    files.commit();
    frames.report();

    const SimulationSettings& s = config.part.simulation;
    fmt::print("{}: {} masses, {} springs, mode {}, {} steps of {} s ({}, restore {}), {:.0f} steps/s{}\n", model.name,
               model.massCount(), model.springCount(), toString(config.part.mode), result.steps, s.timeStep,
               toString(s.integrator), toString(s.restoration.method), double(result.steps) / std::max(result.wallSeconds, 1e-9),
               model.renumbered() ? " (masses renumbered for locality; indices and frames in the file's order)"
               : model.file       ? " (indices and frames in the file's vertex order)"
                                  : "");
    fmt::print("active region: at most {} moving masses and {} computed springs; {} spring evaluations in all\n",
               result.maxMovingMasses, result.maxComputedSprings, result.counters.springsEvaluated);
    if (s.integrator == Integrator::ImplicitEuler)
        fmt::print("implicit solve: {:.1f} conjugate-gradient iterations a step, largest relative residual {:.2e}\n",
                   double(result.counters.solverIterations) / double(std::max<std::size_t>(result.steps, 1)),
                   result.counters.solverResidual);
    for (const ActivityTracker& t : result.trackers) {
        const auto restored = t.restorationTime();
        fmt::print("threshold {}: max active {}, total distinct {}, restoration time {}\n", t.threshold(), t.maxActive(),
                   t.totalDistinct(), restored ? fmt::format("{:.3f} s", *restored) : std::string("not restored"));
    }
    fmt::print("state hash {:016x}\n", stateHash(result.state));
}

}  // namespace

void registerSimulate(CLI::App& app) {
    auto* cmd = app.add_subcommand("simulate", "Simulate a full-deformable part under point loads");
    auto opt = std::make_shared<SimulateOptions>();
    cmd->add_option("file", opt->file, "Mesh file")->required();
    addMeshOptions(cmd, opt->mesh);
    cmd->footer("In --mode rigid-deformable, a force on a mass no zone covers opens a zone there at --level; zones retire once\n"
                "their springs are inactive at the first --threshold and their masses at rest.");
    opt->sim.addTo(*cmd);
    cmd->add_option("--force", opt->forces, "Point load MASS:FX,FY,FZ (repeatable)");
    cmd->add_option("--kick", opt->kicks,
                    "Velocity change MASS:VX,VY,VZ (m/s) of one mass at the start, the thesis's perturbation (repeatable)");
    cmd->add_option("--force-duration", opt->forceDuration, "Seconds the loads act before release")->check(nonNegativeNumber)->capture_default_str();
    cmd->add_option("--duration", opt->duration, "Simulated seconds")->check(positiveNumber)->capture_default_str();
    cmd->add_option("--threshold", opt->thresholds, "Activity thresholds (length units)")->capture_default_str();
    cmd->add_option("--mode", opt->mode, "rigid (never deforms), rigid-deformable (zones), full-deformable (whole-mesh MSD)")
        ->check(CLI::IsMember(enumChoices<PartMode>()))->capture_default_str();
    cmd->add_option("--zone", opt->zones, "Zone MASS@LEVEL or face:F@LEVEL opened at the start (repeatable, --mode rigid-deformable)");
    cmd->add_option("--level", opt->defaultLevel, "Level of zones opened by forces (--mode rigid-deformable)")
        ->check(CLI::Range(1, 255))->capture_default_str();
    cmd->add_option("--vertex-order", opt->vertexOrder,
                    "locality: renumber the masses for memory locality when that speeds the step (MASS arguments and frames "
                    "stay in the file's vertex order); as_given: keep the file's order")
        ->check(CLI::IsMember({"locality", "as_given"}))->capture_default_str();
    cmd->add_flag("--until-restored", opt->untilRestored, "Stop once every threshold has restored after the release");
    cmd->add_option("--csv", opt->csv, "Per-step metrics CSV");
    cmd->add_option("--every", opt->every, "Write every N-th step to the CSV")->check(positiveNumber)->capture_default_str();
    cmd->add_option("--obj-at", opt->objTimes, "Times (s) at which to write the deformed mesh as OBJ")->delimiter(',')->check(nonNegativeNumber);
    cmd->add_option("--obj-prefix", opt->objPrefix, "Path prefix of the OBJ frames")->capture_default_str();
    cmd->callback([opt] { run(*opt); });
}

}  // namespace flexfit::cli
