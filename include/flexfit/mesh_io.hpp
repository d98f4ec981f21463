// Reading and writing meshes.
//
// `.tri` is the thesis's text format, as SPEC.md defines it: line 1 the model's name; then the
// vertex count V and the face count F (on one line or two); then V lines `x y z`; then F lines
// `a b c` of 0-based indices. Blank lines are ignored. OBJ, OFF and PLY have readers of their
// own (obj_io.cpp, off_io.cpp, ply_io.cpp: the file's vertex order and double precision;
// polygons triangulated in their plane). STL and glTF/GLB go through assimp, which gives
// vertices in first-use order, in single precision. Every reader returns a whole, valid mesh or
// throws InputError naming the file, the line where there is one, and the problem.
//
// The mesh read is renumbered where the format's welding or the repair merges or removes
// vertices; MeshReadResult::fileVertices then says where each file vertex went, so a part built
// with it (PartModelSettings::fileVertices) keeps the file's numbering.
//
// Corrupt files are errors: counts that do not match, indices out of range, NaN or infinite
// coordinates, truncation, an empty mesh. Geometric defects a user cannot fix by hand are
// repaired by default (mesh_repair.hpp: near-duplicate vertices welded, degenerate and duplicate
// faces dropped, windings made consistent, unreferenced vertices removed), each kind counted
// in a warning; with `repair = false` they are errors instead, naming the first one's line.
#pragma once

#include "flexfit/mesh.hpp"
#include "flexfit/mesh_repair.hpp"

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace flexfit {

struct MeshReadOptions {
    // Vertices closer than this are welded, asked for (0: only identical positions). Formats
    // that store one vertex per face corner (STL, and OBJ with split normals) always weld
    // identical positions so springs connect the surface. Unset: the repair welds
    // near-duplicates (nearDuplicateTolerance()); the strict reading refuses them.
    std::optional<double> weldTolerance;
    // Repair geometric defects with warnings (true), or refuse them (false: strict).
    bool repair = true;
};

struct MeshReadResult {
    TriMesh mesh;
    MeshDiagnostics diagnostics;     // its warnings list the repairs first
    std::size_t weldedVertices = 0;  // vertices removed by the asked-for or the format's welding
    std::size_t collapsedFaces = 0;  // faces removed because that welding collapsed them
    MeshRepairs repairs;             // what the repair changed (nothing when strict)
    // The file's vertices, when the welding or the repair merged or removed some (mesh.hpp).
    // OBJ, OFF, PLY and .tri: the vertices the file lists; STL, glTF and the other assimp
    // formats: the vertices after the format's welding, in first-use order.
    FileVertices fileVertices;
};

// Parses `.tri` text; `source` names it in errors.
MeshReadResult parseTri(std::string_view text, const std::string& source, const MeshReadOptions& options = {});
MeshReadResult readTri(const std::filesystem::path& path, const MeshReadOptions& options = {});

// Any supported format, chosen by extension (.tri natively, the rest through assimp).
MeshReadResult readMesh(const std::filesystem::path& path, const MeshReadOptions& options = {});

// Writers; choose by extension with writeMesh (.tri or .obj). Throw InputError when the file
// cannot be written, and then leave no file, or the earlier one (writeWholeFile,
// frame_export.hpp). Coordinates are written with 17 significant digits (exact round trip).
void writeTri(const TriMesh& mesh, const std::filesystem::path& path);
void writeObj(const TriMesh& mesh, const std::filesystem::path& path);
void writeMesh(const TriMesh& mesh, const std::filesystem::path& path);
std::string formatTri(const TriMesh& mesh);
// A name as an OBJ "o" line holds it: line breaks become spaces, and a trailing backslash (a
// line continuation to OBJ readers, which would swallow the next line) an underscore.
std::string objObjectName(std::string name);

}  // namespace flexfit
