// The same surface with its vertices renumbered: at random (a mesh with no useful vertex
// order), or breadth-first (reverse Cuthill-McKee: neighbours close in memory, the ordering a
// model build could apply to an imported mesh).
#pragma once

#include "flexfit/mesh.hpp"
#include "flexfit/topology.hpp"

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

namespace flexfit::testing {

// Vertex v becomes newIndex[v].
inline TriMesh renumbered(TriMesh mesh, const std::vector<Index>& newIndex) {
    std::vector<Vec3> vertices(mesh.vertices.size());
    for (std::size_t v = 0; v < vertices.size(); ++v) vertices[newIndex[v]] = mesh.vertices[v];
    for (Face& f : mesh.faces)
        for (Index& v : f) v = newIndex[v];
    mesh.vertices = std::move(vertices);
    return mesh;
}

inline TriMesh shuffledVertices(TriMesh mesh, unsigned seed) {
    std::vector<Index> newIndex(mesh.vertices.size());
    std::iota(newIndex.begin(), newIndex.end(), Index{0});
    std::shuffle(newIndex.begin(), newIndex.end(), std::mt19937(seed));
    return renumbered(std::move(mesh), newIndex);
}

// Reverse Cuthill-McKee: breadth-first from each component's lowest-index vertex, neighbours
// visited by increasing degree, the whole order reversed.
inline TriMesh breadthFirstVertices(TriMesh mesh) {
    const Topology topology = buildTopology(mesh.faces, mesh.vertices.size());
    const std::size_t n = mesh.vertices.size();
    std::vector<Index> order;
    order.reserve(n);
    std::vector<char> seen(n, 0);
    for (Index start = 0; start < n; ++start) {
        if (seen[start]) continue;
        seen[start] = 1;
        order.push_back(start);
        for (std::size_t head = order.size() - 1; head < order.size(); ++head) {
            std::vector<Index> next;
            for (Index w : topology.neighborsOf(order[head]))
                if (!seen[w]) next.push_back(w), seen[w] = 1;
            std::stable_sort(next.begin(), next.end(), [&](Index a, Index b) {
                return topology.neighborsOf(a).size() < topology.neighborsOf(b).size();
            });
            order.insert(order.end(), next.begin(), next.end());
        }
    }
    std::vector<Index> newIndex(n);
    for (std::size_t i = 0; i < n; ++i) newIndex[order[i]] = Index(n - 1 - i);
    return renumbered(std::move(mesh), newIndex);
}

}  // namespace flexfit::testing
