// The OBJ reader: the file's own vertex order, in double precision, with the line of every
// problem. (assimp's OBJ importer gives one vertex per face corner, welded back in first-use
// order, in single precision: a user's vertex 574 would not be mass 574.)
//
// Read: `v x y z` (a 4th weight or 3 colour values are ignored), `f` with corners `i`, `i/t`,
// `i//n` or `i/t/n` (1-based; negative: relative to the last vertex read; positive indices may
// refer forward), polygons of more than 3 corners triangulated in their own plane (Newell's
// normal): a convex one as a fan from its first corner, a concave one by ear clipping (a
// self-intersecting one, which has no proper triangulation, as a fan). Ignored: comments (`#` to the end of any line), texture
// coordinates and normals, groups, objects, smoothing groups, materials. A `\` ending a line
// continues the statement on the next (problems are named at its first line). Refused: points
// and lines (`p`, `l`) and free-form geometry, which cannot be triangulated.
#include "flexfit/mesh_io.hpp"
#include "io_internal.hpp"
#include "polygons.hpp"
#include "text_lines.hpp"

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

// The next statement: a line with its comment cut, and the lines a trailing `\` continues it
// on. False at the end of the text.
bool nextStatement(detail::LineCursor& cursor, detail::TextLine& statement) {
    if (!cursor.next(statement)) return false;
    detail::cutComment(statement);  // `f 1 2 3 # a note` is a face
    detail::TextLine more;
    while (!statement.tokens.empty() && statement.tokens.back().ends_with('\\')) {
        std::string_view& last = statement.tokens.back();
        last.remove_suffix(1);
        if (last.empty()) statement.tokens.pop_back();
        if (!cursor.next(more)) break;
        detail::cutComment(more);
        statement.tokens.insert(statement.tokens.end(), more.tokens.begin(), more.tokens.end());
    }
    return true;
}

}  // namespace

MeshReadResult parseObj(std::string_view text, const std::string& source, const MeshReadOptions& options) {
    if (text.find_first_not_of(" \t\r\n\v\f") == std::string_view::npos) throw InputError(source, 0, "empty file");
    detail::LineCursor cursor(text);
    TriMesh mesh;
    MeshSourceLines lines;
    std::vector<RawPolygon> polygons;
    for (detail::TextLine line; nextStatement(cursor, line);) {
        if (line.tokens.empty()) continue;
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
        if (!detail::triangulatePolygon(mesh.vertices, corners, mesh.faces)) ++fanned;
        lines.faceLine.resize(mesh.faces.size(), polygon.line);
    }
    return finishPolygonRead(std::move(mesh), source, lines, options, fanned);
}

MeshReadResult readObj(const std::filesystem::path& path, const MeshReadOptions& options) { return readTextMesh(path, options, parseObj); }

}  // namespace flexfit
