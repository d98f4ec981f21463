#include "flexfit/topology.hpp"
#include "flexfit/mesh.hpp"

#include <algorithm>
#include <string>

namespace flexfit {
namespace {

// Turns per-item counts (size n) into CSR offsets (size n + 1) in place.
void countsToOffsets(std::vector<Index>& adr) {
    Index running = 0;
    for (Index& a : adr) {
        const Index count = a;
        a = running;
        running += count;
    }
}

void buildEdges(std::span<const Face> faces, Topology& topo, std::vector<std::uint64_t>& halfEdgeFace) {
    // Key: (a << 32 | b) with a < b; sorted keys give unique edges in (a, b) order.
    struct HalfEdge {
        std::uint64_t key;
        Index face;
    };
    std::vector<HalfEdge> halfEdges;
    halfEdges.reserve(faces.size() * 3);
    for (Index f = 0; f < faces.size(); ++f)
        for (int e = 0; e < 3; ++e) {
            const Index a = std::min(faces[f][e], faces[f][(e + 1) % 3]);
            const Index b = std::max(faces[f][e], faces[f][(e + 1) % 3]);
            halfEdges.push_back({(std::uint64_t(a) << 32) | b, f});
        }
    std::sort(halfEdges.begin(), halfEdges.end(),
              [](const HalfEdge& x, const HalfEdge& y) { return x.key != y.key ? x.key < y.key : x.face < y.face; });
    halfEdgeFace.clear();
    for (std::size_t i = 0; i < halfEdges.size();) {
        std::size_t j = i;
        while (j < halfEdges.size() && halfEdges[j].key == halfEdges[i].key) ++j;
        topo.edgeA.push_back(Index(halfEdges[i].key >> 32));
        topo.edgeB.push_back(Index(halfEdges[i].key & 0xffffffffu));
        topo.edgeFaceCount.push_back(Index(j - i));
        // Faces sharing this edge are neighbours (all pairs, for non-manifold edges too).
        for (std::size_t p = i; p < j; ++p)
            for (std::size_t q = i; q < j; ++q)
                if (p != q) halfEdgeFace.push_back((std::uint64_t(halfEdges[p].face) << 32) | halfEdges[q].face);
        i = j;
    }
}

void buildVertexNeighbours(Topology& topo) {
    const std::size_t edges = topo.edgeCount();
    topo.vertexNeighborAdr.assign(topo.vertexCount + 1, 0);
    for (std::size_t e = 0; e < edges; ++e) {
        ++topo.vertexNeighborAdr[topo.edgeA[e]];
        ++topo.vertexNeighborAdr[topo.edgeB[e]];
    }
    countsToOffsets(topo.vertexNeighborAdr);
    topo.vertexNeighbors.resize(2 * edges);
    topo.vertexEdges.resize(2 * edges);
    std::vector<Index> fill(topo.vertexNeighborAdr.begin(), topo.vertexNeighborAdr.end() - 1);
    // Edges are sorted by (a, b): visiting them in order fills each vertex's list ascending
    // for the "b" side; the "a" side is appended after and sorted below.
    for (Index e = 0; e < edges; ++e) {
        const Index a = topo.edgeA[e], b = topo.edgeB[e];
        topo.vertexNeighbors[fill[a]] = b;
        topo.vertexEdges[fill[a]++] = e;
        topo.vertexNeighbors[fill[b]] = a;
        topo.vertexEdges[fill[b]++] = e;
    }
    for (std::size_t v = 0; v < topo.vertexCount; ++v) {
        const Index begin = topo.vertexNeighborAdr[v], end = topo.vertexNeighborAdr[v + 1];
        std::vector<std::pair<Index, Index>> pairs;
        for (Index k = begin; k < end; ++k) pairs.emplace_back(topo.vertexNeighbors[k], topo.vertexEdges[k]);
        std::sort(pairs.begin(), pairs.end());
        for (Index k = begin; k < end; ++k) std::tie(topo.vertexNeighbors[k], topo.vertexEdges[k]) = pairs[k - begin];
    }
}

void buildVertexFaces(std::span<const Face> faces, Topology& topo) {
    topo.vertexFaceAdr.assign(topo.vertexCount + 1, 0);
    for (const Face& f : faces)
        for (Index v : f) ++topo.vertexFaceAdr[v];
    countsToOffsets(topo.vertexFaceAdr);
    topo.vertexFaces.resize(faces.size() * 3);
    std::vector<Index> fill(topo.vertexFaceAdr.begin(), topo.vertexFaceAdr.end() - 1);
    for (Index f = 0; f < faces.size(); ++f)
        for (Index v : faces[f]) topo.vertexFaces[fill[v]++] = f;
}

void buildFaceNeighbours(std::vector<std::uint64_t>& pairs, Topology& topo) {
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    topo.faceNeighborAdr.assign(topo.faceCount + 1, 0);
    for (std::uint64_t p : pairs) ++topo.faceNeighborAdr[p >> 32];
    countsToOffsets(topo.faceNeighborAdr);
    topo.faceNeighbors.reserve(pairs.size());
    for (std::uint64_t p : pairs) topo.faceNeighbors.push_back(Index(p & 0xffffffffu));
}

}  // namespace

Topology buildTopology(std::span<const Face> faces, std::size_t vertexCount) {
    if (const auto beyond = firstIndexBeyond(faces, vertexCount))
        throw InputError("topology", 0, "face " + std::to_string(beyond->first) + " names vertex " + std::to_string(beyond->second) + " of " +
                                            std::to_string(vertexCount));
    Topology topo;
    topo.vertexCount = vertexCount;
    topo.faceCount = faces.size();
    std::vector<std::uint64_t> facePairs;
    buildEdges(faces, topo, facePairs);
    buildVertexNeighbours(topo);
    buildVertexFaces(faces, topo);
    buildFaceNeighbours(facePairs, topo);
    return topo;
}

SolidDefect solidDefect(std::span<const Vec3> vertices, std::span<const Face> faces, const Topology& topology) {
    if (faces.empty() || std::any_of(topology.edgeFaceCount.begin(), topology.edgeFaceCount.end(), [](Index n) { return n != 2; }))
        return SolidDefect::Open;
    std::vector<std::pair<Index, Index>> directed;
    directed.reserve(3 * faces.size());
    for (const Face& f : faces)
        for (std::size_t k = 0; k < 3; ++k) directed.emplace_back(f[k], f[(k + 1) % 3]);
    std::sort(directed.begin(), directed.end());
    if (std::adjacent_find(directed.begin(), directed.end()) != directed.end()) return SolidDefect::Inconsistent;
    double volume = 0.0;  // the divergence theorem over the faces
    for (const Face& f : faces) volume += vertices[f[0]].dot(vertices[f[1]].cross(vertices[f[2]])) / 6.0;
    return volume > 0.0 ? SolidDefect::None : SolidDefect::InsideOut;
}

}  // namespace flexfit
