// The OFF reader: the file's own vertex order, in double precision, with the line of every
// problem. (assimp's OFF importer gives one vertex per face corner, welded back in first-use
// order, in single precision, and drops unused vertices: a user's vertex 574 would not be
// mass 574.)
//
// Read (Geomview's OFF, one record per line): an optional header keyword `[ST][C][N]OFF`,
// or `nOFF` followed by the dimension 3 (ModelNet's `OFF490 518 0` too); the counts
// `vertices faces [edges]` (on the header line, the next, or split over two); one vertex per line, `x y z` and whatever the keyword's prefixes add
// (texture coordinates, colour, normal: ignored); one face per line, `n i_1 ... i_n` with
// 0-based indices and an optional colour after them (ignored). Polygons are triangulated as the
// OBJ reader does. `#` starts a comment. Refused, each with its line: binary OFF, 4D and other
// dimensions, counts that are not non-negative integers, a file that ends before its counts'
// worth of vertices and faces or goes on after them, faces of fewer than 3 corners or with an
// index out of range. Positions the file repeats are welded into their first, with a warning.
#include "flexfit/mesh_io.hpp"
#include "io_internal.hpp"
#include "polygons.hpp"
#include "text_lines.hpp"

#include <charconv>
#include <cstdint>
#include <limits>
#include <optional>

namespace flexfit {
namespace {

using detail::quoted;

// The next line with a token left once its comment is cut; false at the end of the file.
bool nextRecord(detail::LineCursor& cursor, detail::TextLine& line) {
    while (cursor.next(line)) {
        detail::cutComment(line);
        if (!line.tokens.empty()) return true;
    }
    return false;
}

std::optional<std::int64_t> integer(std::string_view token) {
    std::int64_t value = 0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size()) return std::nullopt;
    return value;
}

std::int64_t count(std::string_view token, const char* what, const std::string& source, std::size_t line) {
    const std::optional<std::int64_t> value = integer(token);
    if (!value || *value < 0) throw InputError(source, line, std::string("the ") + what + " count " + quoted(token) + " is not an integer >= 0");
    return *value;
}

// The header keyword's prefixes: what each vertex line carries beyond x y z does not matter,
// as only the first three numbers are read; the dimension does.
bool isHeader(std::string_view token) {
    if (token.size() < 3 || token.substr(token.size() - 3) != "OFF") return false;
    const std::string_view prefixes = token.substr(0, token.size() - 3);
    return prefixes.find_first_not_of("STCN4n") == std::string_view::npos;
}

// The counts' tokens: what follows the header keyword (and the dimension of nOFF) on its line,
// else the next record. `line` is left at the record the counts came from.
std::vector<std::string_view> headerAndCounts(detail::LineCursor& cursor, detail::TextLine& line, const std::string& source) {
    if (!nextRecord(cursor, line)) throw InputError(source, 0, "empty file");
    std::vector<std::string_view> rest = line.tokens;
    // ModelNet's files run the keyword into the vertex count: `OFF490 518 0`.
    if (const std::size_t digits = rest[0].find_first_of("0123456789"); digits != std::string_view::npos && digits > 0 &&
                                                                          isHeader(rest[0].substr(0, digits))) {
        rest.insert(rest.begin() + 1, rest[0].substr(digits));
        rest[0] = rest[0].substr(0, digits);
    }
    if (!isHeader(rest[0])) {
        if (!integer(rest[0])) throw InputError(source, line.number, "not an OFF file: it starts with " + quoted(rest[0]) + ", not OFF");
        return rest;  // no keyword: the counts come first
    }
    const std::string_view keyword = rest[0];
    rest.erase(rest.begin());
    if (keyword.find('4') != std::string_view::npos)
        throw InputError(source, line.number, quoted(keyword) + " is a 4D OFF file: only 3D surfaces can be read");
    if (keyword.find('n') != std::string_view::npos) {
        if (rest.empty() && nextRecord(cursor, line)) rest = line.tokens;
        const std::optional<std::int64_t> dimension = rest.empty() ? std::nullopt : integer(rest[0]);
        if (dimension != 3)
            throw InputError(source, line.number, quoted(keyword) + " needs its dimension, and only 3 can be read" +
                                                      (rest.empty() ? std::string() : ", found " + quoted(rest[0])));
        rest.erase(rest.begin());
    }
    if (!rest.empty() && rest[0] == "BINARY") throw InputError(source, line.number, "binary OFF is not supported: write it as text");
    if (rest.empty()) {
        if (!nextRecord(cursor, line)) throw InputError(source, line.number, "the file ends before the vertex and face counts");
        rest = line.tokens;
    }
    return rest;
}

}  // namespace

