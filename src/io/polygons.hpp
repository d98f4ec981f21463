// Internal to src/io: polygons of the text formats (OBJ, OFF) split into triangles.
#pragma once

#include "flexfit/mesh.hpp"

#include <span>
#include <vector>

namespace flexfit::detail {

// Triangles of one polygon (vertex indices into `vertices`), appended to `out` in its winding:
// triangles as they are; strictly convex polygons as a fan from the first corner; others by ear
// clipping in the polygon's own plane (Newell's normal). False when it had to be split as a fan
// though it is not convex (self-intersecting or flat: no ear left), which the reader reports.
bool triangulatePolygon(const std::vector<Vec3>& vertices, std::span<const Index> corners, std::vector<Face>& out);

}  // namespace flexfit::detail
