// The OBJ reader: the file's own vertex order, in double precision, with the line of every
// problem. (assimp's OBJ importer gives one vertex per face corner, welded back in first-use
// order, in single precision: a user's vertex 574 would not be mass 574.)
//
// Read: `v x y z` (a 4th weight or 3 colour values are ignored), `f` with corners `i`, `i/t`,
// `i//n` or `i/t/n` (1-based; negative: relative to the last vertex read; positive indices may
// refer forward), polygons of more than 3 corners triangulated in their own plane (Newell's
// normal): a convex one as a fan from its first corner, a concave one by ear clipping (a
// self-intersecting one, which has no proper triangulation, as a fan). Ignored: comments, texture
// coordinates and normals, groups, objects, smoothing groups, materials. Refused: points and
// lines (`p`, `l`) and free-form geometry, which cannot be triangulated.
#include "flexfit/mesh_io.hpp"
#include "io_internal.hpp"
#include "text_lines.hpp"

#include <Eigen/Core>

#include <array>
#include <span>
#include <fstream>
#include <limits>
#include <sstream>

namespace flexfit {
namespace {

using detail::quoted;

// A corner's vertex index (the part before the first '/'), 0-based: absolute, or relative to
// `vertexCount` vertices read so far when negative.
std::int64_t cornerIndex(std::string_view corner, std::size_t vertexCount, const std::string& source, std::size_t line) {
    const std::string_view digits = corner.substr(0, corner.find('/'));
    std::int64_t value = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec != std::errc() || end != digits.data() + digits.size() || digits.empty())
        throw InputError(source, line, "face corner " + quoted(corner) + " is not a vertex index");
    if (value == 0) throw InputError(source, line, "face corner " + quoted(corner) + ": OBJ indices start at 1");
    if (value > 0) return value - 1;
    const std::int64_t absolute = std::int64_t(vertexCount) + value;
    if (absolute < 0)
        throw InputError(source, line, "face corner " + quoted(corner) + " refers before the first vertex (" + std::to_string(vertexCount) +
                                           " vertices read so far)");
    return absolute;
}

bool freeForm(std::string_view keyword) {
    for (std::string_view k : {"cstype", "curv", "curv2", "surf", "bmat", "step", "deg", "parm", "trim", "hole"})
        if (keyword == k) return true;
    return false;
}

struct RawPolygon {
    std::vector<std::int64_t> corners;  // 0-based, not yet checked against the vertex count
    std::size_t line;
};

void readFace(const detail::TextLine& line, std::size_t vertexCount, const std::string& source, std::vector<RawPolygon>& polygons) {
    const std::size_t n = line.tokens.size() - 1;
    if (n < 3) throw InputError(source, line.number, "a face needs 3 corners, found " + std::to_string(n));
    RawPolygon polygon{std::vector<std::int64_t>(n), line.number};
    for (std::size_t k = 0; k < n; ++k) polygon.corners[k] = cornerIndex(line.tokens[k + 1], vertexCount, source, line.number);
    polygons.push_back(std::move(polygon));
}

// The polygon in 2D: its plane's dominant axis dropped, oriented so that its own turning
// direction is counter-clockwise.
std::vector<Eigen::Vector2d> projected(const std::vector<Vec3>& vertices, std::span<const Index> corners) {
    Vec3 normal = Vec3::Zero();  // Newell's
    for (std::size_t i = 0; i < corners.size(); ++i) normal += vertices[corners[i]].cross(vertices[corners[(i + 1) % corners.size()]]);
    int axis = 0;
    normal.cwiseAbs().maxCoeff(&axis);
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    const double flip = normal[axis] < 0.0 ? -1.0 : 1.0;
    std::vector<Eigen::Vector2d> out;
    for (Index v : corners) out.emplace_back(vertices[v][a], flip * vertices[v][b]);
    return out;
}

double turn(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    const Eigen::Vector2d u = q - p, w = r - q;
    return u.x() * w.y() - u.y() * w.x();
}

bool inTriangle(const Eigen::Vector2d& x, const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    return turn(p, q, x) >= 0.0 && turn(q, r, x) >= 0.0 && turn(r, p, x) >= 0.0;
}

// Ear clipping; false when no ear is left (a self-intersecting or degenerate polygon).
bool clipEars(std::span<const Index> corners, const std::vector<Eigen::Vector2d>& p, std::vector<Face>& out) {
    std::vector<std::size_t> left(corners.size());
    for (std::size_t i = 0; i < left.size(); ++i) left[i] = i;
    while (left.size() > 3) {
        const std::size_t m = left.size();
        bool clipped = false;
        for (std::size_t i = 0; i < m && !clipped; ++i) {
            const std::size_t a = left[(i + m - 1) % m], b = left[i], c = left[(i + 1) % m];
            if (turn(p[a], p[b], p[c]) <= 0.0) continue;  // reflex or flat: not an ear
            bool blocked = false;
            for (std::size_t j : left) {  // a corner met twice (a bridged hole) does not block its own ear
                const Index v = corners[j];
                if (v != corners[a] && v != corners[b] && v != corners[c] && inTriangle(p[j], p[a], p[b], p[c])) blocked = true;
            }
            if (blocked) continue;
            out.push_back({corners[a], corners[b], corners[c]});
            left.erase(left.begin() + std::ptrdiff_t(i));
            clipped = true;
        }
        if (!clipped) return false;
    }
    out.push_back({corners[left[0]], corners[left[1]], corners[left[2]]});
    return true;
}

// Triangles of one polygon, in its winding. False when it had to be split as a fan though it is
// not convex (self-intersecting or flat: no ear left), which the reader reports.
bool triangulate(const std::vector<Vec3>& vertices, std::span<const Index> corners, std::vector<Face>& out) {
    const auto fan = [&] {
        for (std::size_t k = 1; k + 1 < corners.size(); ++k) out.push_back({corners[0], corners[k], corners[k + 1]});
        return true;
    };
    if (corners.size() == 3) return fan();
    const std::vector<Eigen::Vector2d> p = projected(vertices, corners);
    bool convex = true;
    // Strictly convex: a corner on a straight edge (a T-junction) would give the fan a flat triangle.
    for (std::size_t i = 0; i < p.size() && convex; ++i) convex = turn(p[i], p[(i + 1) % p.size()], p[(i + 2) % p.size()]) > 0.0;
    if (convex) return fan();
    const std::size_t before = out.size();
    if (clipEars(corners, p, out)) return true;
    out.resize(before);
    fan();
    return false;
}

}  // namespace

