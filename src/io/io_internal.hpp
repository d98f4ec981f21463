// Internal to src/io: the readers behind readMesh() (our own for .tri, OBJ, OFF and PLY; assimp for
// the rest), and the steps every reader ends with.
#pragma once

#include "flexfit/mesh_io.hpp"

namespace flexfit {
// The file's extension in lower case (".stl").
std::string lowerExtension(const std::filesystem::path& path);

// Through assimp, whose import runs in a child process (assimp_io.cpp): a crash or a hang on a
// damaged file is an InputError. The import may take 30 s plus 2 s per MB of file.
MeshReadResult readWithAssimp(const std::filesystem::path& path, const MeshReadOptions& options);
namespace detail {
// Tests: every assimp import in this scope may take `seconds` (> 0). Scopes must not overlap.
class ScopedImportTimeLimit {
public:
    explicit ScopedImportTimeLimit(double seconds);
    ~ScopedImportTimeLimit();
    ScopedImportTimeLimit(const ScopedImportTimeLimit&) = delete;
    ScopedImportTimeLimit& operator=(const ScopedImportTimeLimit&) = delete;
};
}  // namespace detail
// OBJ in the file's vertex order (obj_io.cpp).
MeshReadResult parseObj(std::string_view text, const std::string& source, const MeshReadOptions& options);
MeshReadResult readObj(const std::filesystem::path& path, const MeshReadOptions& options);
// OFF in the file's vertex order (off_io.cpp).
MeshReadResult parseOff(std::string_view text, const std::string& source, const MeshReadOptions& options);
MeshReadResult readOff(const std::filesystem::path& path, const MeshReadOptions& options);
// PLY (ASCII and binary) in the file's vertex order (ply_io.cpp).
MeshReadResult parsePly(std::string_view text, const std::string& source, const MeshReadOptions& options);
MeshReadResult readPly(const std::filesystem::path& path, const MeshReadOptions& options);

// The end of the polygon formats' readers (OBJ, OFF): a mesh with no triangle refused; positions
// repeated exactly (split normals, texture seams, the seams of a model made of pieces) welded
// as the format's welding (the rest keep the file's order and their lines); finishRead; a
// warning for each, and for `fanned` polygons split as fans though not convex.
MeshReadResult finishPolygonRead(TriMesh mesh, const std::string& source, const MeshSourceLines& lines, const MeshReadOptions& options,
                                 std::size_t fanned);

using TextMeshParser = MeshReadResult (*)(std::string_view text, const std::string& source, const MeshReadOptions& options);
// A text file parsed by `parse`, the mesh named after the file's stem.
MeshReadResult readTextMesh(const std::filesystem::path& path, const MeshReadOptions& options, TextMeshParser parse);

// The welding a format needs before the repair (identical positions merged).
enum class FormatWelding {
    None,        // the file's vertices are distinct (.tri)
    Repeats,     // a file that lists shared vertices repeats some (OBJ, OFF, PLY): the file's
                 // numbering is kept through the weld (MeshReadResult::fileVertices)
    PerCorner,   // one vertex per face corner (STL, through assimp): the welded vertices, in
                 // first-use order, are the file's numbering
};

// What every reader does with the mesh it parsed (`lines`: where its vertices and faces were,
// when known): the asked-for welding (or the format's: identical positions), then the repair or
// the strict check, then validation.
MeshReadResult finishRead(TriMesh mesh, const std::string& source, const MeshSourceLines& lines, const MeshReadOptions& options,
                          FormatWelding formatWelding);
}
