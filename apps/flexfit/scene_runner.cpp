#include "scene_runner.hpp"

#include "cli_common.hpp"
#include "progress.hpp"

#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <regex>
#include <set>
#include <span>

namespace flexfit::cli {
namespace {

using Clock = std::chrono::steady_clock;

std::size_t zoneCount(const World& w) {
    std::size_t n = 0;
    for (BodyId id = 0; id < w.bodyCount(); ++id) n += w.part(id).zoneCount();
    return n;
}

std::size_t movingMasses(const World& w) {
    std::size_t n = 0;
    for (BodyId id = 0; id < w.bodyCount(); ++id) n += w.part(id).movingMasses().size();
    return n;
}

std::size_t computedSprings(const World& w) {
    std::size_t n = 0;
    for (BodyId id = 0; id < w.bodyCount(); ++id) n += w.part(id).computedSprings().size();
    return n;
}

// Largest distance of a moving mass from its rest position (part frame = length in the world).
double deformation(const Part& part) {
    double d = 0.0;
    for (Index m : part.movingMasses()) d = std::max(d, (part.state().positions[m] - part.model().restPositions[m]).norm());
    return d;
}

// metrics.csv: one row per step (time at its end); counts over the world, the operator's
// coupling, per-stage microseconds; then per part, in scene order: its centre of mass
// (<part>_x, _y, _z; moving parts), the force deformable parts pressed on it in the step
// (<part>_contact_fx, _fy, _fz, world frame, RigidBody::deformableContactForce; dynamic parts)
// and its largest deformation (<part>_deformation; parts that deform), given in `deformations`
// by body.
std::string csvHeader(const Scene& scene) {
    std::string h = "time,contacts,zones,moving_masses,computed_springs,coupling_fx,coupling_fy,coupling_fz,coupling_tx,coupling_ty,coupling_tz";
    for (std::size_t s = 0; s < kStageCount; ++s) h += std::string(",us_") + toString(Stage(s));
    h += ",us_world_step";
    for (const ScenePart& p : scene.parts) {
        if (p.body.motion != MotionType::Static) h += "," + p.name + "_x," + p.name + "_y," + p.name + "_z";
        if (p.body.motion == MotionType::Dynamic) h += "," + p.name + "_contact_fx," + p.name + "_contact_fy," + p.name + "_contact_fz";
        if (p.part.mode != PartMode::Rigid) h += "," + p.name + "_deformation";
    }
    return h + "\n";
}

std::string csvRow(const Scene& scene, const World& w, std::span<const double> deformations) {
    const Coupling& c = w.coupling();
    std::string row = fmt::format("{:.6f},{},{},{},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}", w.time(), w.contacts().size(), zoneCount(w),
                                  movingMasses(w), computedSprings(w), c.force.x(), c.force.y(), c.force.z(), c.torque.x(),
                                  c.torque.y(), c.torque.z());
    for (double s : w.profile().lastSeconds) row += fmt::format(",{:.3f}", s * 1e6);
    row += fmt::format(",{:.3f}", w.profile().lastStepSeconds * 1e6);
    for (BodyId id = 0; id < scene.parts.size(); ++id) {
        if (scene.parts[id].body.motion != MotionType::Static) {
            const Vec3 p = w.centreOfMass(id);
            row += fmt::format(",{:.9g},{:.9g},{:.9g}", p.x(), p.y(), p.z());
        }
        if (scene.parts[id].body.motion == MotionType::Dynamic) {
            const Vec3& f = w.body(id).deformableContactForce;
            row += fmt::format(",{:.9g},{:.9g},{:.9g}", f.x(), f.y(), f.z());
        }
        if (scene.parts[id].part.mode != PartMode::Rigid) row += fmt::format(",{:.9g}", deformations[id]);
    }
    return row + "\n";
}

void writeObjFrame(const std::filesystem::path& path, const World& w, const Scene& scene) {
    std::vector<NamedPart> parts;
    for (BodyId id = 0; id < w.bodyCount(); ++id) parts.push_back({scene.parts[id].name, &w.part(id)});
    writePartsObj(path, fmt::format("flexfit run {} t={:.6f}", scene.source, w.time()), parts);
}

std::string poseJson(const Pose& p) {
    const auto& q = p.rotation;
    return fmt::format("{{\"position\": [{:.9g}, {:.9g}, {:.9g}], \"rotation_wxyz\": [{:.9g}, {:.9g}, {:.9g}, {:.9g}]}}", p.translation.x(),
                       p.translation.y(), p.translation.z(), q.w(), q.x(), q.y(), q.z());
}

std::string jsonString(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        if (static_cast<unsigned char>(c) < 0x20) {
            out += fmt::format("\\u{:04x}", int(c));
            continue;
        }
        out += c;
    }
    return out + "\"";
}

std::string optionalJson(const std::optional<double>& v) { return v ? fmt::format("{:.6f}", *v) : "null"; }

// A run into a directory an earlier run wrote replaces that run's frames: frame_NNNNNN.obj,
// .vtp, .glb and frames.pvd that this run did not write are removed once it has finished (they
// would otherwise sit beside the new ones, and ParaView or a script would read them as this
// run's). Nothing else in the directory is touched.
void removeEarlierFrames(const std::filesystem::path& out, const std::set<std::string>& written) {
    static const std::regex frame(R"(frame_[0-9]{6}\.(obj|vtp|glb)|frames\.pvd)");
    std::error_code ec;
    std::vector<std::filesystem::path> earlier;
    for (const auto& entry : std::filesystem::directory_iterator(out, ec)) {
        const std::string name = entry.path().filename().string();
        if (entry.is_regular_file(ec) && std::regex_match(name, frame) && !written.contains(name)) earlier.push_back(entry.path());
    }
    for (const auto& path : earlier) std::filesystem::remove(path, ec);  // best effort: the run itself is done
}

}  // namespace

