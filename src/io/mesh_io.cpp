// Format dispatch and the OBJ writer.
#include "flexfit/mesh_io.hpp"
#include "io_internal.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>

namespace flexfit {
namespace {

std::string lowerExtension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

}  // namespace

MeshReadResult readMesh(const std::filesystem::path& path, const MeshReadOptions& options) {
    if (!(options.weldTolerance >= 0.0) || !std::isfinite(options.weldTolerance))
        throw InputError(path.string(), 0, "weld tolerance must be a finite number >= 0");
    if (lowerExtension(path) != ".tri") return readWithAssimp(path, options);
    MeshReadResult result = readTri(path);
    if (options.weldTolerance > 0.0) {
        // .tri vertices are shared by construction; weld only when asked, then re-validate.
        const std::size_t before = result.mesh.vertices.size();
        result.collapsedFaces = weldVertices(result.mesh, options.weldTolerance);
        result.weldedVertices = before - result.mesh.vertices.size();
        result.diagnostics = validateMesh(result.mesh, path.string());
        if (result.collapsedFaces > 0)
            result.diagnostics.warnings.push_back(std::to_string(result.collapsedFaces) +
                                                  " faces collapsed by welding and were removed");
    }
    return result;
}

void writeObj(const TriMesh& mesh, const std::filesystem::path& path) {
    std::ofstream file(path, std::ios::binary);
    if (!file) throw InputError(path.string(), 0, "cannot open the file for writing");
    file << "# written by flexfit\n";
    if (!mesh.name.empty()) file << "o " << mesh.name << "\n";
    char buffer[128];
    for (const Vec3& v : mesh.vertices) {
        std::snprintf(buffer, sizeof buffer, "v %.17g %.17g %.17g\n", v.x(), v.y(), v.z());
        file << buffer;
    }
    for (const Face& f : mesh.faces) file << "f " << f[0] + 1 << " " << f[1] + 1 << " " << f[2] + 1 << "\n";
    if (!file) throw InputError(path.string(), 0, "write failed");
}

void writeMesh(const TriMesh& mesh, const std::filesystem::path& path) {
    const std::string ext = lowerExtension(path);
    if (ext == ".tri") return writeTri(mesh, path);
    if (ext == ".obj") return writeObj(mesh, path);
    throw InputError(path.string(), 0, "cannot write '" + ext + "': supported output formats are .tri and .obj");
}

}  // namespace flexfit