MeshReadResult parseOff(std::string_view text, const std::string& source, const MeshReadOptions& options) {
    detail::LineCursor cursor(text);
    detail::TextLine line;
    std::vector<std::string_view> counts = headerAndCounts(cursor, line, source);
    if (counts.size() < 2 && nextRecord(cursor, line)) counts.insert(counts.end(), line.tokens.begin(), line.tokens.end());  // split over lines
    if (counts.size() < 2) throw InputError(source, line.number, "expected the vertex and face counts, found one number");
    const std::int64_t vertexCount = count(counts[0], "vertex", source, line.number);
    const std::int64_t faceCount = count(counts[1], "face", source, line.number);
    if (counts.size() > 2) count(counts[2], "edge", source, line.number);  // checked, not used
    if (vertexCount > std::int64_t(std::numeric_limits<Index>::max()))
        throw InputError(source, line.number, std::to_string(vertexCount) + " vertices exceed the supported maximum");

    TriMesh mesh;
    MeshSourceLines lines;
    for (std::int64_t v = 0; v < vertexCount; ++v) {
        if (!nextRecord(cursor, line))
            throw InputError(source, cursor.lineNumber(), "the file ends after " + std::to_string(v) + " of its " + std::to_string(vertexCount) + " vertices");
        if (line.tokens.size() < 3)
            throw InputError(source, line.number, "a vertex needs 3 coordinates, found " + std::to_string(line.tokens.size()));
        mesh.vertices.emplace_back(detail::parseCoordinate(line.tokens[0], source, line.number),
                                   detail::parseCoordinate(line.tokens[1], source, line.number),
                                   detail::parseCoordinate(line.tokens[2], source, line.number));
        lines.vertexLine.push_back(line.number);
    }
    std::vector<Index> corners;
    std::size_t fanned = 0;
    for (std::int64_t f = 0; f < faceCount; ++f) {
        if (!nextRecord(cursor, line))
            throw InputError(source, cursor.lineNumber(), "the file ends after " + std::to_string(f) + " of its " + std::to_string(faceCount) + " faces");
        const std::optional<std::int64_t> n = integer(line.tokens[0]);
        if (!n) throw InputError(source, line.number, "a face starts with its corner count, found " + quoted(line.tokens[0]));
        if (*n < 3) throw InputError(source, line.number, "a face needs 3 corners, found " + std::to_string(*n));
        if (std::int64_t(line.tokens.size()) - 1 < *n)
            throw InputError(source, line.number, "the face has " + std::to_string(*n) + " corners but lists " + std::to_string(line.tokens.size() - 1));
        corners.clear();
        for (std::int64_t k = 1; k <= *n; ++k) {
            const std::string_view token = line.tokens[std::size_t(k)];
            const std::optional<std::int64_t> index = integer(token);
            if (!index) throw InputError(source, line.number, "face corner " + quoted(token) + " is not a vertex index");
            if (*index < 0 || *index >= vertexCount)
                throw InputError(source, line.number, "face corner " + std::to_string(*index) + " out of range (the file has " +
                                                          std::to_string(vertexCount) + " vertices, numbered from 0)");
            corners.push_back(Index(*index));
        }
        if (!detail::triangulatePolygon(mesh.vertices, corners, mesh.faces)) ++fanned;
        lines.faceLine.resize(mesh.faces.size(), line.number);
    }
    if (nextRecord(cursor, line))
        throw InputError(source, line.number, "more data after the " + std::to_string(vertexCount) + " vertices and " + std::to_string(faceCount) +
                                                  " faces the counts declare");
    return finishPolygonRead(std::move(mesh), source, lines, options, fanned);
}

MeshReadResult readOff(const std::filesystem::path& path, const MeshReadOptions& options) { return readTextMesh(path, options, parseOff); }

}  // namespace flexfit
