// Mesh import through assimp (OBJ, STL, PLY, OFF, glTF/GLB, and the rest assimp reads).
//
// The scene graph is flattened: every mesh instance is transformed by its node's world matrix
// and appended. Polygons are triangulated by assimp; point and line primitives cannot be and
// are rejected. Vertices are welded (exactly, or within the tolerance) because most formats
// split them per face corner.
#include "flexfit/mesh_io.hpp"
#include "io_internal.hpp"
#include "text_lines.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>

namespace flexfit {
namespace {

Eigen::Matrix4d toEigen(const aiMatrix4x4& m) {
    Eigen::Matrix4d out;
    out << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
    return out;
}

void appendMesh(const aiMesh& source, const Eigen::Matrix4d& transform, const std::string& file, TriMesh& out) {
    const Index base = Index(out.vertices.size());
    for (unsigned v = 0; v < source.mNumVertices; ++v) {
        const aiVector3D& p = source.mVertices[v];
        out.vertices.push_back((transform * Eigen::Vector4d(p.x, p.y, p.z, 1.0)).head<3>());
    }
    for (unsigned f = 0; f < source.mNumFaces; ++f) {
        const aiFace& face = source.mFaces[f];
        if (face.mNumIndices != 3)
            throw InputError(file, 0, "mesh '" + std::string(source.mName.C_Str()) + "' face " + std::to_string(f) + " has " +
                                          std::to_string(face.mNumIndices) +
                                          " vertices: points and lines cannot be triangulated");
        out.faces.push_back({base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    }
}

void appendNode(const aiScene& scene, const aiNode& node, const Eigen::Matrix4d& parent, const std::string& file, TriMesh& out) {
    const Eigen::Matrix4d world = parent * toEigen(node.mTransformation);
    for (unsigned i = 0; i < node.mNumMeshes; ++i) appendMesh(*scene.mMeshes[node.mMeshes[i]], world, file, out);
    for (unsigned i = 0; i < node.mNumChildren; ++i) appendNode(scene, *node.mChildren[i], world, file, out);
}

// A whole token that is a number assimp cannot hold: NaN, infinity, or beyond float range
// (assimp stores coordinates as 32-bit floats). Words that merely start with "inf" do not count.
bool isNonFiniteToken(std::string_view token) {
    double value = 0.0;
    const char* begin = token.data() + (token.size() > 1 && token[0] == '+' ? 1 : 0);
    const auto [end, ec] = std::from_chars(begin, token.data() + token.size(), value);
    if (end != token.data() + token.size()) return false;
    if (ec == std::errc::result_out_of_range) return true;
    return ec == std::errc() && !(std::abs(value) <= double(std::numeric_limits<float>::max()));
}

// First line of a text file holding a NaN/Inf token; 0 when none (binary files, or none found).
// Lines as the text readers count them (text_lines.hpp).
std::size_t lineOfNonFiniteToken(const std::filesystem::path& path) {
    std::ifstream file(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    detail::LineCursor cursor(text);
    detail::TextLine line;
    while (cursor.next(line))
        for (std::string_view token : line.tokens)
            if (isNonFiniteToken(token)) return line.number;
    return 0;
}

// An ASCII STL cut short still imports (assimp reads the facets it finds): a file that starts
// with "solid" and is not a binary STL by its size (84 + 50 n bytes, n at offset 80) must end
// with an "endsolid" line (indented or not; blanks, NULs and a DOS end-of-file byte after it
// are ignored). Reads the first 84 bytes and the last 4 KiB; the whole file only to name the
// line of a refusal.
void requireWholeAsciiStl(const std::filesystem::path& path) {
    std::error_code ec;
    if (lowerExtension(path) != ".stl" || !std::filesystem::is_regular_file(path, ec)) return;  // assimp names what else is wrong
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) return;
    std::ifstream in(path, std::ios::binary);
    std::string head(std::size_t(std::min<std::uintmax_t>(size, 84)), '\0');
    in.read(head.data(), std::streamsize(head.size()));
    const std::size_t first = head.find_first_not_of(" \t\r\n");
    if (first == std::string::npos || head.compare(first, 5, "solid") != 0) return;  // binary, or not an STL assimp reads as text
    if (head.size() == 84) {
        std::uint32_t facets = 0;
        std::memcpy(&facets, head.data() + 80, 4);
        if (size == 84 + 50 * std::uint64_t(facets)) return;  // binary, whatever its header says
    }
    const std::uintmax_t tailStart = size > 4096 ? size - 4096 : 0;
    std::string tail(std::size_t(size - tailStart), '\0');
    in.seekg(std::streamoff(tailStart));
    in.read(tail.data(), std::streamsize(tail.size()));
    constexpr std::string_view kTrailing(" \t\r\n\v\f\x1a\0", 8);
    const std::size_t last = tail.find_last_not_of(kTrailing);
    if (last != std::string::npos) {
        const std::size_t lineStart = tail.find_last_of("\r\n", last);
        const std::size_t start = tail.find_first_not_of(" \t", lineStart == std::string::npos ? 0 : lineStart + 1);
        if (tail.compare(start, 8, "endsolid") == 0) return;
    }
    std::ifstream whole(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(whole)), std::istreambuf_iterator<char>());
    // The last line with something on it, counted as the text readers count lines.
    detail::LineCursor cursor(std::string_view(text).substr(0, text.find_last_not_of(kTrailing) + 1));
    detail::TextLine line;
    std::size_t lastLine = 0;
    while (cursor.next(line)) lastLine = line.number;
    throw InputError(path.string(), lastLine, "the ASCII STL ends without an 'endsolid' line: the file is cut short");
}

}  // namespace

MeshReadResult readWithAssimp(const std::filesystem::path& path, const MeshReadOptions& options) {
    const std::string file = path.string();
    if (!std::filesystem::exists(path)) throw InputError(file, 0, "cannot open the file for reading: it does not exist");
    requireWholeAsciiStl(path);
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(file, aiProcess_Triangulate | aiProcess_ValidateDataStructure);
    if (scene == nullptr) throw InputError(file, 0, std::string("cannot import: ") + importer.GetErrorString());
    if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || scene->mRootNode == nullptr)
        throw InputError(file, 0, "cannot import: the file holds no complete scene");

    TriMesh mesh;
    mesh.name = path.stem().string();
    appendNode(*scene, *scene->mRootNode, Eigen::Matrix4d::Identity(), file, mesh);
    if (mesh.faces.empty()) throw InputError(file, 0, "empty mesh: no triangles");
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
        if (!mesh.vertices[v].allFinite())
            throw InputError(file, lineOfNonFiniteToken(path), "a vertex has a NaN or infinite coordinate");

    return finishRead(std::move(mesh), file, {}, options, FormatWelding::PerCorner);  // one vertex per corner in STL: weld identical ones
}

}  // namespace flexfit