RunSummary runScene(const Scene& scene, const RunOptions& options) {
    const double duration = options.duration.value_or(scene.duration);
    if (options.duration && !(std::isfinite(*options.duration) && *options.duration > 0.0))
        throw InputError("option --duration", 0, "must be finite and > 0");
    if (const std::optional<std::string> problem = stepCountProblem(duration, scene.world.timeStep))
        throw InputError(options.duration ? "option --duration" : scene.source, 0, *problem);
    SceneRun run(scene);
    World& w = run.world();
    const auto steps = std::uint64_t(std::llround(duration / scene.world.timeStep));
    // Everything is written under temporary names and moved into place at the end: a run that
    // fails (a divergence, World::step) leaves no half-written CSV, frames or summary.
    PendingFiles files;
    std::ofstream csv;
    const std::filesystem::path csvPath = options.out / "metrics.csv";
    if (!options.out.empty()) {
        files.makeDirectory(options.out);
        csv.open(files.add(csvPath));
        if (!csv) throw InputError(csvPath.string(), 0, "cannot write");
        csv << csvHeader(scene);
    }
    RunSummary s;
    for (const auto& [every, what] : {std::pair{options.objEvery, "OBJ"}, std::pair{options.vtkEvery, "VTK"}, std::pair{options.glbEvery, "glTF"}})
        if (every && !(*every >= 0.0 && std::isfinite(*every)))
            throw InputError(scene.source, 0, std::string("seconds between ") + what + " frames must be finite and >= 0");
    auto strideOf = [&](double every) { return every > 0.0 ? std::max<std::uint64_t>(1, std::llround(every / scene.world.timeStep)) : 0; };
    const std::uint64_t objStride = strideOf(options.objEvery.value_or(scene.objEvery)), vtkStride = strideOf(options.vtkEvery.value_or(scene.vtkEvery)),
                        glbStride = strideOf(options.glbEvery.value_or(scene.glbEvery));
    std::vector<FramePart> frameParts;
    for (BodyId id = 0; id < w.bodyCount(); ++id) frameParts.push_back({scene.parts[id].name, &w.part(id)});
    std::vector<std::pair<double, std::string>> vtkFrames;
    std::set<std::string> frameNames;  // this run's frames, and frames.pvd
    std::vector<double> deformations(w.bodyCount(), 0.0);  // by body, this step's
    ProgressBar bar("run " + std::filesystem::path(scene.source).filename().string(), options.progress);
    const auto start = Clock::now();
    for (std::uint64_t i = 0; i < steps; ++i) {
        const auto before = Clock::now();
        run.step();
        const double wall = std::chrono::duration<double>(Clock::now() - before).count();
        const std::size_t contacts = w.contacts().size();
        if (const double micros = w.profile().lastStepSeconds * 1e6; micros > s.maxStepMicros) {
            s.maxStepMicros = micros;
            s.maxStepTime = w.time();
        }
        if (contacts > 0) {
            ++s.contactSteps;
            s.contactWallSeconds += wall;
            s.contactStepMicros.push_back(w.profile().lastStepSeconds * 1e6);
            s.lastContact = w.time();
            s.restored.reset();
        }
        const std::size_t moving = movingMasses(w);
        if (s.lastContact && !s.restored && moving == 0) s.restored = w.time();
        s.maxContacts = std::max(s.maxContacts, contacts);
        s.maxMovingMasses = std::max(s.maxMovingMasses, moving);
        s.maxComputedSprings = std::max(s.maxComputedSprings, computedSprings(w));
        s.maxZones = std::max(s.maxZones, zoneCount(w));
        for (BodyId id = 0; id < w.bodyCount(); ++id) {  // once a step: O(moving masses) each
            deformations[id] = deformation(w.part(id));
            s.maxDeformation = std::max(s.maxDeformation, deformations[id]);
        }
        if (w.coupling().active) s.maxCouplingForce = std::max(s.maxCouplingForce, w.coupling().force.norm());
        if (csv.is_open() && (i + 1) % std::uint64_t(std::max(1, options.csvEvery)) == 0) csv << csvRow(scene, w, deformations);
        if (objStride && !options.out.empty() && (i + 1) % objStride == 0)
            writeObjFrame(files.add(options.out / *frameNames.insert(fmt::format("frame_{:06d}.obj", i + 1)).first), w, scene);
        if (vtkStride && !options.out.empty() && (i + 1) % vtkStride == 0) {
            vtkFrames.emplace_back(w.time(), *frameNames.insert(fmt::format("frame_{:06d}.vtp", i + 1)).first);
            writeVtkFrame(files.add(options.out / vtkFrames.back().second), frameParts);
        }
        if (glbStride && !options.out.empty() && (i + 1) % glbStride == 0)
            writeGlbFrame(files.add(options.out / *frameNames.insert(fmt::format("frame_{:06d}.glb", i + 1)).first), frameParts);
        bar.update(double(i + 1) / double(steps));
    }
    bar.finish();
    s.wallSeconds = std::chrono::duration<double>(Clock::now() - start).count();
    s.steps = steps;
    s.simulatedSeconds = w.time();
    s.profile = w.profile();
    s.events = w.assemblyEvents();
    s.stateHash = w.stateHash();
    for (BodyId id = 0; id < w.bodyCount(); ++id) s.finalCentres.push_back(w.centreOfMass(id));
    if (!options.out.empty()) {
        writeWholeFile(files.add(options.out / "summary.json"), summaryJson(scene, s));
        if (!vtkFrames.empty()) writeVtkCollection(files.add(options.out / *frameNames.insert("frames.pvd").first), vtkFrames);
        csv.close();
        if (!csv) throw InputError(csvPath.string(), 0, "write failed");
        files.commit();
        removeEarlierFrames(options.out, frameNames);
    }
    return s;
}

