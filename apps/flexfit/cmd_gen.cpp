// flexfit gen torus|sphere|heart|torus1|torus2|container-mouth -o FILE
#include "cli_common.hpp"
#include "commands.hpp"

#include <fmt/core.h>

namespace flexfit::cli {
namespace {

void save(TriMesh mesh, const std::string& out, const std::string& name) {
    if (!name.empty()) mesh.name = name;
    const MeshDiagnostics d = validateMesh(mesh, "generated " + mesh.name);
    writeMesh(mesh, out);
    fmt::print("{}: {} vertices, {} faces, {} springs -> {}\n", mesh.name, mesh.vertices.size(), mesh.faces.size(), d.edgeCount, out);
}

CLI::App* addShape(CLI::App& gen, const std::string& shape, const std::string& help, std::string& out, std::string& name) {
    auto* cmd = gen.add_subcommand(shape, help);
    cmd->add_option("-o,--output", out, "Output mesh (.tri or .obj)")->required();
    cmd->add_option("--name", name, "Model name written in the file");
    return cmd;
}

}  // namespace

void registerGen(CLI::App& app) {
    auto* gen = app.add_subcommand("gen", "Generate the thesis's test shapes");
    gen->require_subcommand(1);
    struct Options {
        std::string out, name;
        double major = 10.0, minor = 2.5, radius = 10.0, size = 20.0;
        int u = 24, v = 24, segments = 32, rings = 16, ico = -1, heartSegments = 93, heartRings = 80;
    };
    auto opt = std::make_shared<Options>();

    auto* torus = addShape(*gen, "torus", "Torus around the y axis", opt->out, opt->name);
    torus->add_option("--major", opt->major, "Major radius (centre to tube centre)")->capture_default_str();
    torus->add_option("--minor", opt->minor, "Minor radius (tube)")->capture_default_str();
    torus->add_option("--u", opt->u, "Segments around the axis")->capture_default_str();
    torus->add_option("--v", opt->v, "Segments around the tube")->capture_default_str();
    torus->callback([opt] { save(makeTorus(opt->major, opt->minor, opt->u, opt->v), opt->out, opt->name); });

    auto* sphere = addShape(*gen, "sphere", "UV sphere, or icosphere with --ico N", opt->out, opt->name);
    sphere->add_option("--radius", opt->radius, "Radius")->capture_default_str();
    sphere->add_option("--segments", opt->segments, "Segments around the y axis")->capture_default_str();
    sphere->add_option("--rings", opt->rings, "Rings pole to pole")->capture_default_str();
    sphere->add_option("--ico", opt->ico, "Icosphere subdivisions (0-8) instead of a UV sphere");
    sphere->callback([opt] {
        save(opt->ico >= 0 ? makeIcoSphere(opt->radius, opt->ico) : makeUvSphere(opt->radius, opt->segments, opt->rings),
             opt->out, opt->name);
    });

    auto* heart = addShape(*gen, "heart", "Closed organic heart-like surface (7,349 vertices by default)", opt->out, opt->name);
    heart->add_option("--size", opt->size, "Height")->capture_default_str();
    heart->add_option("--segments", opt->heartSegments, "Segments around the vertical axis")->capture_default_str();
    heart->add_option("--rings", opt->heartRings, "Rings top to bottom")->capture_default_str();
    heart->callback([opt] { save(makeHeart(opt->size, opt->heartSegments, opt->heartRings), opt->out, opt->name); });

    addShape(*gen, "torus1", "Thesis Torus 1: 576 masses, 1,728 springs", opt->out, opt->name)
        ->callback([opt] { save(makeTorus1(), opt->out, opt->name); });
    addShape(*gen, "torus2", "Thesis Torus 2: 1,566 masses", opt->out, opt->name)
        ->callback([opt] { save(makeTorus2(), opt->out, opt->name); });
    addShape(*gen, "container-mouth", "Container mouth torus: outer diameter 25, inner 15", opt->out, opt->name)
        ->callback([opt] { save(makeContainerMouth(), opt->out, opt->name); });
}

}  // namespace flexfit::cli
