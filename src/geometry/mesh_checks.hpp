// Internal to src/geometry: the checks validateMesh (mesh.cpp) and repairMesh (mesh_repair.cpp)
// share, so that what one refuses the other repairs by the same test.
#pragma once

#include "flexfit/mesh.hpp"

#include <string>
#include <vector>

namespace flexfit::detail {

std::size_t lineOf(const std::vector<std::size_t>& lines, std::size_t i);  // 0 when unknown
std::string faceText(std::size_t f, const Face& face);                     // "face 3 (0 1 2)"

// Throws InputError for what no repair can mend: an empty mesh, a NaN or infinite coordinate,
// a scale outside what Flexfit computes with (kMaxMeshCoordinate, kMinMeshSize), an index out of
// range.
void requireWellFormed(const TriMesh& mesh, const std::string& source, const MeshSourceLines& lines);

// A face is of zero area when its double area, edges scaled by areaScale() (the inverse
// bounding-box diagonal), is at most 2e-12.
double areaScale(const TriMesh& mesh);
bool hasZeroArea(const TriMesh& mesh, const Face& face, double scale);

}  // namespace flexfit::detail