MeshReadResult parseObj(std::string_view text, const std::string& source, const MeshReadOptions& options) {
    if (text.find_first_not_of(" \t\r\n\v\f") == std::string_view::npos) throw InputError(source, 0, "empty file");
    detail::LineCursor cursor(text);
    TriMesh mesh;
    MeshSourceLines lines;
    std::vector<RawPolygon> polygons;
    for (detail::TextLine line; cursor.next(line);) {
        const std::string_view keyword = line.tokens[0];
        if (keyword == "v") {
            if (line.tokens.size() < 4)
                throw InputError(source, line.number, "a vertex needs 3 coordinates, found " + std::to_string(line.tokens.size() - 1));
            mesh.vertices.emplace_back(detail::parseCoordinate(line.tokens[1], source, line.number),
                                       detail::parseCoordinate(line.tokens[2], source, line.number),
                                       detail::parseCoordinate(line.tokens[3], source, line.number));
            lines.vertexLine.push_back(line.number);
        } else if (keyword == "f" || keyword == "fo") {
            readFace(line, mesh.vertices.size(), source, polygons);
        } else if (keyword == "p" || keyword == "l") {
            throw InputError(source, line.number, "'" + std::string(keyword) + "' elements are points and lines: they cannot be triangulated");
        } else if (freeForm(keyword)) {
            throw InputError(source, line.number, "free-form geometry ('" + std::string(keyword) + "') cannot be triangulated");
        }
    }
    if (mesh.vertices.size() > std::numeric_limits<Index>::max())
        throw InputError(source, 0, std::to_string(mesh.vertices.size()) + " vertices exceed the supported maximum");
    std::vector<Index> corners;
    std::size_t fanned = 0;
    for (const RawPolygon& polygon : polygons) {
        corners.clear();
        for (const std::int64_t c : polygon.corners) {
            if (c >= std::int64_t(mesh.vertices.size()))
                throw InputError(source, polygon.line, "face corner " + std::to_string(c + 1) + " out of range (the file has " +
                                                           std::to_string(mesh.vertices.size()) + " vertices)");
            corners.push_back(Index(c));
        }
        if (!triangulate(mesh.vertices, corners, mesh.faces)) ++fanned;
        lines.faceLine.resize(mesh.faces.size(), polygon.line);
    }
    if (mesh.faces.empty()) throw InputError(source, 0, "empty mesh: no triangles");
    // Exporters that split vertices to carry normals or texture seams repeat positions: those
    // are welded as the format's welding (the rest keep the file's order and their lines).
    const std::vector<Index> target = weldTargets(mesh.vertices, 0.0);
    std::size_t repeats = 0;
    for (std::size_t v = 0; v < target.size(); ++v) repeats += target[v] != v ? 1 : 0;
    MeshReadResult result = finishRead(std::move(mesh), source, lines, options, repeats > 0);
    if (fanned > 0)
        result.diagnostics.warnings.insert(result.diagnostics.warnings.begin(),
                                           std::to_string(fanned) + " polygons cross themselves (or are flat) and were split as fans: "
                                           "their triangles may overlap");
    if (repeats > 0)
        result.diagnostics.warnings.insert(result.diagnostics.warnings.begin(),
                                           std::to_string(repeats) + " vertices repeat an earlier one's position (split normals or "
                                           "texture seams) and were welded into it: vertex indices (scene masses, frames) are the welded mesh's, "
                                           "not the file's (flexfit convert writes that mesh)");
    return result;
}

MeshReadResult readObj(const std::filesystem::path& path, const MeshReadOptions& options) {
    MeshReadResult result = parseObj(detail::readTextFile(path), path.string(), options);
    result.mesh.name = path.stem().string();
    return result;
}

}  // namespace flexfit