std::string summaryJson(const Scene& scene, const RunSummary& s) {
    std::string j = "{\n";
    j += fmt::format("  \"scene\": {},\n  \"steps\": {},\n  \"time_step\": {},\n  \"simulated_seconds\": {:.6f},\n", jsonString(scene.source), s.steps,
                     scene.world.timeStep, s.simulatedSeconds);
    j += fmt::format("  \"wall_seconds\": {:.6f},\n  \"steps_per_second\": {:.1f},\n", s.wallSeconds, double(s.steps) / s.wallSeconds);
    j += fmt::format("  \"contact_steps\": {},\n  \"contact_steps_per_second\": {},\n", s.contactSteps,
                     s.contactSteps ? fmt::format("{:.1f}", double(s.contactSteps) / s.contactWallSeconds) : "null");
    for (const auto& [key, p] : {std::pair{"p50", 50.0}, std::pair{"p99", 99.0}, std::pair{"max", 100.0}})
        j += fmt::format("  \"contact_step_us_{}\": {},\n", key,
                         s.contactStepMicros.empty() ? std::string("null") : fmt::format("{:.3f}", nearestRankPercentile(s.contactStepMicros, p)));
    j += fmt::format("  \"step_us_max\": {:.3f},\n  \"step_us_max_time\": {:.6f},\n", s.maxStepMicros, s.maxStepTime);
    j += fmt::format("  \"max_contacts\": {},\n  \"max_zones\": {},\n  \"max_moving_masses\": {},\n  \"max_computed_springs\": {},\n",
                     s.maxContacts, s.maxZones, s.maxMovingMasses, s.maxComputedSprings);
    j += fmt::format("  \"max_deformation\": {:.9g},\n  \"last_contact\": {},\n  \"restored_at\": {},\n  \"max_coupling_force\": {:.9g},\n",
                     s.maxDeformation, optionalJson(s.lastContact), optionalJson(s.restored), s.maxCouplingForce);
    j += fmt::format("  \"substeps\": {},\n  \"cut_moves\": {},\n  \"rigid_queries\": {},\n", s.profile.substeps, s.profile.cutMoves,
                     s.profile.rigidQueries);
    j += fmt::format("  \"face_queries\": {},\n  \"face_traversals\": {},\n", s.profile.faceQueries, s.profile.faceTraversals);
    j += fmt::format("  \"world_step_seconds\": {:.9f},\n  \"stage_seconds\": {{", s.profile.totalStepSeconds);
    for (std::size_t i = 0; i < kStageCount; ++i)
        j += fmt::format("{}{}: {:.9f}", i ? ", " : "", jsonString(toString(Stage(i))), s.profile.totalSeconds[i]);
    j += "},\n  \"assembly_events\": [";
    for (std::size_t i = 0; i < s.events.size(); ++i) {
        const AssemblyEvent& e = s.events[i];
        j += fmt::format("{}\n    {{\"rule\": {}, \"technique\": {}, \"time\": {:.6f}, \"from\": {}, \"to\": {}}}", i ? "," : "",
                         jsonString(e.rule), jsonString(toString(e.technique)), e.time, poseJson(e.primaryPoseBefore), poseJson(e.primaryPoseAfter));
    }
    j += s.events.empty() ? "],\n" : "\n  ],\n";
    j += "  \"final_centres\": {";
    for (std::size_t i = 0; i < s.finalCentres.size(); ++i)
        j += fmt::format("{}{}: [{:.9g}, {:.9g}, {:.9g}]", i ? ", " : "", jsonString(scene.parts[i].name), s.finalCentres[i].x(),
                         s.finalCentres[i].y(), s.finalCentres[i].z());
    j += fmt::format("}},\n  \"state_hash\": \"{:016x}\"\n}}\n", s.stateHash);
    return j;
}

}  // namespace flexfit::cli
