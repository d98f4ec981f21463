// flexfit info FILE: what a mesh holds and what model it gives.
#include "cli_common.hpp"
#include "commands.hpp"

#include <fmt/core.h>

#include <numeric>

namespace flexfit::cli {
namespace {

struct MeshInfo {
    std::size_t vertices = 0, faces = 0, springs = 0, boundary = 0, nonManifold = 0, components = 0;
    Eigen::AlignedBox3d box;
    bool closed = false;
    long euler = 0;
    double genus = 0.0;  // meaningful for closed orientable meshes only
};

std::size_t countComponents(const TriMesh& mesh) {
    std::vector<Index> parent(mesh.vertices.size());
    std::iota(parent.begin(), parent.end(), Index(0));
    auto find = [&](Index v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    for (const Face& f : mesh.faces) {
        parent[find(f[1])] = find(f[0]);
        parent[find(f[2])] = find(f[0]);
    }
    std::size_t components = 0;
    for (Index v = 0; v < parent.size(); ++v) components += find(v) == v ? 1 : 0;
    return components;
}

MeshInfo describe(const MeshReadResult& read) {
    MeshInfo info;
    info.vertices = read.mesh.vertices.size();
    info.faces = read.mesh.faces.size();
    info.springs = read.diagnostics.edgeCount;
    info.boundary = read.diagnostics.boundaryEdges;
    info.nonManifold = read.diagnostics.nonManifoldEdges;
    info.closed = read.diagnostics.closed();
    info.box = boundingBox(read.mesh);
    info.components = countComponents(read.mesh);
    info.euler = long(info.vertices) - long(info.springs) + long(info.faces);
    info.genus = (2.0 * double(info.components) - double(info.euler)) / 2.0;
    return info;
}

void printText(const std::string& file, const std::string& name, const MeshInfo& i) {
    fmt::print("file              {}\nname              {}\n", file, name);
    fmt::print("vertices (masses) {}\nfaces             {}\nsprings (edges)   {}\n", i.vertices, i.faces, i.springs);
    fmt::print("boundary edges    {}\nnon-manifold      {}\ncomponents        {}\n", i.boundary, i.nonManifold, i.components);
    fmt::print("bounding box      [{:.6g}, {:.6g}, {:.6g}] - [{:.6g}, {:.6g}, {:.6g}]\n", i.box.min().x(), i.box.min().y(),
               i.box.min().z(), i.box.max().x(), i.box.max().y(), i.box.max().z());
    fmt::print("size              {:.6g} x {:.6g} x {:.6g}\n", i.box.sizes().x(), i.box.sizes().y(), i.box.sizes().z());
    if (i.closed)
        fmt::print("closed            yes\nEuler char.       {}\ngenus             {}\n", i.euler, i.genus);
    else
        fmt::print("closed            no (Euler characteristic and genus need a closed mesh)\n");
}

std::string jsonString(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        if (static_cast<unsigned char>(c) < 0x20) { out += fmt::format("\\u{:04x}", int(c)); continue; }
        out += c;
    }
    return out + "\"";
}

void printJson(const std::string& file, const std::string& name, const MeshInfo& i, const std::vector<std::string>& warnings) {
    std::string w;
    for (std::size_t k = 0; k < warnings.size(); ++k) w += (k ? ", " : "") + jsonString(warnings[k]);
    fmt::print("{{\"file\": {}, \"name\": {}, \"vertices\": {}, \"faces\": {}, \"springs\": {}, \"boundary_edges\": {}, "
               "\"non_manifold_edges\": {}, \"components\": {}, \"closed\": {}, ",
               jsonString(file), jsonString(name), i.vertices, i.faces, i.springs, i.boundary, i.nonManifold, i.components,
               i.closed ? "true" : "false");
    fmt::print("\"bbox_min\": [{:.17g}, {:.17g}, {:.17g}], \"bbox_max\": [{:.17g}, {:.17g}, {:.17g}], ", i.box.min().x(),
               i.box.min().y(), i.box.min().z(), i.box.max().x(), i.box.max().y(), i.box.max().z());
    if (i.closed)
        fmt::print("\"euler_characteristic\": {}, \"genus\": {}, ", i.euler, i.genus);
    else
        fmt::print("\"euler_characteristic\": null, \"genus\": null, ");
    fmt::print("\"warnings\": [{}]}}\n", w);
}

}  // namespace

void registerInfo(CLI::App& app) {
    auto* cmd = app.add_subcommand("info", "Vertices, faces, springs, boundary/non-manifold edges, bounds, genus");
    struct Options {
        std::string file;
        bool json = false;
        MeshOptions mesh;
    };
    auto opt = std::make_shared<Options>();
    cmd->add_option("file", opt->file, "Mesh file (.tri, .obj, .stl, .ply, .off, .gltf, .glb)")->required();
    cmd->add_flag("--json", opt->json, "Print one JSON object");
    addMeshOptions(cmd, opt->mesh);
    cmd->callback([opt] {
        const MeshReadResult read = loadMesh(opt->file, opt->mesh.read());
        const MeshInfo info = describe(read);
        if (opt->json)
            printJson(opt->file, read.mesh.name, info, read.diagnostics.warnings);
        else
            printText(opt->file, read.mesh.name, info);
    });
}

}  // namespace flexfit::cli
