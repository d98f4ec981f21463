// flexfit convert IN OUT: any readable mesh to .tri or .obj.
#include "cli_common.hpp"
#include "commands.hpp"

#include <fmt/core.h>

namespace flexfit::cli {

void registerConvert(CLI::App& app) {
    auto* cmd = app.add_subcommand("convert", "Convert a mesh to .tri or .obj (validated and repaired, vertices welded)");
    struct Options {
        std::string in, out, name;
        MeshOptions mesh;
    };
    auto opt = std::make_shared<Options>();
    cmd->add_option("input", opt->in, "Input mesh")->required();
    cmd->add_option("output", opt->out, "Output mesh (.tri or .obj)")->required();
    addMeshOptions(cmd, opt->mesh);
    cmd->add_option("--name", opt->name, "Model name to write (default: the input's)");
    cmd->callback([opt] {
        MeshReadResult read = loadMesh(opt->in, opt->mesh.read());
        if (!opt->name.empty()) read.mesh.name = opt->name;
        writeMesh(read.mesh, opt->out);
        fmt::print("{} -> {}: {} vertices, {} faces, {} springs", opt->in, opt->out, read.mesh.vertices.size(),
                   read.mesh.faces.size(), read.diagnostics.edgeCount);
        if (read.weldedVertices > 0) fmt::print(" ({} vertices welded)", read.weldedVertices);
        if (read.repairs.any()) fmt::print(" (repaired: see the warnings)");
        fmt::print("\n");
    });
}

}  // namespace flexfit::cli
