// Format dispatch and the OBJ writer.
#include "flexfit/mesh_io.hpp"
#include "flexfit/frame_export.hpp"
#include "io_internal.hpp"
#include "geometry/mesh_checks.hpp"
#include "text_lines.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace flexfit {

std::string lowerExtension(const std::filesystem::path& path) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

namespace {

// Strict reading: a face the welding would collapse (two corners at one position) is refused,
// not dropped.
void requireNoCollapse(const TriMesh& mesh, double tolerance, const std::string& source, const MeshSourceLines& lines) {
    const std::vector<Index> target = weldTargets(mesh.vertices, tolerance);
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
        const Face& face = mesh.faces[f];
        for (int k = 0; k < 3; ++k) {
            const Index u = face[k], v = face[(k + 1) % 3];
            if (target[u] == target[v])
                throw InputError(source, detail::lineOf(lines.faceLine, f),
                                 detail::faceText(f, face) + " is degenerate: its corners " + std::to_string(u) + " and " + std::to_string(v) +
                                     (tolerance > 0.0 ? " are within the weld tolerance" : " are at the same position"));
        }
    }
}

}  // namespace

namespace {

std::size_t repeatedPositions(const std::vector<Vec3>& vertices) {
    const std::vector<Index> target = weldTargets(vertices, 0.0);
    std::size_t repeats = 0;
    for (std::size_t v = 0; v < target.size(); ++v) repeats += target[v] != v ? 1 : 0;
    return repeats;
}

}  // namespace

MeshReadResult finishPolygonRead(TriMesh mesh, const std::string& source, const MeshSourceLines& lines, const MeshReadOptions& options,
                                 std::size_t fanned) {
    if (mesh.faces.empty()) throw InputError(source, 0, "empty mesh: no triangles");
    const std::size_t repeats = repeatedPositions(mesh.vertices);
    MeshReadResult result = finishRead(std::move(mesh), source, lines, options, repeats > 0 ? FormatWelding::Repeats : FormatWelding::None);
    std::vector<std::string>& warnings = result.diagnostics.warnings;
    if (fanned > 0)
        warnings.insert(warnings.begin(), std::to_string(fanned) + " polygons cross themselves (or are flat) and were split as fans: "
                                                                   "their triangles may overlap");
    if (repeats > 0)
        warnings.insert(warnings.begin(), std::to_string(repeats) + " vertices repeat an earlier one's position (split normals, texture "
                                          "seams, the seams of a model made of pieces) and were welded into it: a part's vertex indices "
                                          "(scene masses, frames) stay the file's; the mesh read (flexfit convert) has the welded ones");
    return result;
}

MeshReadResult readTextMesh(const std::filesystem::path& path, const MeshReadOptions& options, TextMeshParser parse) {
    MeshReadResult result = parse(detail::readTextDocument(path), path.string(), options);
    result.mesh.name = path.stem().string();
    return result;
}

MeshReadResult finishRead(TriMesh mesh, const std::string& source, const MeshSourceLines& lines, const MeshReadOptions& options,
                          FormatWelding formatWelding) {
    detail::requireWellFormed(mesh, source, lines);
    MeshReadResult result;
    const bool welds = formatWelding != FormatWelding::None || options.weldTolerance.has_value();
    if (welds && !options.repair) requireNoCollapse(mesh, options.weldTolerance.value_or(0.0), source, lines);
    FileVertices file{{}, mesh.vertices};
    if (welds) {  // indices change: the lines no longer match the faces
        const std::size_t before = mesh.vertices.size();
        const std::size_t faces = mesh.faces.size();
        result.collapsedFaces = weldVertices(mesh, options.weldTolerance.value_or(0.0), &file.meshVertex);
        result.weldedVertices = before - mesh.vertices.size();
        if (mesh.faces.empty() && faces > 0) {  // said before the emptiness check names only its result
            std::ostringstream text;
            text << "welding within " << options.weldTolerance.value_or(0.0) << " collapsed all " << faces
                 << " faces: the weld tolerance is as large as the mesh";
            throw InputError(source, 0, text.str());
        }
    }
    if (formatWelding == FormatWelding::PerCorner) file = {{}, mesh.vertices};  // numbered as welded
    const MeshSourceLines none;
    const MeshSourceLines& where = welds ? none : lines;
    const double tolerance = options.weldTolerance.value_or(-1.0);  // < 0: near-duplicates
    if (options.repair)
        result.repairs = repairMesh(mesh, tolerance, source, where);
    else
        requireNoDefects(mesh, tolerance, source, where);
    if (!result.repairs.vertexMap.empty()) {
        if (file.meshVertex.empty()) file.meshVertex = result.repairs.vertexMap;
        else composeVertexMap(file.meshVertex, result.repairs.vertexMap);
    }
    if (!file.meshVertex.empty() && (file.count() != mesh.vertices.size() || !result.repairs.vertexMap.empty()))
        result.fileVertices = std::move(file);
    result.diagnostics = validateMesh(mesh, source);
    std::vector<std::string> warnings = result.repairs.warnings();
    if (result.collapsedFaces > 0) warnings.push_back(std::to_string(result.collapsedFaces) + " faces collapsed by welding and were removed");
    warnings.insert(warnings.end(), result.diagnostics.warnings.begin(), result.diagnostics.warnings.end());
    result.diagnostics.warnings = std::move(warnings);
    result.mesh = std::move(mesh);
    return result;
}

MeshReadResult readMesh(const std::filesystem::path& path, const MeshReadOptions& options) {
    if (options.weldTolerance && !(*options.weldTolerance >= 0.0 && std::isfinite(*options.weldTolerance)))
        throw InputError(path.string(), 0, "weld tolerance must be a finite number >= 0");
    if (std::error_code ec; std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
        throw InputError(path.string(), 0, "not a regular file (a directory or a device): name a mesh file");
    const std::string ext = lowerExtension(path);
    if (ext == ".tri") return readTri(path, options);
    if (ext == ".obj") return readObj(path, options);
    if (ext == ".off") return readOff(path, options);
    if (ext == ".ply") return readPly(path, options);
    return readWithAssimp(path, options);
}

// An OBJ object name on one line: line breaks become spaces, and a trailing backslash (a line
// continuation to OBJ readers, which would swallow the first vertex) an underscore.
std::string objObjectName(std::string name) {
    for (char& c : name)
        if (c == '\n' || c == '\r') c = ' ';
    if (!name.empty() && name.back() == '\\') name.back() = '_';
    return name;
}

void writeObj(const TriMesh& mesh, const std::filesystem::path& path) {
    std::string text = "# written by flexfit\n";
    if (!mesh.name.empty()) text += "o " + objObjectName(mesh.name) + "\n";
    char buffer[128];
    for (const Vec3& v : mesh.vertices) {
        std::snprintf(buffer, sizeof buffer, "v %.17g %.17g %.17g\n", v.x(), v.y(), v.z());
        text += buffer;
    }
    for (const Face& f : mesh.faces) text += "f " + std::to_string(f[0] + 1) + " " + std::to_string(f[1] + 1) + " " + std::to_string(f[2] + 1) + "\n";
    writeWholeFile(path, text);
}

void writeMesh(const TriMesh& mesh, const std::filesystem::path& path) {
    const std::string ext = lowerExtension(path);
    if (ext == ".tri") return writeTri(mesh, path);
    if (ext == ".obj") return writeObj(mesh, path);
    throw InputError(path.string(), 0, "cannot write '" + ext + "': supported output formats are .tri and .obj");
}

}  // namespace flexfit
