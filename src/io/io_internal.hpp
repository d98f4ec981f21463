// Internal to src/io: the assimp path behind readMesh(), and the steps every reader ends with.
#pragma once

#include "flexfit/mesh_io.hpp"

namespace flexfit {
MeshReadResult readWithAssimp(const std::filesystem::path& path, const MeshReadOptions& options);
// OBJ in the file's vertex order (obj_io.cpp).
MeshReadResult parseObj(std::string_view text, const std::string& source, const MeshReadOptions& options);
MeshReadResult readObj(const std::filesystem::path& path, const MeshReadOptions& options);

// What every reader does with the mesh it parsed (`lines`: where its vertices and faces were,
// when known): the asked-for welding (or the format's, `formatWelds`: identical positions),
// then the repair or the strict check, then validation.
MeshReadResult finishRead(TriMesh mesh, const std::string& source, const MeshSourceLines& lines, const MeshReadOptions& options,
                          bool formatWelds);
}
