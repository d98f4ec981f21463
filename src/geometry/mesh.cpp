#include "flexfit/mesh.hpp"
#include "geometry/mesh_checks.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cmath>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace flexfit {

namespace detail {

std::size_t lineOf(const std::vector<std::size_t>& lines, std::size_t i) { return i < lines.size() ? lines[i] : 0; }

std::string faceText(std::size_t f, const Face& face) {
    return "face " + std::to_string(f) + " (" + std::to_string(face[0]) + " " + std::to_string(face[1]) + " " + std::to_string(face[2]) + ")";
}

void requireWorkableScale(const TriMesh& mesh, const std::string& source, const MeshSourceLines& lines) {
    std::size_t largest = 0;
    double magnitude = 0.0;
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
        if (const double m = mesh.vertices[v].cwiseAbs().maxCoeff(); m > magnitude) largest = v, magnitude = m;
    std::ostringstream problem;
    if (magnitude > kMaxMeshCoordinate) {
        problem << "vertex " << largest << " has a coordinate of magnitude " << magnitude << ", beyond the " << kMaxMeshCoordinate
                << " units Flexfit computes with (products of coordinates would overflow): rescale the mesh (a unit mistaken?)";
        throw InputError(source, lineOf(lines.vertexLine, largest), problem.str());
    }
    if (const double size = boundingBox(mesh).diagonal().norm(); size < kMinMeshSize) {
        problem << "the mesh's size (its bounding-box diagonal) is " << size << ", below the " << kMinMeshSize
                << " units Flexfit computes with (products of coordinates would underflow): rescale the mesh (a unit mistaken?)";
        throw InputError(source, 0, problem.str());
    }
}

void requireWellFormed(const TriMesh& mesh, const std::string& source, const MeshSourceLines& lines) {
    if (mesh.vertices.empty()) throw InputError(source, 0, "empty mesh: no vertices");
    if (mesh.faces.empty()) throw InputError(source, 0, "empty mesh: no faces");
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
        if (!mesh.vertices[v].allFinite())
            throw InputError(source, lineOf(lines.vertexLine, v), "vertex " + std::to_string(v) + " has a NaN or infinite coordinate");
    requireWorkableScale(mesh, source, lines);
    if (const auto beyond = firstIndexBeyond(mesh.faces, mesh.vertices.size())) {
        const auto [f, idx] = *beyond;
        throw InputError(source, lineOf(lines.faceLine, f),
                         faceText(f, mesh.faces[f]) + ": index " + std::to_string(idx) + " out of range (the mesh has " +
                             std::to_string(mesh.vertices.size()) + " vertices)");
    }
}

double areaScale(const TriMesh& mesh) {
    const double diagonal = boundingBox(mesh).diagonal().stableNorm();  // no over/underflow
    return diagonal > 0.0 ? 1.0 / diagonal : 1.0;
}

bool hasZeroArea(const TriMesh& mesh, const Face& face, double scale) {
    // Edges are scaled by the bounding-box diagonal first, so the test is relative and neither
    // underflows for tiny meshes nor overflows for huge ones.
    const Vec3& a = mesh.vertices[face[0]];
    const Vec3 ab = (mesh.vertices[face[1]] - a) * scale, ac = (mesh.vertices[face[2]] - a) * scale;
    return !(ab.cross(ac).norm() > 2e-12);
}

}  // namespace detail

using detail::faceText;
using detail::lineOf;

namespace {

void checkFaceIndices(const TriMesh& mesh, const std::string& source, const MeshSourceLines& lines) {
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
        const Face& face = mesh.faces[f];
        if (face[0] == face[1] || face[1] == face[2] || face[0] == face[2])
            throw InputError(source, lineOf(lines.faceLine, f), faceText(f, face) + " is degenerate: repeated vertex");
    }
}

