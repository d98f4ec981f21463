// flexfit experiment restoration: thesis Table 4.2 and Fig. 4.5/4.6 on torus1, and the cost of
// the restoration methods (the thesis's Fig. 4.9).
#include "cli_common.hpp"
#include "commands.hpp"
#include "perturbation_run.hpp"
#include "progress.hpp"

#include <fmt/core.h>

#include <chrono>
#include <sstream>

namespace flexfit::cli {
namespace {

struct ExperimentOptions {
    std::string out = "out/restoration";
    double force = 1.0;         // N along +x
    double loadDuration = 1.0;  // s
    double maxDuration = 200.0; // s
    double timeStep = 1e-3;
    double globalDamping = 0.1;  // gamma, kg/s: a light "air friction" (thesis eq. 2.1)
    Index mass = 0;
    int costSteps = 20000;  // steps per round of the restoration-cost measurement
    bool plots = true;
};

struct MaterialRun {
    std::string name;
    Material material;
    PerturbationResult result;
};

// Thesis Table 4.2, in the order rigid, elastic, superelastic.
struct ThesisRow {
    double restoration;
    std::size_t max001, total001, max01, total01;
};
constexpr ThesisRow kThesis[3] = {{0.954, 64, 65, 25, 25}, {3.794, 312, 368, 109, 122}, {24.969, 952, 1360, 287, 466}};

SimulationSettings anchorSettings(const Material& m, const ExperimentOptions& opt) {
    SimulationSettings s;
    s.timeStep = opt.timeStep;
    s.globalDamping = opt.globalDamping;
    s.restoration.method = RestorationMethod::AnchorSprings;
    s.restoration.anchorStiffness = m.stiffness;
    s.restoration.anchorDamping = m.damping;
    return s;
}

// The thesis's models: one material on every spring, 1 kg masses.
PartModelSettings springsOf(const Material& material) {
    PartModelSettings settings;
    settings.material = material;
    return settings;
}

MaterialRun runMaterial(const std::string& name, const Material& material, const ExperimentOptions& opt, std::ostream& series) {
    PerturbationConfig config;
    config.model = buildPartModel(makeTorus1(), springsOf(material));
    config.part.mode = PartMode::FullDeformable;
    config.part.simulation = anchorSettings(material, opt);
    config.loads = {{opt.mass, Vec3(opt.force, 0.0, 0.0)}};
    config.loadDuration = opt.loadDuration;
    config.duration = opt.maxDuration;
    config.stopWhenRestored = true;
    const auto every = std::uint64_t(std::max(1.0, std::round(0.01 / opt.timeStep)));  // 10 ms samples
    auto observer = [&](const Part& part, const std::vector<ActivityTracker>& trackers) {
        if (part.state().stepCount % every == 0)
            series << name << "," << fmt::format("{:.3f}", part.time()) << "," << trackers[0].activeNow() << ","
                   << trackers[1].activeNow() << "\n";
    };
    ProgressBar bar("restoration " + name);
    MaterialRun run{name, material, runPerturbation(config, observer, [&](double f) { bar.update(f); })};
    return run;
}

// Steps per second of torus1 (elastic) for each restoration method, measured in one process,
// interleaved over rounds, best round kept.
std::vector<std::pair<std::string, double>> measureRestorationCost(const ExperimentOptions& opt) {
    const Material m = Material::elastic();
    const auto model = buildPartModel(makeTorus1(), springsOf(m));
    const RestorationMethod methods[3] = {RestorationMethod::None, RestorationMethod::AnchorSprings, RestorationMethod::Constraint};
    double best[3] = {0, 0, 0};
    constexpr int kRounds = 5;
    const int kSteps = opt.costSteps;
    const PointLoad load{opt.mass, Vec3(opt.force, 0, 0)};
    for (int round = 0; round < kRounds; ++round)
        for (int k = 0; k < 3; ++k) {
            SimulationSettings s = anchorSettings(m, opt);
            s.restoration.method = methods[k];
            PartState state = PartState::atRest(*model);
            const auto start = std::chrono::steady_clock::now();
            for (int step = 0; step < kSteps; ++step) stepFullModel(*model, s, std::span(&load, 1), state);
            const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            best[k] = std::max(best[k], kSteps / seconds);
        }
    std::vector<std::pair<std::string, double>> cost;
    for (int k = 0; k < 3; ++k) cost.emplace_back(toString(methods[k]), best[k]);
    return cost;
}

std::string restorationText(const ActivityTracker& t) {
    const auto r = t.restorationTime();
    return r ? fmt::format("{:.3f} s", *r) : std::string("not restored");
}

std::string summary(const ExperimentOptions& opt, const std::vector<MaterialRun>& runs,
                    const std::vector<std::pair<std::string, double>>& cost) {
    std::ostringstream md;
    md << "# Restoration experiment (thesis Table 4.2, Fig. 4.5/4.6)\n\n";
    md << fmt::format(
        "**Model.** torus1: R = 10, r = 2.5, 24 x 24 = {} masses of 1 kg, {} springs.\n\n"
        "**Perturbation.** A constant force of {} N along +x on mass {} (the outermost mass at (12.5, 0, 0)), "
        "held for {} s from rest, then released.\n\n"
        "**Dynamics.** Semi-implicit Euler, dt = {} s, no gravity, global damping gamma = {} kg/s. Restoration by anchor springs "
        "(the thesis's \"invisible model\", section 4.1.4) with k_a = k and b_a = b of each material. "
        "Active spring: | |x_i - x_j| - L | > threshold. Restoration time: from the release to the first step "
        "with no active spring. Runs end when both thresholds have restored (or after {} s).\n\n",
        runs[0].result.state.positions.size(), makeTorus1().faces.size() * 3 / 2, opt.force, opt.mass, opt.loadDuration,
        opt.timeStep, opt.globalDamping, opt.maxDuration);
    md << "| | rigid (ours) | rigid (thesis) | elastic (ours) | elastic (thesis) | superelastic (ours) | superelastic (thesis) |\n";
    md << "|---|---|---|---|---|---|---|\n";
    auto row = [&](const std::string& label, auto ours, auto thesis) {
        md << "| " << label;
        for (int k = 0; k < 3; ++k) md << " | " << ours(runs[k]) << " | " << thesis(kThesis[k]);
        md << " |\n";
    };
    row("k, b (kg/s², kg/s)", [](const MaterialRun& r) { return fmt::format("{}, {}", r.material.stiffness, r.material.damping); },
        [](const ThesisRow&) { return std::string("same"); });
    row("restoration time (0.01)", [](const MaterialRun& r) { return restorationText(r.result.trackers[0]); },
        [](const ThesisRow& t) { return fmt::format("{} s", t.restoration); });
    row("restoration time (0.1)", [](const MaterialRun& r) { return restorationText(r.result.trackers[1]); },
        [](const ThesisRow&) { return std::string("-"); });
    row("max active (0.01)", [](const MaterialRun& r) { return std::to_string(r.result.trackers[0].maxActive()); },
        [](const ThesisRow& t) { return std::to_string(t.max001); });
    row("total active (0.01)", [](const MaterialRun& r) { return std::to_string(r.result.trackers[0].totalDistinct()); },
        [](const ThesisRow& t) { return std::to_string(t.total001); });
    row("max active (0.1)", [](const MaterialRun& r) { return std::to_string(r.result.trackers[1].maxActive()); },
        [](const ThesisRow& t) { return std::to_string(t.max01); });
    row("total active (0.1)", [](const MaterialRun& r) { return std::to_string(r.result.trackers[1].totalDistinct()); },
        [](const ThesisRow& t) { return std::to_string(t.total01); });
    md << "\nThe thesis gives the restoration time once per material (its threshold is not stated for it).\n\n";
    md << "![threshold 0.01](active_springs_0.01.png)\n![threshold 0.1](active_springs_0.1.png)\n\n";
    md << "## Cost of the restoration methods (thesis Fig. 4.9)\n\n";
    md << fmt::format("torus1, elastic, loaded, full MSD step; best of 5 interleaved rounds of {} steps, one process.\n\n",
                      opt.costSteps);
    md << "| restoration | steps/s | relative to none |\n|---|---|---|\n";
    for (const auto& [name, rate] : cost) md << fmt::format("| {} | {:.0f} | {:.2f} |\n", name, rate, rate / cost[0].second);
    return md.str();
}

void run(const ExperimentOptions& opt) {
    makeDirectory(opt.out);
    const std::filesystem::path dir(opt.out);
    std::ostringstream series;
    series << "material,time,active_0.01,active_0.1\n";
    std::vector<MaterialRun> runs;
    runs.push_back(runMaterial("rigid", Material::rigid(), opt, series));
    runs.push_back(runMaterial("elastic", Material::elastic(), opt, series));
    runs.push_back(runMaterial("superelastic", Material::superelastic(), opt, series));
    writeTextFile(dir / "active_springs.csv", series.str());

    std::ostringstream table;
    table << "material,stiffness,damping,threshold,restoration_time_s,max_active,total_active,steps\n";
    for (const MaterialRun& r : runs)
        for (const ActivityTracker& t : r.result.trackers) {
            const auto rt = t.restorationTime();
            table << fmt::format("{},{},{},{},{},{},{},{}\n", r.name, r.material.stiffness, r.material.damping, t.threshold(),
                                 rt ? fmt::format("{:.3f}", *rt) : "", t.maxActive(), t.totalDistinct(), r.result.steps);
        }
    writeTextFile(dir / "table_4_2.csv", table.str());

    const auto cost = measureRestorationCost(opt);
    std::ostringstream costCsv;
    costCsv << "restoration,steps_per_second\n";
    for (const auto& [name, rate] : cost) costCsv << fmt::format("{},{:.1f}\n", name, rate);
    writeTextFile(dir / "restoration_cost.csv", costCsv.str());

    const std::string md = summary(opt, runs, cost);
    writeTextFile(dir / "summary.md", md);
    if (opt.plots) runPlotScript("plot_restoration.py", {(dir / "active_springs.csv").string(), dir.string()});
    fmt::print("{}", md);
}

}  // namespace

void registerExperimentRestoration(CLI::App& experiment) {
    auto* cmd = experiment.add_subcommand("restoration", "Thesis Table 4.2 and Fig. 4.5/4.6: restoration of torus1");
    auto opt = std::make_shared<ExperimentOptions>();
    cmd->add_option("--out", opt->out, "Output directory")->capture_default_str();
    cmd->add_option("--force", opt->force, "Force along +x (N)")->check(CLI::PositiveNumber)->capture_default_str();
    cmd->add_option("--load-duration", opt->loadDuration, "Seconds the force acts")->check(CLI::PositiveNumber)->capture_default_str();
    cmd->add_option("--max-duration", opt->maxDuration, "Simulated seconds at most per material")->check(CLI::PositiveNumber)
        ->capture_default_str();
    cmd->add_option("--dt", opt->timeStep, "Time step (s)")->check(CLI::PositiveNumber)->capture_default_str();
    cmd->add_option("--global-damping", opt->globalDamping, "Global damping gamma (kg/s)")->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    cmd->add_option("--mass", opt->mass, "Loaded mass")->check(CLI::Range(0, 575))->capture_default_str();
    cmd->add_option("--cost-steps", opt->costSteps, "Steps per round when timing the restoration methods")
        ->check(CLI::PositiveNumber)->capture_default_str();
    cmd->add_flag("!--no-plots", opt->plots, "Skip the PNG plots");
    cmd->callback([opt] { run(*opt); });
}

}  // namespace flexfit::cli
