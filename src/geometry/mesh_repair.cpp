#include "flexfit/mesh_repair.hpp"
#include "geometry/mesh_checks.hpp"

#include <algorithm>
#include <cstdint>
#include <sstream>

namespace flexfit {
namespace {

using detail::faceText;
using detail::lineOf;

std::string vertexText(Index v, const MeshSourceLines& lines) {
    const std::size_t line = lineOf(lines.vertexLine, v);
    return "vertex " + std::to_string(v) + (line > 0 ? " (line " + std::to_string(line) + ")" : "");
}

// The faces' edges grouped by their two vertices: (min, max) << 32, then the face, and whether
// the face runs the edge from min to max.
struct EdgeUse {
    std::uint64_t key;
    Index face;
    bool forward;
    auto operator<=>(const EdgeUse&) const = default;
};

std::vector<EdgeUse> edgeUses(const std::vector<Face>& faces) {
    std::vector<EdgeUse> uses;
    uses.reserve(3 * faces.size());
    for (std::size_t f = 0; f < faces.size(); ++f)
        for (std::size_t k = 0; k < 3; ++k) {
            const Index u = faces[f][k], v = faces[f][(k + 1) % 3];
            uses.push_back({std::uint64_t(std::min(u, v)) << 32 | std::max(u, v), Index(f), u < v});
        }
    std::sort(uses.begin(), uses.end());
    return uses;
}

// Faces sharing an edge with exactly one other face, in CSR form: a neighbour and whether the
// two run the edge the same way (then one of them must be flipped).
struct Neighbours {
    std::vector<std::size_t> begin;  // (F + 1)
    std::vector<std::pair<Index, bool>> list;
};

Neighbours manifoldNeighbours(const std::vector<Face>& faces) {
    const std::vector<EdgeUse> uses = edgeUses(faces);
    std::vector<std::pair<Index, std::pair<Index, bool>>> pairs;
    for (std::size_t i = 0; i < uses.size();) {
        std::size_t j = i;
        while (j < uses.size() && uses[j].key == uses[i].key) ++j;
        if (j - i == 2) {
            const bool same = uses[i].forward == uses[i + 1].forward;
            pairs.push_back({uses[i].face, {uses[i + 1].face, same}});
            pairs.push_back({uses[i + 1].face, {uses[i].face, same}});
        }
        i = j;
    }
    std::sort(pairs.begin(), pairs.end());
    Neighbours n;
    n.begin.assign(faces.size() + 1, 0);
    for (const auto& p : pairs) ++n.begin[p.first + 1];
    for (std::size_t f = 0; f < faces.size(); ++f) n.begin[f + 1] += n.begin[f];
    n.list.reserve(pairs.size());
    for (const auto& p : pairs) n.list.push_back(p.second);
    return n;
}

// Flips the minority of each orientable piece; returns the faces flipped and counts the
// pieces no flipping makes consistent.
std::size_t orientConsistently(std::vector<Face>& faces, std::size_t& nonOrientable) {
    const Neighbours n = manifoldNeighbours(faces);
    constexpr std::uint8_t kUnseen = 2;
    std::vector<std::uint8_t> parity(faces.size(), kUnseen);  // 1: wound against the piece's first face
    std::vector<Index> piece;
    std::size_t flipped = 0;
    for (std::size_t seed = 0; seed < faces.size(); ++seed) {
        if (parity[seed] != kUnseen) continue;
        piece.assign(1, Index(seed));
        parity[seed] = 0;
        bool orientable = true;
        for (std::size_t at = 0; at < piece.size(); ++at) {
            const Index f = piece[at];
            for (std::size_t k = n.begin[f]; k < n.begin[f + 1]; ++k) {
                const auto [g, same] = n.list[k];
                const std::uint8_t wanted = parity[f] ^ std::uint8_t(same);
                if (parity[g] == kUnseen) {
                    parity[g] = wanted;
                    piece.push_back(g);
                } else if (parity[g] != wanted) {
                    orientable = false;
                }
            }
        }
        if (!orientable) {
            ++nonOrientable;
            continue;
        }
        const std::size_t against = std::size_t(std::count_if(piece.begin(), piece.end(), [&](Index f) { return parity[f] == 1; }));
        const std::uint8_t flip = against * 2 > piece.size() ? 0 : 1;  // the fewer; ties: those against the first face
        for (Index f : piece)
            if (parity[f] == flip) {
                std::swap(faces[f][1], faces[f][2]);
                ++flipped;
            }
    }
    return flipped;
}

// Keeps the faces for which keep(face index) holds, in order.
template <class Keep>
std::size_t dropFaces(std::vector<Face>& faces, Keep keep) {
    std::vector<Face> kept;
    kept.reserve(faces.size());
    for (std::size_t f = 0; f < faces.size(); ++f)
        if (keep(f)) kept.push_back(faces[f]);
    const std::size_t dropped = faces.size() - kept.size();
    faces = std::move(kept);
    return dropped;
}

std::size_t dropDegenerateFaces(TriMesh& mesh) {
    const double scale = detail::areaScale(mesh);
    return dropFaces(mesh.faces, [&](std::size_t f) {
        const Face& face = mesh.faces[f];
        return face[0] != face[1] && face[1] != face[2] && face[0] != face[2] && !detail::hasZeroArea(mesh, face, scale);
    });
}

// Each face's first copy (same three vertices, in any order), or itself.
std::vector<Index> firstCopies(const std::vector<Face>& faces) {
    std::vector<std::pair<Face, Index>> sorted(faces.size());
    for (std::size_t f = 0; f < faces.size(); ++f) {
        Face key = faces[f];
        std::sort(key.begin(), key.end());
        sorted[f] = {key, Index(f)};
    }
    std::sort(sorted.begin(), sorted.end());
    std::vector<Index> first(faces.size());
    for (std::size_t i = 0; i < sorted.size(); ++i)
        first[sorted[i].second] = i > 0 && sorted[i].first == sorted[i - 1].first ? first[sorted[i - 1].second] : sorted[i].second;
    return first;
}

std::size_t dropDuplicateFaces(std::vector<Face>& faces) {
    const std::vector<Index> first = firstCopies(faces);
    return dropFaces(faces, [&](std::size_t f) { return first[f] == Index(f); });
}

std::vector<bool> referenced(const TriMesh& mesh) {
    std::vector<bool> used(mesh.vertices.size(), false);
    for (const Face& f : mesh.faces)
        for (Index v : f) used[v] = true;
    return used;
}

std::size_t removeUnreferencedVertices(TriMesh& mesh, VertexMap& remap) {
    const std::vector<bool> used = referenced(mesh);
    remap.assign(mesh.vertices.size(), kNoVertex);
    std::vector<Vec3> kept;
    kept.reserve(mesh.vertices.size());
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
        if (used[v]) {
            remap[v] = Index(kept.size());
            kept.push_back(mesh.vertices[v]);
        }
    for (Face& f : mesh.faces)
        for (Index& v : f) v = remap[v];
    const std::size_t removed = mesh.vertices.size() - kept.size();
    mesh.vertices = std::move(kept);
    return removed;
}

double resolvedTolerance(const TriMesh& mesh, double weldTolerance) {
    return weldTolerance >= 0.0 ? weldTolerance : nearDuplicateTolerance(mesh);
}

std::string plural(std::size_t count, const std::string& one, const std::string& many) {
    return std::to_string(count) + " " + (count == 1 ? one : many);
}

}  // namespace

double nearDuplicateTolerance(const TriMesh& mesh) {
    return kNearDuplicateShare * boundingBox(mesh).diagonal().stableNorm();
}

bool MeshRepairs::any() const {
    return weldedVertices + degenerateFaces + duplicateFaces + flippedFaces + nonOrientablePieces + unreferencedVertices > 0;
}

std::vector<std::string> MeshRepairs::warnings() const {
    std::vector<std::string> out;
    if (weldedVertices > 0) {
        std::ostringstream text;
        text << plural(weldedVertices, "vertex", "vertices") << " welded into an earlier one within " << weldTolerance
             << " (near-duplicate positions)";
        out.push_back(text.str());
    }
    if (degenerateFaces > 0) out.push_back(plural(degenerateFaces, "degenerate face", "degenerate faces") + " (zero area or a repeated vertex) dropped");
    if (duplicateFaces > 0) out.push_back(plural(duplicateFaces, "duplicate face", "duplicate faces") + " (the same vertices as an earlier face) dropped");
    if (flippedFaces > 0) out.push_back(plural(flippedFaces, "face", "faces") + " flipped to agree with the winding around them");
    if (nonOrientablePieces > 0)
        out.push_back(plural(nonOrientablePieces, "non-orientable piece", "non-orientable pieces") + " left with inconsistent windings");
    if (unreferencedVertices > 0) out.push_back(plural(unreferencedVertices, "vertex", "vertices") + " used by no face removed");
    return out;
}

MeshRepairs repairMesh(TriMesh& mesh, double weldTolerance, const std::string& source, const MeshSourceLines& lines) {
    detail::requireWellFormed(mesh, source, lines);
    MeshRepairs r;
    r.weldTolerance = resolvedTolerance(mesh, weldTolerance);
    const std::size_t vertices = mesh.vertices.size(), faces = mesh.faces.size();
    VertexMap welded, removed;
    weldVertices(mesh, r.weldTolerance, &welded);  // also drops the faces it collapses: counted as degenerate below
    r.weldedVertices = vertices - mesh.vertices.size();
    const std::size_t collapsed = faces - mesh.faces.size();
    r.degenerateFaces = collapsed + dropDegenerateFaces(mesh);
    r.duplicateFaces = dropDuplicateFaces(mesh.faces);
    r.flippedFaces = orientConsistently(mesh.faces, r.nonOrientablePieces);
    r.unreferencedVertices = removeUnreferencedVertices(mesh, removed);
    if (mesh.faces.empty()) {
        std::ostringstream text;
        text << "no face is left after dropping the degenerate and duplicate ones";
        if (r.weldedVertices > 0)  // the near-duplicate weld scales with the mesh: one vertex far out makes it swallow the rest
            text << " (" << plural(r.weldedVertices, "vertex", "vertices") << " welded within " << r.weldTolerance
                 << ", a share of the mesh's size: a vertex far from the others makes that size, and the weld, huge)";
        throw InputError(source, 0, text.str());
    }
    if (r.weldedVertices > 0 || r.unreferencedVertices > 0) {
        r.vertexMap = std::move(welded);
        composeVertexMap(r.vertexMap, removed);
    }
    return r;
}

void requireNoDefects(const TriMesh& mesh, double weldTolerance, const std::string& source, const MeshSourceLines& lines) {
    validateMesh(mesh, source, lines);  // corrupt input, degenerate and duplicate faces
    const double tolerance = resolvedTolerance(mesh, weldTolerance);
    const std::vector<Index> target = weldTargets(mesh.vertices, tolerance);
    for (std::size_t v = 0; v < target.size(); ++v)
        if (target[v] != Index(v)) {
            std::ostringstream text;
            text << vertexText(Index(v), lines) << " is within " << tolerance << " of " << vertexText(target[v], lines)
                 << ": near-duplicate positions (a crack in the surface)";
            throw InputError(source, lineOf(lines.vertexLine, v), text.str());
        }
    const std::vector<bool> used = referenced(mesh);
    for (std::size_t v = 0; v < used.size(); ++v)
        if (!used[v]) throw InputError(source, lineOf(lines.vertexLine, v), vertexText(Index(v), lines) + " is used by no face");
    const std::vector<EdgeUse> uses = edgeUses(mesh.faces);
    std::size_t worst = mesh.faces.size();  // the inconsistent pair whose later face comes first
    std::size_t other = 0;
    std::uint64_t edge = 0;
    for (std::size_t i = 0; i + 1 < uses.size(); ++i) {
        const bool pair = uses[i + 1].key == uses[i].key && (i + 2 >= uses.size() || uses[i + 2].key != uses[i].key) &&
                          (i == 0 || uses[i - 1].key != uses[i].key);
        if (!pair || uses[i].forward != uses[i + 1].forward) continue;
        const std::size_t later = std::max(uses[i].face, uses[i + 1].face);
        if (later < worst) {
            worst = later;
            other = std::min(uses[i].face, uses[i + 1].face);
            edge = uses[i].key;
        }
    }
    if (worst < mesh.faces.size())
        throw InputError(source, lineOf(lines.faceLine, worst),
                         faceText(worst, mesh.faces[worst]) + " runs its edge (" + std::to_string(edge >> 32) + " " +
                             std::to_string(edge & 0xffffffffu) + ") the same way as face " + std::to_string(other) +
                             ": inconsistent winding");
}

}  // namespace flexfit