void checkFaceAreas(const TriMesh& mesh, const std::string& source, const MeshSourceLines& lines) {
    const double scale = detail::areaScale(mesh);
    for (std::size_t f = 0; f < mesh.faces.size(); ++f)
        if (detail::hasZeroArea(mesh, mesh.faces[f], scale))
            throw InputError(source, lineOf(lines.faceLine, f), faceText(f, mesh.faces[f]) + " is degenerate: zero area");
}

void checkDuplicateFaces(const TriMesh& mesh, const std::string& source, const MeshSourceLines& lines) {
    std::vector<std::pair<Face, std::size_t>> sorted;
    sorted.reserve(mesh.faces.size());
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
        Face key = mesh.faces[f];
        std::sort(key.begin(), key.end());
        sorted.emplace_back(key, f);
    }
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t i = 1; i < sorted.size(); ++i) {
        if (sorted[i].first != sorted[i - 1].first) continue;
        const std::size_t first = sorted[i - 1].second, second = sorted[i].second;
        std::string where = "face " + std::to_string(first);
        if (lineOf(lines.faceLine, first) > 0) where += " (line " + std::to_string(lines.faceLine[first]) + ")";
        throw InputError(source, lineOf(lines.faceLine, second),
                         faceText(second, mesh.faces[second]) + " duplicates " + where);
    }
}

void countEdges(const TriMesh& mesh, MeshDiagnostics& diagnostics) {
    std::vector<std::uint64_t> keys;
    keys.reserve(mesh.faces.size() * 3);
    for (const Face& face : mesh.faces)
        for (int e = 0; e < 3; ++e) {
            const Index a = std::min(face[e], face[(e + 1) % 3]), b = std::max(face[e], face[(e + 1) % 3]);
            keys.push_back((std::uint64_t(a) << 32) | b);
        }
    std::sort(keys.begin(), keys.end());
    for (std::size_t i = 0; i < keys.size();) {
        std::size_t j = i;
        while (j < keys.size() && keys[j] == keys[i]) ++j;
        ++diagnostics.edgeCount;
        if (j - i == 1) ++diagnostics.boundaryEdges;
        if (j - i >= 3) ++diagnostics.nonManifoldEdges;
        i = j;
    }
}

}  // namespace

Eigen::AlignedBox3d boundingBox(const TriMesh& mesh) {
    Eigen::AlignedBox3d box;
    for (const Vec3& v : mesh.vertices) box.extend(v);
    return box;
}

MeshDiagnostics validateMesh(const TriMesh& mesh, const std::string& source, const MeshSourceLines& lines) {
    detail::requireWellFormed(mesh, source, lines);
    checkFaceIndices(mesh, source, lines);
    checkFaceAreas(mesh, source, lines);
    checkDuplicateFaces(mesh, source, lines);

    MeshDiagnostics diagnostics;
    countEdges(mesh, diagnostics);
    std::vector<unsigned char> used(mesh.vertices.size(), 0);
    for (const Face& face : mesh.faces)
        for (Index v : face) used[v] = 1;
    diagnostics.unreferencedVertices = std::size_t(std::count(used.begin(), used.end(), 0));

    if (diagnostics.boundaryEdges > 0)
        diagnostics.warnings.push_back(std::to_string(diagnostics.boundaryEdges) +
                                       " boundary edges: the surface is open");
    if (diagnostics.nonManifoldEdges > 0)
        diagnostics.warnings.push_back(std::to_string(diagnostics.nonManifoldEdges) +
                                       " non-manifold edges (shared by three or more faces)");
    if (diagnostics.unreferencedVertices > 0)
        diagnostics.warnings.push_back(std::to_string(diagnostics.unreferencedVertices) +
                                       " vertices used by no face: they become free masses with no spring");
    return diagnostics;
}

