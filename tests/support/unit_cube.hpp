// The unit cube [0, 1]^3 as 12 outward-facing triangles (8 vertices, 18 edges): a closed mesh
// whose distances and counts are known in closed form.
#pragma once

#include "flexfit/mesh.hpp"

namespace flexfit::testing {

inline TriMesh unitCube() {
    TriMesh mesh;
    mesh.name = "cube";
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    mesh.faces = {{0, 3, 2}, {0, 2, 1}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                  {3, 7, 6}, {3, 6, 2}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}};
    return mesh;
}

}  // namespace flexfit::testing
