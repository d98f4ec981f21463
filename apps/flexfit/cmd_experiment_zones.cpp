// flexfit experiment zones: thesis Table 4.4, Fig. 4.17-4.18 and annex Fig. 6.1-6.4. Steps/s of
// rigid-deformable parts with 1..6 zones at levels 1..8 against the full MSD model of the same
// mesh, measured in the same process, with the size of the active region of each configuration.
#include "cli_common.hpp"
#include "commands.hpp"
#include "progress.hpp"

#include <fmt/core.h>

#include <chrono>
#include <sstream>

namespace flexfit::cli {
namespace {

struct ZonesOptions {
    std::string out = "out/zones";
    int maxZones = 6, maxLevel = 8;
    double minTime = 0.05;  // seconds of stepping per measurement
    double force = 0.05;    // N on each seed every step, keeping the zones loaded
    bool plots = true;
};

struct Measurement {
    std::string model;
    int zones = 0, level = 0;
    std::size_t movingMasses = 0, computedSprings = 0;
    double stepsPerSecond = 0.0;
};

// Thesis Table 4.4: full MSD frames per second (with rendering, 2017 CPU).
struct ThesisFps {
    const char* model;
    double fps;
};
constexpr ThesisFps kThesisFps[3] = {{"torus1", 353}, {"torus2", 185}, {"heart", 36.5}};

// Seeds spread over the surface: farthest-point sampling from mass 0 (deterministic).
std::vector<Index> spreadSeeds(const PartModel& model, int count) {
    std::vector<Index> seeds{0};
    std::vector<double> distance(model.massCount(), std::numeric_limits<double>::infinity());
    while (int(seeds.size()) < count) {
        const Vec3& last = model.restPositions[seeds.back()];
        Index farthest = 0;
        for (Index m = 0; m < model.massCount(); ++m) {
            distance[m] = std::min(distance[m], (model.restPositions[m] - last).norm());
            if (distance[m] > distance[farthest]) farthest = m;
        }
        seeds.push_back(farthest);
    }
    return seeds;
}

PartSettings experimentSettings(PartMode mode) {
    PartSettings s;
    s.mode = mode;
    s.simulation.timeStep = 1e-3;
    s.simulation.restoration.method = RestorationMethod::Constraint;
    s.simulation.restoration.constraintFraction = 1e-3;
    return s;
}

// Steps the part (loading the seeds every step) for at least minTime; returns steps/s.
double measure(Part& part, const std::vector<Index>& seeds, const ZonesOptions& opt) {
    using Clock = std::chrono::steady_clock;
    std::size_t steps = 0, batch = 16;
    const auto start = Clock::now();
    double elapsed = 0.0;
    while (elapsed < opt.minTime) {
        for (std::size_t i = 0; i < batch; ++i) {
            for (Index s : seeds) part.applyForce(s, Vec3(0, opt.force, 0));
            part.step();
        }
        steps += batch;
        batch *= 2;
        elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    }
    return double(steps) / elapsed;
}

std::vector<Measurement> runModel(const TriMesh& mesh, const ZonesOptions& opt, ProgressBar& bar, int& done, int total) {
    const auto model = buildPartModel(mesh);  // the elastic preset, 1 kg masses
    const std::vector<Index> allSeeds = spreadSeeds(*model, opt.maxZones);
    std::vector<Measurement> rows;
    Part full(model, experimentSettings(PartMode::FullDeformable));
    rows.push_back({mesh.name, 0, 0, model->massCount(), model->springCount(), measure(full, {allSeeds[0]}, opt)});
    // Zones covering every mass (one zone at the top level): the rigid-deformable worst case.
    Part whole(model, experimentSettings(PartMode::RigidDeformable));
    whole.openZone(ZoneSeed::mass(allSeeds[0]), 255);
    rows.push_back({mesh.name, -1, 255, whole.movingMasses().size(), whole.computedSprings().size(),
                    measure(whole, {allSeeds[0]}, opt)});
    for (int zones = 1; zones <= opt.maxZones; ++zones) {
        const std::vector<Index> seeds(allSeeds.begin(), allSeeds.begin() + zones);
        for (int level = 1; level <= opt.maxLevel; ++level) {
            Part part(model, experimentSettings(PartMode::RigidDeformable));
            for (Index s : seeds) part.openZone(ZoneSeed::mass(s), level);
            Measurement m{mesh.name, zones, level, part.movingMasses().size(), part.computedSprings().size(), 0.0};
            m.stepsPerSecond = measure(part, seeds, opt);
            rows.push_back(m);
            bar.update(double(++done) / total);
        }
    }
    return rows;
}

double fullRate(const std::vector<Measurement>& rows, const std::string& model) {
    for (const Measurement& m : rows)
        if (m.model == model && m.zones == 0) return m.stepsPerSecond;
    return 0.0;
}

// Lowest level at which `zones` zones move every mass of the model; 0 when none does.
int saturationLevel(const std::vector<Measurement>& rows, const std::string& model, int zones) {
    std::size_t masses = 0;
    for (const Measurement& m : rows)
        if (m.model == model && m.zones == 0) masses = m.movingMasses;
    for (const Measurement& m : rows)
        if (m.model == model && m.zones == zones && m.movingMasses == masses) return m.level;
    return 0;
}

std::string summary(const std::vector<Measurement>& rows, const ZonesOptions& opt) {
    std::ostringstream md;
    md << "# Deformation zones: rigid-deformable against full MSD (thesis Table 4.4, Fig. 4.17-4.18, 6.1-6.4)\n\n";
    md << fmt::format(
        "Each configuration opens 1-{} zones (seeds by farthest-point sampling from mass 0) at levels 1-{}, applies "
        "{} N along +y to every seed at every step (the zones stay loaded), and steps for at least {} s; the full MSD "
        "model of the same mesh is measured in the same process. Elastic preset, semi-implicit Euler, dt = 1 ms, "
        "restoration constraint c = 0.001. Steps/s without rendering; the thesis measured frames/s with rendering on a "
        "2017 CPU.\n\n",
        opt.maxZones, opt.maxLevel, opt.force, opt.minTime);
    md << "| model | masses | springs | full MSD steps/s | thesis full MSD FPS | best speed-up (config) | "
          "speed-up with the most zones at the top level | moving masses there | zones covering every mass |\n"
          "|---|---|---|---|---|---|---|---|---|\n";
    for (const ThesisFps& t : kThesisFps) {
        const double fullSps = fullRate(rows, t.model);
        const Measurement* best = nullptr;
        const Measurement* top = nullptr;
        const Measurement* whole = nullptr;
        std::size_t masses = 0, springs = 0;
        for (const Measurement& m : rows) {
            if (m.model != t.model) continue;
            if (m.zones == 0) {
                masses = m.movingMasses;
                springs = m.computedSprings;
                continue;
            }
            if (m.zones < 0) {
                whole = &m;
                continue;
            }
            if (!best || m.stepsPerSecond > best->stepsPerSecond) best = &m;
            if (m.zones == opt.maxZones && m.level == opt.maxLevel) top = &m;
        }
        if (!best || !top || !whole) continue;
        md << fmt::format("| {} | {} | {} | {:.0f} | {} | {:.0f}x ({} zone, level {}) | {:.2f}x | {} of {} | {:.2f}x |\n", t.model,
                          masses, springs, fullSps, t.fps, best->stepsPerSecond / fullSps, best->zones, best->level,
                          top->stepsPerSecond / fullSps, top->movingMasses, masses, whole->stepsPerSecond / fullSps);
    }
    md << "\nSpeed-ups are rigid-deformable steps/s over full MSD steps/s; the last column is one zone at level 255 "
          "(every mass moving), the thesis's worst case.\n";
    md << "\nThesis: up to 5x faster with one zone at level 1; about 15 % slower than full MSD when the zones cover "
          "the whole model; torus1 covered entirely from level 7 (6 zones).\n\n";
    for (const ThesisFps& t : kThesisFps) {
        const int saturation = saturationLevel(rows, t.model, opt.maxZones);
        md << fmt::format("- {}: {} zones cover every mass {}\n", t.model, opt.maxZones,
                          saturation > 0 ? fmt::format("from level {}", saturation)
                                         : fmt::format("at no level up to {}", opt.maxLevel));
    }
    md << "\nFull table: `zones.csv` (zones = 0: full MSD; zones = -1: one zone covering every mass). Plots: `steps_<model>.png`, `speedup_<model>.png`.\n\n";
    for (const ThesisFps& t : kThesisFps)
        md << fmt::format("![{0} steps/s](steps_{0}.png)\n![{0} speed-up](speedup_{0}.png)\n\n", t.model);
    return md.str();
}

void run(const ZonesOptions& opt) {
    makeDirectory(opt.out);
    const std::filesystem::path dir(opt.out);
    const int total = 3 * opt.maxZones * opt.maxLevel;
    int done = 0;
    ProgressBar bar("zones");
    std::vector<Measurement> rows;
    for (const TriMesh& mesh : {makeTorus1(), makeTorus2(), makeHeart()}) {
        const std::vector<Measurement> modelRows = runModel(mesh, opt, bar, done, total);
        rows.insert(rows.end(), modelRows.begin(), modelRows.end());
    }
    bar.finish();
    std::ostringstream csv;
    csv << "model,zones,level,moving_masses,computed_springs,steps_per_second,full_steps_per_second,speedup\n";
    for (const Measurement& m : rows) {
        const double full = fullRate(rows, m.model);
        csv << fmt::format("{},{},{},{},{},{:.1f},{:.1f},{:.4f}\n", m.model, m.zones, m.level, m.movingMasses, m.computedSprings,
                           m.stepsPerSecond, full, m.stepsPerSecond / full);
    }
    writeWholeFile(dir / "zones.csv", csv.str());
    const std::string md = summary(rows, opt);
    writeWholeFile(dir / "summary.md", md);
    if (opt.plots) runPlotScript("plot_zones.py", {(dir / "zones.csv").string(), dir.string()});
    fmt::print("{}", md);
}

}  // namespace

void registerExperimentZones(CLI::App& experiment) {
    auto* cmd = experiment.add_subcommand("zones", "Thesis Table 4.4, Fig. 4.17-4.18, 6.1-6.4: zones x levels against full MSD");
    auto opt = std::make_shared<ZonesOptions>();
    cmd->add_option("--out", opt->out, "Output directory")->capture_default_str();
    cmd->add_option("--max-zones", opt->maxZones, "Zones 1..N")->check(CLI::Range(1, 64))->capture_default_str();
    cmd->add_option("--max-level", opt->maxLevel, "Levels 1..N")->check(CLI::Range(1, 64))->capture_default_str();
    cmd->add_option("--min-time", opt->minTime, "Seconds of stepping per measurement")->check(positiveNumber)
        ->capture_default_str();
    cmd->add_option("--force", opt->force, "Force on each seed per step (N)")->check(nonNegativeNumber)->capture_default_str();
    cmd->add_flag("!--no-plots", opt->plots, "Skip the PNG plots");
    cmd->callback([opt] { run(*opt); });
}

}  // namespace flexfit::cli
