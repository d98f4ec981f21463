// The `.tri` reader and writer (format in mesh_io.hpp).
#include "flexfit/mesh_io.hpp"
#include "flexfit/frame_export.hpp"
#include "io_internal.hpp"
#include "text_lines.hpp"

#include <charconv>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

namespace flexfit {
namespace {

using detail::LineCursor;
using detail::parseCoordinate;
using detail::quoted;
using Line = detail::TextLine;

std::uint64_t parseCount(std::string_view token, const std::string& source, std::size_t line, const char* what) {
    std::uint64_t value = 0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size())
        throw InputError(source, line, std::string(what) + " " + quoted(token) + " is not a non-negative integer");
    return value;
}

void readCounts(LineCursor& cursor, const std::string& source, std::uint64_t& vertexCount, std::uint64_t& faceCount) {
    Line line;
    if (!cursor.next(line)) throw InputError(source, cursor.lineNumber(), "unexpected end of file: expected the vertex and face counts");
    if (line.tokens.size() == 2) {
        vertexCount = parseCount(line.tokens[0], source, line.number, "vertex count");
        faceCount = parseCount(line.tokens[1], source, line.number, "face count");
        return;
    }
    if (line.tokens.size() != 1)
        throw InputError(source, line.number, "expected the vertex and face counts, found " + std::to_string(line.tokens.size()) + " values");
    vertexCount = parseCount(line.tokens[0], source, line.number, "vertex count");
    if (!cursor.next(line)) throw InputError(source, cursor.lineNumber(), "unexpected end of file: expected the face count");
    if (line.tokens.size() != 1)
        throw InputError(source, line.number, "expected the face count, found " + std::to_string(line.tokens.size()) + " values");
    faceCount = parseCount(line.tokens[0], source, line.number, "face count");
}

void readVertices(LineCursor& cursor, const std::string& source, std::uint64_t count, TriMesh& mesh, MeshSourceLines& lines) {
    Line line;
    for (std::uint64_t v = 0; v < count; ++v) {
        if (!cursor.next(line))
            throw InputError(source, cursor.lineNumber(), "unexpected end of file: the header announces " + std::to_string(count) +
                                                               " vertices, found " + std::to_string(v));
        if (line.tokens.size() != 3)
            throw InputError(source, line.number, "vertex " + std::to_string(v) + " needs 3 coordinates, found " +
                                                      std::to_string(line.tokens.size()) +
                                                      " values (do the header's counts match the file?)");
        mesh.vertices.emplace_back(parseCoordinate(line.tokens[0], source, line.number),
                                   parseCoordinate(line.tokens[1], source, line.number),
                                   parseCoordinate(line.tokens[2], source, line.number));
        lines.vertexLine.push_back(line.number);
    }
}

void readFaces(LineCursor& cursor, const std::string& source, std::uint64_t count, TriMesh& mesh, MeshSourceLines& lines) {
    Line line;
    for (std::uint64_t f = 0; f < count; ++f) {
        if (!cursor.next(line))
            throw InputError(source, cursor.lineNumber(), "unexpected end of file: the header announces " + std::to_string(count) +
                                                               " faces, found " + std::to_string(f));
        if (line.tokens.size() > 3)
            throw InputError(source, line.number, "face " + std::to_string(f) + " has " + std::to_string(line.tokens.size()) +
                                                      " indices: .tri faces are triangles");
        if (line.tokens.size() < 3)
            throw InputError(source, line.number, "face " + std::to_string(f) + " needs 3 vertex indices, found " +
                                                      std::to_string(line.tokens.size()));
        Face face{};
        for (int k = 0; k < 3; ++k) {
            const std::uint64_t index = parseCount(line.tokens[k], source, line.number, "vertex index");
            if (index >= mesh.vertices.size())
                throw InputError(source, line.number, "face " + std::to_string(f) + ": index " + std::to_string(index) +
                                                          " out of range (the mesh has " + std::to_string(mesh.vertices.size()) + " vertices)");
            face[k] = Index(index);
        }
        mesh.faces.push_back(face);
        lines.faceLine.push_back(line.number);
    }
}

std::string trimmed(std::string_view s) {
    std::size_t b = 0, e = s.size();
    while (b < e && (detail::isBlank(s[b]) || s[b] == '\n')) ++b;
    while (e > b && (detail::isBlank(s[e - 1]) || s[e - 1] == '\n')) --e;
    return std::string(s.substr(b, e - b));
}

}  // namespace

MeshReadResult parseTri(std::string_view text, const std::string& source, const MeshReadOptions& options) {
    if (text.find_first_not_of(" \t\r\n\v\f") == std::string_view::npos) throw InputError(source, 0, "empty file");
    LineCursor cursor(text);
    TriMesh mesh;
    mesh.name = trimmed(cursor.firstLine());
    std::uint64_t vertexCount = 0, faceCount = 0;
    readCounts(cursor, source, vertexCount, faceCount);
    if (vertexCount == 0) throw InputError(source, cursor.lineNumber(), "empty mesh: the vertex count is 0");
    if (faceCount == 0) throw InputError(source, cursor.lineNumber(), "empty mesh: the face count is 0");
    if (vertexCount > std::numeric_limits<Index>::max())
        throw InputError(source, cursor.lineNumber(), "vertex count " + std::to_string(vertexCount) + " exceeds the supported maximum");
    // Never trust the counts for allocation: a line holds at least 6 characters per record.
    mesh.vertices.reserve(std::min<std::uint64_t>(vertexCount, text.size() / 6 + 1));
    mesh.faces.reserve(std::min<std::uint64_t>(faceCount, text.size() / 6 + 1));
    MeshSourceLines lines;
    readVertices(cursor, source, vertexCount, mesh, lines);
    readFaces(cursor, source, faceCount, mesh, lines);
    Line extra;
    if (cursor.next(extra))
        throw InputError(source, extra.number, "unexpected data after the last face: the header's counts (" +
                                                   std::to_string(vertexCount) + " vertices, " + std::to_string(faceCount) +
                                                   " faces) do not match the file");
    return finishRead(std::move(mesh), source, lines, options, FormatWelding::None);  // .tri shares vertices: no format welding
}

MeshReadResult readTri(const std::filesystem::path& path, const MeshReadOptions& options) {
    return parseTri(detail::readTextDocument(path), path.string(), options);
}

std::string formatTri(const TriMesh& mesh) {
    std::string name = mesh.name.empty() ? "unnamed" : mesh.name;
    for (char& c : name)
        if (c == '\n' || c == '\r') c = ' ';
    std::string out = name + "\n" + std::to_string(mesh.vertices.size()) + " " + std::to_string(mesh.faces.size()) + "\n";
    char buffer[128];
    for (const Vec3& v : mesh.vertices) {
        std::snprintf(buffer, sizeof buffer, "%.17g %.17g %.17g\n", v.x(), v.y(), v.z());
        out += buffer;
    }
    for (const Face& f : mesh.faces) out += std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
    return out;
}

void writeTri(const TriMesh& mesh, const std::filesystem::path& path) {
    writeWholeFile(path, formatTri(mesh));
}

}  // namespace flexfit