namespace {

// Exact mode: vertices whose coordinates are equal (0.0 and -0.0 alike; NaN equal to nothing),
// found by sorting their bit patterns. Each joins the first of its group in input order.
std::vector<Index> identicalPositions(std::span<const Vec3> vertices) {
    using Key = std::array<std::uint64_t, 3>;
    auto keyOf = [](const Vec3& p) {
        return Key{std::bit_cast<std::uint64_t>(p.x() + 0.0), std::bit_cast<std::uint64_t>(p.y() + 0.0), std::bit_cast<std::uint64_t>(p.z() + 0.0)};
    };
    std::vector<std::pair<Key, Index>> order(vertices.size());
    for (std::size_t v = 0; v < vertices.size(); ++v) order[v] = {keyOf(vertices[v]), Index(v)};
    std::sort(order.begin(), order.end());  // by position, then index: a group's first is the earliest
    std::vector<Index> first(vertices.size());
    for (std::size_t i = 0; i < order.size(); ++i) {
        const Index v = order[i].second;
        const bool joins = i > 0 && order[i].first == order[i - 1].first && !vertices[v].hasNaN();
        first[v] = joins ? first[order[i - 1].second] : v;
    }
    return first;
}

// Tolerance mode: a hash grid with cells of the tolerance's size; each vertex is compared with
// the kept vertices in the 27 surrounding cells (each cell's in the order they were kept) and
// joins the first one found within the tolerance.
std::vector<Index> positionsWithin(std::span<const Vec3> vertices, double tolerance) {
    struct CellHash {
        std::size_t operator()(const std::array<std::int64_t, 3>& c) const {
            // Unsigned arithmetic: wraps instead of overflowing for far-away cells.
            return std::size_t(std::uint64_t(c[0]) * 73856093u) ^ std::size_t(std::uint64_t(c[1]) * 19349663u) ^
                   std::size_t(std::uint64_t(c[2]) * 83492791u);
        }
    };
    constexpr Index kNone = Index(-1);
    // A cell's kept vertices as a list threaded through `next`: no allocation per cell.
    std::unordered_map<std::array<std::int64_t, 3>, std::pair<Index, Index>, CellHash> cells;  // first, last
    cells.reserve(vertices.size());
    std::vector<Index> next(vertices.size(), kNone), first(vertices.size());
    auto cellOf = [&](const Vec3& p) {
        // Clamped so that huge or non-finite coordinates never overflow the integer cast.
        auto axis = [&](double x) {
            const double c = std::floor(x / tolerance);
            return std::int64_t(std::isfinite(c) ? std::clamp(c, -1e15, 1e15) : 0.0);
        };
        return std::array<std::int64_t, 3>{axis(p.x()), axis(p.y()), axis(p.z())};
    };
    for (std::size_t v = 0; v < vertices.size(); ++v) {
        const Vec3& p = vertices[v];
        const auto c = cellOf(p);
        Index match = kNone;
        for (int dx = -1; dx <= 1 && match == kNone; ++dx)
            for (int dy = -1; dy <= 1 && match == kNone; ++dy)
                for (int dz = -1; dz <= 1 && match == kNone; ++dz) {
                    const auto it = cells.find({c[0] + dx, c[1] + dy, c[2] + dz});
                    if (it == cells.end()) continue;
                    for (Index k = it->second.first; k != kNone; k = next[k])
                        if ((vertices[k] - p).norm() <= tolerance) {
                            match = k;
                            break;
                        }
                }
        if (match != kNone) {
            first[v] = match;
            continue;
        }
        first[v] = Index(v);
        const auto [it, inserted] = cells.try_emplace(c, Index(v), Index(v));
        if (!inserted) {
            next[it->second.second] = Index(v);
            it->second.second = Index(v);
        }
    }
    return first;
}

}  // namespace

std::vector<Index> weldTargets(std::span<const Vec3> vertices, double tolerance) {
    return tolerance > 0 ? positionsWithin(vertices, tolerance) : identicalPositions(vertices);
}

void composeVertexMap(VertexMap& map, const VertexMap& then) {
    for (std::size_t i = 0; i < map.size(); ++i)
        if (map[i] != kNoVertex && map[i] >= then.size())
            throw InputError("vertex map", 0, "composeVertexMap: entry " + std::to_string(i) + " is " + std::to_string(map[i]) +
                                                  ", beyond the second map's " + std::to_string(then.size()) + " entries");
    for (Index& v : map)
        if (v != kNoVertex) v = then[v];
}

