// flexfit remesh IN OUT --edge L: a simulation-quality surface (near-uniform edges, sharp
// features kept) within a reported Hausdorff distance of the input.
#include "cli_common.hpp"
#include "commands.hpp"

#include <fmt/core.h>

namespace flexfit::cli {
namespace {

void printQuality(const char* label, const MeshQuality& q) {
    fmt::print("  {:<6} {:>8} faces, min angle {:5.1f} deg, {:5.1f} % of triangles with an angle below 20 deg, "
               "edges {:.4g} / {:.4g} / {:.4g} (min / mean / max), spread {:.3f}\n",
               label, q.faces, q.minAngle, 100.0 * q.slivers, q.minEdge, q.meanEdge, q.maxEdge, q.edgeSpread);
}

void printThinFeatures(const RemeshResult& r, const std::string& source) {
    if (r.releasedEdges == 0) return;
    const double share = 100.0 * r.roundedHausdorff / r.diagonal;
    if (r.rounded)
        fmt::print("  thin features rounded: {} sharp edge pieces no longer kept, where sharp edges are closer than half the target edge\n",
                   r.releasedEdges);
    else
        warn(fmt::format("{}: thin features kept (slivers remain between sharp edges closer than half the target edge): rounding them "
                         "moved the surface {:.3f} % of the diagonal, left no fewer slivers or opened the closed surface; --thin-features round "
                         "rounds them anyway",
                         source, share));
}

}  // namespace

void registerRemesh(CLI::App& app) {
    auto* cmd = app.add_subcommand("remesh", "Remesh for simulation: near-uniform edges, sharp features kept (CGAL)");
    struct Options {
        std::string in, out, thinFeatures = "auto";
        RemeshOptions remesh;
        MeshOptions mesh;
    };
    auto opt = std::make_shared<Options>();
    cmd->add_option("input", opt->in, "Input mesh")->required();
    cmd->add_option("output", opt->out, "Output mesh (.tri or .obj)")->required();
    cmd->add_option("--edge", opt->remesh.targetEdge, "Target edge length, in the mesh's units")->required()->check(positiveNumber);
    cmd->add_option("--iterations", opt->remesh.iterations, "Remeshing rounds")->capture_default_str()->check(CLI::Range(1, 100));
    cmd->add_option("--feature-angle", opt->remesh.featureAngle, "Edges whose faces meet at more than this many degrees stay sharp")
        ->capture_default_str()
        ->check(openAngleDegrees);
    cmd->add_option("--thin-features", opt->thinFeatures,
                    "Sharp edges closer than half the target edge: keep them (slivers stay between them), round them, or auto (round "
                    "them when 1 % or more of the triangles are slivers, if that leaves fewer and the surface within the target edge of the input)")
        ->check(CLI::IsMember(enumChoices<ThinFeatures>()))
        ->capture_default_str();
    addMeshOptions(cmd, opt->mesh);
    cmd->callback([opt] {
        opt->remesh.thinFeatures = enumOption<ThinFeatures>(opt->thinFeatures, "option --thin-features");
        const MeshReadResult read = loadMesh(opt->in, opt->mesh.read());
        const RemeshResult r = remeshForSimulation(read.mesh, opt->remesh, opt->in);
        writeMesh(r.mesh, opt->out);
        fmt::print("{} -> {}: target edge {:.4g}, {} sharp or border edges kept\n", opt->in, opt->out, opt->remesh.targetEdge, r.featureEdges);
        printThinFeatures(r, opt->in);
        printQuality("input", r.before);
        printQuality("output", r.after);
        if (r.droppedFaces > 0) warn(fmt::format("{}: {} degenerate output faces dropped (where sharp polylines meet)", opt->in, r.droppedFaces));
        fmt::print("  Hausdorff distance {:.4g} ({:.3f} % of the bounding-box diagonal {:.4g})\n", r.hausdorff, 100.0 * r.hausdorffShare(),
                   r.diagonal);
        if (opt->remesh.targetEdge > kCoarseRemeshEdgeShare * r.diagonal)  // the short side is refused; the long one is legal, but rarely meant
            warn(fmt::format("{}: the target edge {:.4g} is {:.0f} % of the part's bounding-box diagonal: {} faces are left, {:.1f} % of the "
                             "diagonal from the input (a unit mistaken?)",
                             opt->in, opt->remesh.targetEdge, 100.0 * opt->remesh.targetEdge / r.diagonal, r.mesh.faces.size(),
                             100.0 * r.hausdorffShare()));
    });
}

}  // namespace flexfit::cli
