// Reading and writing meshes.
//
// `.tri` is the thesis's text format, as SPEC.md defines it: line 1 the model's name; then the
// vertex count V and the face count F (on one line or two); then V lines `x y z`; then F lines
// `a b c` of 0-based indices. Blank lines are ignored. Everything else (OBJ, STL, PLY, OFF,
// glTF/GLB) goes through assimp. Every reader validates before returning: it returns a whole,
// valid mesh or throws InputError naming the file, the line where there is one, and the
// problem.
#pragma once

#include "flexfit/mesh.hpp"

#include <filesystem>
#include <string>
#include <string_view>

namespace flexfit {

struct MeshReadOptions {
    // Vertices closer than this are welded (0: only identical positions). Formats that store
    // one vertex per face corner (STL, and OBJ with split normals) need welding so springs
    // connect the surface.
    double weldTolerance = 0.0;
};

struct MeshReadResult {
    TriMesh mesh;
    MeshDiagnostics diagnostics;
    std::size_t weldedVertices = 0;  // vertices removed by welding
    std::size_t collapsedFaces = 0;  // faces removed because welding collapsed them
};

// Parses `.tri` text; `source` names it in errors.
MeshReadResult parseTri(std::string_view text, const std::string& source);
MeshReadResult readTri(const std::filesystem::path& path);

// Any supported format, chosen by extension (.tri natively, the rest through assimp).
MeshReadResult readMesh(const std::filesystem::path& path, const MeshReadOptions& options = {});

// Writers; choose by extension with writeMesh (.tri or .obj). Throw InputError when the file
// cannot be written. Coordinates are written with 17 significant digits (exact round trip).
void writeTri(const TriMesh& mesh, const std::filesystem::path& path);
void writeObj(const TriMesh& mesh, const std::filesystem::path& path);
void writeMesh(const TriMesh& mesh, const std::filesystem::path& path);
std::string formatTri(const TriMesh& mesh);

}  // namespace flexfit