std::optional<std::pair<std::size_t, Index>> firstIndexBeyond(std::span<const Face> faces, std::size_t vertexCount) {
    for (std::size_t f = 0; f < faces.size(); ++f)
        for (const Index v : faces[f])
            if (v >= vertexCount) return std::pair{f, v};
    return std::nullopt;
}

void checkFileVertices(const FileVertices& file, std::size_t meshVertexCount) {
    const auto fail = [](const std::string& problem) { throw InputError("file vertices", 0, problem); };
    if (file.positions.size() != file.count())
        fail(std::to_string(file.count()) + " file vertices but " + std::to_string(file.positions.size()) + " positions");
    for (std::size_t u = 0; u < file.count(); ++u) {
        if (file.meshVertex[u] != kNoVertex && file.meshVertex[u] >= meshVertexCount)
            fail("file vertex " + std::to_string(u) + " goes to vertex " + std::to_string(file.meshVertex[u]) + ", out of range (the mesh has " +
                 std::to_string(meshVertexCount) + ")");
        if (!file.positions[u].allFinite()) fail("file vertex " + std::to_string(u) + " has a non-finite position");
    }
}

VertexMap firstFileVertices(const FileVertices& file, std::size_t meshVertexCount) {
    checkFileVertices(file, meshVertexCount);
    VertexMap first(meshVertexCount, kNoVertex);
    for (std::size_t i = file.count(); i-- > 0;)
        if (const Index v = file.meshVertex[i]; v != kNoVertex) first[v] = Index(i);
    return first;
}

TriMesh inFileOrder(const TriMesh& mesh, const FileVertices& file) {
    if (file.empty()) return mesh;
    const VertexMap first = firstFileVertices(file, mesh.vertices.size());
    TriMesh out{mesh.name, file.positions, mesh.faces};
    for (std::size_t u = 0; u < file.count(); ++u)
        if (file.meshVertex[u] != kNoVertex) out.vertices[u] = mesh.vertices[file.meshVertex[u]];
    for (Face& f : out.faces)
        for (Index& v : f) v = first[v];
    return out;
}

std::size_t weldVertices(TriMesh& mesh, double tolerance, VertexMap* moved) {
    if (!(tolerance >= 0.0) || !std::isfinite(tolerance))
        throw InputError(mesh.name.empty() ? std::string("weld") : mesh.name, 0, "the weld tolerance must be finite and >= 0");
    if (const auto beyond = firstIndexBeyond(mesh.faces, mesh.vertices.size()))
        throw InputError(mesh.name.empty() ? std::string("weld") : mesh.name, 0,
                         "face " + std::to_string(beyond->first) + " names vertex " + std::to_string(beyond->second) + " of " +
                             std::to_string(mesh.vertices.size()));
    const std::vector<Index> target = weldTargets(mesh.vertices, tolerance);
    // Kept vertices in input order; every vertex maps to its target's new index.
    std::vector<Index> remap(mesh.vertices.size());
    std::vector<Vec3> kept;
    kept.reserve(mesh.vertices.size());
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
        if (target[v] == Index(v)) {
            remap[v] = Index(kept.size());
            kept.push_back(mesh.vertices[v]);
        } else {
            remap[v] = remap[target[v]];
        }
    }
    std::vector<Face> faces;
    faces.reserve(mesh.faces.size());
    for (const Face& face : mesh.faces) {
        const Face f{remap[face[0]], remap[face[1]], remap[face[2]]};
        if (f[0] != f[1] && f[1] != f[2] && f[0] != f[2]) faces.push_back(f);
    }
    const std::size_t collapsed = mesh.faces.size() - faces.size();
    mesh.vertices = std::move(kept);
    mesh.faces = std::move(faces);
    if (moved) *moved = std::move(remap);
    return collapsed;
}

}  // namespace flexfit
