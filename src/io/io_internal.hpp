// Internal to src/io: the assimp path behind readMesh().
#pragma once

#include "flexfit/mesh_io.hpp"

namespace flexfit {
MeshReadResult readWithAssimp(const std::filesystem::path& path, const MeshReadOptions& options);
}
