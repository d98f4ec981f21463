// Mesh topology as flat CSR arrays (MuJoCo's `*_adr` / `*_num` style, no pointer graphs).
//
// Built once per model in O(F log F) by sorting half-edge keys; no dense adjacency matrix, so
// models of 20,000+ triangles stay cheap. Each unique undirected edge is one spring; an edge
// shared by two faces appears once.
#pragma once

#include "flexfit/core.hpp"

#include <span>
#include <vector>

namespace flexfit {

struct Topology {
    std::size_t vertexCount = 0;
    std::size_t faceCount = 0;

    // Unique edges, sorted by (edgeA, edgeB) with edgeA < edgeB.
    std::vector<Index> edgeA;          // (E)
    std::vector<Index> edgeB;          // (E)
    std::vector<Index> edgeFaceCount;  // (E) faces using the edge: 1 boundary, 2 manifold, 3+ not

    // mass -> masses: neighbours of v are vertexNeighbors[vertexNeighborAdr[v] .. adr[v+1]).
    std::vector<Index> vertexNeighborAdr;  // (V+1)
    std::vector<Index> vertexNeighbors;    // (2E) ascending per vertex
    // mass -> springs, aligned with vertexNeighbors: vertexEdges[k] joins v and vertexNeighbors[k].
    std::vector<Index> vertexEdges;  // (2E)
    // mass -> faces.
    std::vector<Index> vertexFaceAdr;  // (V+1)
    std::vector<Index> vertexFaces;    // (3F)
    // face -> faces sharing an edge (3 per face on a closed manifold).
    std::vector<Index> faceNeighborAdr;  // (F+1)
    std::vector<Index> faceNeighbors;

    std::size_t edgeCount() const { return edgeA.size(); }
    std::span<const Index> neighborsOf(Index v) const {
        return {vertexNeighbors.data() + vertexNeighborAdr[v], vertexNeighbors.data() + vertexNeighborAdr[v + 1]};
    }
    std::span<const Index> edgesOf(Index v) const {
        return {vertexEdges.data() + vertexNeighborAdr[v], vertexEdges.data() + vertexNeighborAdr[v + 1]};
    }
    std::span<const Index> facesOf(Index v) const {
        return {vertexFaces.data() + vertexFaceAdr[v], vertexFaces.data() + vertexFaceAdr[v + 1]};
    }
    std::span<const Index> faceNeighborsOf(Index f) const {
        return {faceNeighbors.data() + faceNeighborAdr[f], faceNeighbors.data() + faceNeighborAdr[f + 1]};
    }
};

// Faces must hold indices < vertexCount (validateMesh guarantees it; InputError otherwise).
Topology buildTopology(std::span<const Face> faces, std::size_t vertexCount);

// Whether a mesh bounds a solid: closed and manifold (every edge on two faces), consistently
// oriented (each edge used once in each direction) and outward (a positive enclosed volume).
// The first of these it fails, or None. The signed distance field needs a solid; the
// triangle test reads a solid's faces one-sided (collision.hpp).
enum class SolidDefect { None, Open, Inconsistent, InsideOut };
SolidDefect solidDefect(std::span<const Vec3> vertices, std::span<const Face> faces, const Topology& topology);

}  // namespace flexfit
