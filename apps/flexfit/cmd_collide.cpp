// flexfit collide A B: the contacts between two meshes in given poses, and the query's cost.
#include "cli_common.hpp"
#include "commands.hpp"

#include <cmath>
#include <fmt/core.h>

#include <chrono>

namespace flexfit::cli {
namespace {

struct CollideOptions {
    std::string a, b;
    std::string translateA = "0,0,0", translateB = "0,0,0", rotateA, rotateB;
    std::string bv = "aabb", test = "triangle";
    bool json = false;
    int maxPrint = 20;
    MeshOptions mesh;
};

// "x,y,z" translation and optional "ax,ay,az,degrees" rotation (about the origin, then moved).
Pose parsePose(const std::string& translation, const std::string& rotation, const std::string& option) {
    Pose pose;
    pose.translation = parseVec3(translation, "--pose-" + option);
    if (!rotation.empty()) {
        const std::size_t last = rotation.rfind(',');
        if (last == std::string::npos) throw InputError("option --rotate-" + option, 0, "'" + rotation + "' is not ax,ay,az,degrees");
        const Vec3 axis = parseVec3(rotation.substr(0, last), "--rotate-" + option);
        const Vec3 angle = parseVec3(rotation.substr(last + 1) + ",0,0", "--rotate-" + option);
        if (!(axis.norm() > 0) || !std::isfinite(axis.norm()))
            throw InputError("option --rotate-" + option, 0, "the rotation axis must be non-zero (and its length finite)");
        // In one turn first: 1e308 degrees times pi overflowed to a NaN pose (NaN contacts).
        pose.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(std::fmod(angle.x(), 360.0) * M_PI / 180.0, axis.normalized()));
    }
    return pose;
}

void run(const CollideOptions& opt) {
    const BoundingVolumeKind kind = enumOption<BoundingVolumeKind>(opt.bv, "option --bv");
    const ExactTest test = enumOption<ExactTest>(opt.test, "option --test");
    PartSettings rigid;
    rigid.mode = PartMode::Rigid;
    Part a(buildPartModel(loadMesh(opt.a, opt.mesh.read()).mesh), rigid), b(buildPartModel(loadMesh(opt.b, opt.mesh.read()).mesh), rigid);
    a.setPose(parsePose(opt.translateA, opt.rotateA, "a"));
    b.setPose(parsePose(opt.translateB, opt.rotateB, "b"));
    const auto buildStart = std::chrono::steady_clock::now();
    const PartCollider ca(a, kind, test), cb(b, kind, test);
    const double buildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - buildStart).count();
    std::vector<Contact> contacts;
    QueryStats stats;
    const auto start = std::chrono::steady_clock::now();
    queryPair(0, a, ca, 1, b, cb, test, contacts, stats);
    const double queryMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    double deepest = 0.0;
    for (const Contact& c : contacts) deepest = std::max(deepest, c.depth);
    if (opt.json) {
        fmt::print("{{\"bv\": \"{}\", \"test\": \"{}\", \"build_ms\": {:.3f}, \"query_ms\": {:.3f}, \"volume_tests\": {}, "
                   "\"candidate_pairs\": {}, \"exact_tests\": {}, \"contact_count\": {}, \"contacts\": [",
                   toString(kind), toString(test), buildMs, queryMs, stats.volumeTests, stats.candidatePairs, stats.exactTests,
                   contacts.size());
        for (std::size_t i = 0; i < contacts.size(); ++i) {
            const Contact& c = contacts[i];
            fmt::print("{}{{\"face_a\": {}, \"face_b\": {}, \"point\": [{:.9g}, {:.9g}, {:.9g}], \"normal\": [{:.9g}, {:.9g}, {:.9g}], "
                       "\"depth\": {:.9g}}}",
                       i ? ", " : "", c.faceA, c.faceB, c.point.x(), c.point.y(), c.point.z(), c.normal.x(), c.normal.y(),
                       c.normal.z(), c.depth);
        }
        fmt::print("]}}\n");
        return;
    }
    fmt::print("{} ({} faces) x {} ({} faces), {} hierarchies, {} test\n", opt.a, a.model().faceCount(), opt.b,
               b.model().faceCount(), toString(kind), toString(test));
    fmt::print("build {:.3f} ms; query {:.3f} ms: {} volume tests, {} candidate face pairs, {} exact tests\n", buildMs, queryMs,
               stats.volumeTests, stats.candidatePairs, stats.exactTests);
    fmt::print("{} contacts{}\n", contacts.size(), contacts.empty() ? "" : fmt::format(", deepest {:.6g}", deepest));
    for (std::size_t i = 0; i < contacts.size() && int(i) < opt.maxPrint; ++i) {
        const Contact& c = contacts[i];
        fmt::print("  face {} x face {}: point ({:.6g}, {:.6g}, {:.6g}) normal ({:.4f}, {:.4f}, {:.4f}) depth {:.6g}\n", c.faceA,
                   c.faceB, c.point.x(), c.point.y(), c.point.z(), c.normal.x(), c.normal.y(), c.normal.z(), c.depth);
    }
    if (int(contacts.size()) > opt.maxPrint) fmt::print("  ... ({} more; --max or --json for all)\n", contacts.size() - std::size_t(opt.maxPrint));
}

}  // namespace

void registerCollide(CLI::App& app) {
    auto* cmd = app.add_subcommand("collide", "Contacts between two meshes in given poses, with the query's statistics");
    auto opt = std::make_shared<CollideOptions>();
    cmd->add_option("a", opt->a, "First mesh (the pressing part: its faces are spheres with --test sphere)")->required();
    cmd->add_option("b", opt->b, "Second mesh")->required();
    addMeshOptions(cmd, opt->mesh);
    cmd->add_option("--pose-a", opt->translateA, "Translation x,y,z of A")->capture_default_str();
    cmd->add_option("--rotate-a", opt->rotateA, "Rotation of A: axis and degrees ax,ay,az,deg");
    cmd->add_option("--pose-b", opt->translateB, "Translation x,y,z of B")->capture_default_str();
    cmd->add_option("--rotate-b", opt->rotateB, "Rotation of B: axis and degrees ax,ay,az,deg");
    cmd->add_option("--bv", opt->bv, "Bounding volume of the face hierarchies")->check(CLI::IsMember(enumChoices<BoundingVolumeKind>()))
        ->capture_default_str();
    cmd->add_option("--test", opt->test, "Exact test: triangle (triangle-triangle) or sphere (thesis: sphere-triangle)")
        ->check(CLI::IsMember(enumChoices<ExactTest>()))->capture_default_str();
    cmd->add_flag("--json", opt->json, "Print one JSON object with every contact");
    cmd->add_option("--max", opt->maxPrint, "Contacts listed in the text output")->check(nonNegativeNumber)->capture_default_str();
    cmd->callback([opt] { run(*opt); });
}

}  // namespace flexfit::cli
