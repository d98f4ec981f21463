// The same surface with its vertices renumbered at random: a mesh with no useful vertex order.
#pragma once

#include "flexfit/mesh.hpp"

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

namespace flexfit::testing {

inline TriMesh shuffledVertices(TriMesh mesh, unsigned seed) {
    std::vector<Index> newIndex(mesh.vertices.size());
    std::iota(newIndex.begin(), newIndex.end(), Index{0});
    std::shuffle(newIndex.begin(), newIndex.end(), std::mt19937(seed));
    std::vector<Vec3> vertices(mesh.vertices.size());
    for (std::size_t v = 0; v < vertices.size(); ++v) vertices[newIndex[v]] = mesh.vertices[v];
    for (Face& f : mesh.faces)
        for (Index& v : f) v = newIndex[v];
    mesh.vertices = std::move(vertices);
    return mesh;
}

}  // namespace flexfit::testing
