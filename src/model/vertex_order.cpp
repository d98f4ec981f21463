#include "model/vertex_order.hpp"

#include <algorithm>
#include <cstdint>

namespace flexfit::detail {
namespace {

// Scratch for oneRing: per-vertex marks stamped with a counter, so a query costs O(valence log
// valence) however large the valence (a fan-triangulated cap meets one vertex in every face).
struct RingScratch {
    std::vector<std::pair<Index, Index>> turns;
    std::vector<std::uint32_t> reachedMark, inRingMark;  // (V)
    std::uint32_t stamp = 0;
};

// v's neighbours in the turning order of its faces (a -> b for each face (v, a, b) as wound),
// starting at a boundary neighbour when v has one; neighbours off that cycle follow in index
// order.
void oneRing(const Topology& topology, std::span<const Face> faces, Index v, RingScratch& s, std::vector<Index>& ring) {
    std::vector<std::pair<Index, Index>>& turns = s.turns;
    turns.clear();
    for (Index f : topology.facesOf(v)) {
        const Face& face = faces[f];
        const int c = face[0] == v ? 0 : face[1] == v ? 1 : 2;
        turns.emplace_back(face[std::size_t((c + 1) % 3)], face[std::size_t((c + 2) % 3)]);
    }
    std::sort(turns.begin(), turns.end());
    const auto nextOf = [&](Index a) -> const Index* {
        const auto it = std::lower_bound(turns.begin(), turns.end(), std::pair<Index, Index>(a, 0));
        return it != turns.end() && it->first == a ? &it->second : nullptr;
    };
    ring.clear();
    if (turns.empty()) return;
    const std::uint32_t stamp = ++s.stamp;
    for (const auto& t : turns) s.reachedMark[t.second] = stamp;
    Index start = turns.front().first;
    for (const auto& t : turns)  // a neighbour no turn reaches starts an open fan
        if (s.reachedMark[t.first] != stamp) {
            start = t.first;
            break;
        }
    for (Index a = start; s.inRingMark[a] != stamp;) {
        s.inRingMark[a] = stamp;
        ring.push_back(a);
        const Index* next = nextOf(a);
        if (next == nullptr) break;
        a = *next;
    }
    for (Index w : topology.neighborsOf(v))
        if (s.inRingMark[w] != stamp) s.inRingMark[w] = stamp, ring.push_back(w);
}

// The vertex a breadth-first search from `start` reaches last (in start's component).
Index farthestFrom(const Topology& topology, Index start, std::vector<char>& seen, std::vector<Index>& queue) {
    queue.assign(1, start);
    seen[start] = 1;
    for (std::size_t head = 0; head < queue.size(); ++head)
        for (Index w : topology.neighborsOf(queue[head]))
            if (!seen[w]) seen[w] = 1, queue.push_back(w);
    for (Index v : queue) seen[v] = 0;
    return queue.back();
}

}  // namespace

std::vector<Index> localityOrder(const Topology& topology, std::span<const Face> faces) {
    const std::size_t n = topology.vertexCount;
    std::vector<char> seen(n, 0);
    std::vector<Index> order, queue, ring;
    RingScratch scratch;
    scratch.reachedMark.assign(n, 0);
    scratch.inRingMark.assign(n, 0);
    order.reserve(n);
    for (Index lowest = 0; lowest < n; ++lowest) {
        if (seen[lowest]) continue;
        const Index start = farthestFrom(topology, farthestFrom(topology, lowest, seen, queue), seen, queue);
        seen[start] = 1;
        order.push_back(start);
        for (std::size_t head = order.size() - 1; head < order.size(); ++head) {
            oneRing(topology, faces, order[head], scratch, ring);
            const std::size_t k = ring.size();
            std::size_t first = 0;  // just after the visited run, so fronts keep turning one way
            for (std::size_t i = 0; i < k; ++i)
                if (seen[ring[i]] && !seen[ring[(i + 1) % k]]) {
                    first = (i + 1) % k;
                    break;
                }
            for (std::size_t i = 0; i < k; ++i) {
                const Index w = ring[(first + i) % k];
                if (!seen[w]) seen[w] = 1, order.push_back(w);
            }
        }
    }
    std::vector<Index> newIndex(n);
    for (std::size_t i = 0; i < n; ++i) newIndex[order[i]] = Index(i);
    return newIndex;
}

TriMesh renumberVertices(const TriMesh& mesh, std::span<const Index> newIndex) {
    TriMesh out;
    out.name = mesh.name;
    out.vertices.resize(mesh.vertices.size());
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) out.vertices[newIndex[v]] = mesh.vertices[v];
    out.faces = mesh.faces;
    for (Face& f : out.faces)
        for (Index& v : f) v = newIndex[v];
    return out;
}

}  // namespace flexfit::detail
