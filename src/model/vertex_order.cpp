#include "model/vertex_order.hpp"

#include <algorithm>

namespace flexfit::detail {
namespace {

// v's neighbours in the turning order of its faces (a -> b for each face (v, a, b) as wound),
// starting at a boundary neighbour when v has one; neighbours off that cycle follow in index
// order.
void oneRing(const Topology& topology, std::span<const Face> faces, Index v, std::vector<std::pair<Index, Index>>& turns,
             std::vector<Index>& ring) {
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
    Index start = turns.front().first;
    for (const auto& [a, b] : turns) {  // a neighbour no turn reaches starts an open fan
        const bool reached = std::any_of(turns.begin(), turns.end(), [&](const auto& t) { return t.second == a; });
        if (!reached) {
            start = a;
            break;
        }
    }
    for (Index a = start; ring.size() <= turns.size();) {
        if (std::find(ring.begin(), ring.end(), a) != ring.end()) break;
        ring.push_back(a);
        const Index* next = nextOf(a);
        if (next == nullptr) break;
        a = *next;
    }
    for (Index w : topology.neighborsOf(v))
        if (std::find(ring.begin(), ring.end(), w) == ring.end()) ring.push_back(w);
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
    std::vector<std::pair<Index, Index>> turns;
    order.reserve(n);
    for (Index lowest = 0; lowest < n; ++lowest) {
        if (seen[lowest]) continue;
        const Index start = farthestFrom(topology, farthestFrom(topology, lowest, seen, queue), seen, queue);
        seen[start] = 1;
        order.push_back(start);
        for (std::size_t head = order.size() - 1; head < order.size(); ++head) {
            oneRing(topology, faces, order[head], turns, ring);
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
