// Mesh import through assimp (OBJ, STL, PLY, OFF, glTF/GLB, and the rest assimp reads).
//
// The scene graph is flattened: every mesh instance is transformed by its node's world matrix
// and appended. Polygons are triangulated by assimp; point and line primitives cannot be and
// are rejected. Vertices are welded (exactly, or within the tolerance) because most formats
// split them per face corner.
//
// The import itself (assimp's reading and the flattening) runs in a child process
// (core/child_process.hpp): assimp crashes or never returns on some damaged files, and a crash
// would end the user's program. A crash or a timeout is an InputError naming the file. The
// mesh comes back through a pipe as the same doubles the flattening computed, so the result is
// the same bits as an import in this process.
#include "flexfit/mesh_io.hpp"
#include "core/child_process.hpp"
#include "io_internal.hpp"
#include "text_lines.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <atomic>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>

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

// The flattened triangles as bytes: counts, then the vertices' doubles, then the faces' indices.
std::string serialize(const TriMesh& mesh) {
    const std::uint64_t counts[2] = {mesh.vertices.size(), mesh.faces.size()};
    std::string out(reinterpret_cast<const char*>(counts), sizeof counts);
    if (!mesh.vertices.empty()) out.append(reinterpret_cast<const char*>(mesh.vertices.front().data()), mesh.vertices.size() * sizeof(Vec3));
    out.append(reinterpret_cast<const char*>(mesh.faces.data()), mesh.faces.size() * sizeof(Face));
    return out;
}

TriMesh deserialize(const std::string& bytes, const std::string& file) {
    std::uint64_t counts[2] = {0, 0};
    const auto broken = [&] { return InputError(file, 0, "cannot import: the import process sent a malformed mesh"); };
    if (bytes.size() < sizeof counts) throw broken();
    std::memcpy(counts, bytes.data(), sizeof counts);
    if (counts[0] > bytes.size() / sizeof(Vec3) || counts[1] > bytes.size() / sizeof(Face) ||
        bytes.size() != sizeof counts + counts[0] * sizeof(Vec3) + counts[1] * sizeof(Face))
        throw broken();
    TriMesh mesh;
    mesh.vertices.resize(counts[0]);
    mesh.faces.resize(counts[1]);
    static_assert(sizeof(Vec3) == 3 * sizeof(double), "vertices are three packed doubles");
    if (counts[0] > 0) std::memcpy(mesh.vertices.front().data(), bytes.data() + sizeof counts, counts[0] * sizeof(Vec3));
    std::memcpy(mesh.faces.data(), bytes.data() + sizeof counts + counts[0] * sizeof(Vec3), counts[1] * sizeof(Face));
    return mesh;
}

// assimp's import and the flattening, as the child process runs them; throws std::runtime_error
// with the problem alone (the parent names the file).
std::string importTriangles(const std::string& file) {
    try {
        Assimp::Importer importer;
        const aiScene* scene = importer.ReadFile(file, aiProcess_Triangulate | aiProcess_ValidateDataStructure);
        if (scene == nullptr) throw InputError(file, 0, std::string("cannot import: ") + importer.GetErrorString());
        if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || scene->mRootNode == nullptr)
            throw InputError(file, 0, "cannot import: the file holds no complete scene");
        TriMesh mesh;
        appendNode(*scene, *scene->mRootNode, Eigen::Matrix4d::Identity(), file, mesh);
        return serialize(mesh);
    } catch (const InputError& e) {
        throw std::runtime_error(e.problem());
    }
}

std::atomic<double> importSecondsOverride{0.0};

// The time an import may take: 30 s, and 2 s more per MB of file (assimp-testmodels' largest
// files import in well under a second each).
double importSeconds(const std::filesystem::path& path) {
    if (const double chosen = importSecondsOverride.load(); chosen > 0.0) return chosen;
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(path, ec);
    return 30.0 + (ec ? 0.0 : 2.0 * double(size) / 1e6);
}

// A token read whole as a number (a leading '+' allowed): its value, or out of a double's
// range; nullopt for anything else (a word, a number with more after it).
struct WholeNumber {
    double value = 0.0;
    bool outOfRange = false;
};
std::optional<WholeNumber> wholeNumber(std::string_view token) {
    WholeNumber n;
    const char* begin = token.data() + (token.size() > 1 && token[0] == '+' ? 1 : 0);
    const auto [end, ec] = std::from_chars(begin, token.data() + token.size(), n.value);
    if (end != token.data() + token.size() || (ec != std::errc() && ec != std::errc::result_out_of_range)) return std::nullopt;
    n.outOfRange = ec == std::errc::result_out_of_range;
    return n;
}

// A whole token that is a number assimp cannot hold: NaN, infinity, or beyond float range
// (assimp stores coordinates as 32-bit floats). Words that merely start with "inf" do not count.
bool isNonFiniteToken(std::string_view token) {
    const std::optional<WholeNumber> n = wholeNumber(token);
    return n && (n->outOfRange || !(std::abs(n->value) <= double(std::numeric_limits<float>::max())));
}

// First line of a text file holding a NaN/Inf token; 0 when none (binary files, or none found).
// Lines as the text readers count them (text_lines.hpp).
std::size_t lineOfNonFiniteToken(const std::filesystem::path& path) {
    const std::string text = detail::readTextFile(path);
    detail::LineCursor cursor(text);
    detail::TextLine line;
    while (cursor.next(line))
        for (std::string_view token : line.tokens)
            if (isNonFiniteToken(token)) return line.number;
    return 0;
}

// A regular .stl file's size and first 84 bytes (a binary STL's header and facet count), read
// once for both checks below; nullopt for anything else (assimp names what else is wrong).
struct StlStart {
    std::uintmax_t size = 0;
    std::string head;
    // The size a binary STL of the count at offset 80 has (84 + 50 n); 0 when shorter than 84 bytes.
    std::uint64_t binarySize() const {
        if (head.size() < 84) return 0;
        std::uint32_t facets = 0;
        std::memcpy(&facets, head.data() + 80, 4);
        return 84 + 50 * std::uint64_t(facets);
    }
    std::uint32_t facets() const { return binarySize() == 0 ? 0 : std::uint32_t((binarySize() - 84) / 50); }
    // An ASCII STL starts with "solid" and is not a binary STL by its size (some exporters start
    // a binary header with "solid" too).
    bool ascii() const {
        const std::size_t first = head.find_first_not_of(" \t\r\n");
        return first != std::string::npos && head.compare(first, 5, "solid") == 0 && size != binarySize();
    }
};

std::optional<StlStart> stlStart(const std::filesystem::path& path) {
    std::error_code ec;
    if (lowerExtension(path) != ".stl" || !std::filesystem::is_regular_file(path, ec)) return std::nullopt;
    StlStart s;
    s.size = std::filesystem::file_size(path, ec);
    if (ec) return std::nullopt;
    std::ifstream in(path, std::ios::binary);
    s.head.assign(std::size_t(std::min<std::uintmax_t>(s.size, 84)), '\0');
    in.read(s.head.data(), std::streamsize(s.head.size()));
    return s;
}

// An ASCII STL's structure, checked line by line before assimp reads it: solid, then facets of
// `facet normal x y z`, `outer loop`, three `vertex x y z`, `endloop`, `endfacet`, then
// `endsolid` (more solids may follow; NULs and a DOS end-of-file byte after the last are
// ignored). Assimp 5.2.5 reads a file cut short as a smaller, open mesh, and leaks its buffers
// when a loop has other than three vertices or facets and vertices disagree (upstream issue
// 5946); here each is refused at its line, and assimp only ever sees well-formed files.
void checkAsciiStl(const std::filesystem::path& path) {
    const std::string text = detail::readTextFile(path);
    const std::string file = path.string();
    enum class At { Start, Solid, Facet, Loop, LoopEnd, AfterSolid } at = At::Start;
    int vertices = 0;
    detail::LineCursor cursor(text);
    detail::TextLine line;
    std::size_t lastLine = 0;
    const auto fail = [&](const std::string& problem) { throw InputError(file, line.number, problem); };
    const auto expectNumbers = [&](std::size_t from, const char* what) {
        if (line.tokens.size() != from + 3) fail(std::string("'") + what + "' needs three numbers");
        for (std::size_t i = from; i < from + 3; ++i)
            if (!wholeNumber(line.tokens[i])) fail(std::string("'") + what + "': '" + std::string(line.tokens[i]) + "' is not a number");
    };
    while (cursor.next(line)) {
        lastLine = line.number;
        const std::string_view key = line.tokens[0];
        switch (at) {
        case At::Start:
        case At::AfterSolid:
            if (key == "solid") at = At::Solid;
            else if (at == At::AfterSolid && key.find_first_not_of(std::string_view("\0\x1a", 2)) == std::string_view::npos) continue;
            else fail(at == At::Start ? "expected 'solid'" : "'" + std::string(key) + "' after 'endsolid'");
            break;
        case At::Solid:
            if (key == "endsolid") at = At::AfterSolid;
            else if (key == "facet") {
                if (line.tokens.size() < 2 || line.tokens[1] != "normal") fail("expected 'facet normal x y z'");
                expectNumbers(2, "facet normal");
                at = At::Facet;
            } else fail("expected 'facet' or 'endsolid', found '" + std::string(key) + "'");
            break;
        case At::Facet:
            if (key != "outer" || line.tokens.size() != 2 || line.tokens[1] != "loop") fail("expected 'outer loop'");
            at = At::Loop;
            vertices = 0;
            break;
        case At::Loop:
            if (key == "vertex") {
                if (++vertices > 3) fail("a facet with more than three vertices: STL facets are triangles");
                expectNumbers(1, "vertex");
                for (std::size_t i = 1; i < 4; ++i) {
                    if (!isNonFiniteToken(line.tokens[i])) continue;
                    const WholeNumber n = *wholeNumber(line.tokens[i]);  // a number: expectNumbers checked it
                    if (!n.outOfRange && !std::isfinite(n.value)) fail("a vertex has a NaN or infinite coordinate");
                    fail("coordinate '" + std::string(line.tokens[i]) + "' is beyond single precision (STL holds 32-bit floats, about 3.4e38 at most)");
                }
            } else if (key == "endloop") {
                if (vertices != 3) fail("a facet with " + std::to_string(vertices) + " vertices: STL facets are triangles");
                at = At::LoopEnd;
            } else fail("expected 'vertex' or 'endloop', found '" + std::string(key) + "'");
            break;
        case At::LoopEnd:
            if (key != "endfacet") fail("expected 'endfacet', found '" + std::string(key) + "'");
            at = At::Solid;
            break;
        }
    }
    if (at != At::AfterSolid) throw InputError(file, lastLine, "the ASCII STL ends without an 'endsolid' line: the file is cut short");
}

// A .stl that is not an ASCII STL must be a binary one: an 80-byte header, the facet count n,
// then 50 bytes a facet. Checked here, so a file cut short or with a wrong count is named as
// such (assimp says only "Failed to determine STL storage representation").
void checkBinaryStl(const std::filesystem::path& path, const StlStart& s) {
    const std::string file = path.string();
    const std::string neither = "neither an ASCII STL (a first line 'solid', keywords in lower case) nor a binary STL";
    if (s.size < 84) throw InputError(file, 0, neither + " (an 84-byte header, then 50 bytes a facet): " + std::to_string(s.size) + " bytes");
    if (s.size != s.binarySize())
        throw InputError(file, 0, neither + ": as binary, its header counts " + std::to_string(s.facets()) + " facets (" +
                                      std::to_string(s.binarySize()) + " bytes) but the file has " + std::to_string(s.size) +
                                      " bytes (cut short, or damaged)");
}

// An STL's structure, checked before assimp reads it: as ASCII or as binary, whichever it is.
void checkStl(const std::filesystem::path& path) {
    const std::optional<StlStart> start = stlStart(path);
    if (!start) return;
    if (start->ascii())
        checkAsciiStl(path);
    else
        checkBinaryStl(path, *start);
}

}  // namespace

namespace detail {
ScopedImportTimeLimit::ScopedImportTimeLimit(double seconds) { importSecondsOverride.store(seconds); }
ScopedImportTimeLimit::~ScopedImportTimeLimit() { importSecondsOverride.store(0.0); }
}  // namespace detail

MeshReadResult readWithAssimp(const std::filesystem::path& path, const MeshReadOptions& options) {
    const std::string file = path.string();
    if (!std::filesystem::exists(path)) throw InputError(file, 0, "cannot open the file for reading: it does not exist");
    checkStl(path);
    const double seconds = importSeconds(path);
    std::string bytes;
    try {
        bytes = detail::runInChild([&] { return importTriangles(file); }, seconds);
    } catch (const detail::ChildFailure& e) {
        switch (e.kind()) {
        case detail::ChildFailure::Kind::Threw: throw InputError(file, 0, e.what());
        case detail::ChildFailure::Kind::Crashed:
            throw InputError(file, 0, std::string("cannot import: assimp's importer crashed reading the file (") + e.what() +
                                          "): the file is damaged, or a variant of its format assimp cannot read");
        case detail::ChildFailure::Kind::TimedOut:
            throw InputError(file, 0, std::string("cannot import: assimp's importer ") + e.what() +
                                          ": the file is damaged, or a variant of its format assimp cannot read");
        case detail::ChildFailure::Kind::Failed: throw InputError(file, 0, std::string("cannot import: the import process ") + e.what());
        }
    }
    TriMesh mesh = deserialize(bytes, file);
    mesh.name = path.stem().string();
    if (mesh.faces.empty()) throw InputError(file, 0, "empty mesh: no triangles");
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
        if (!mesh.vertices[v].allFinite())
            throw InputError(file, lineOfNonFiniteToken(path), "a vertex has a NaN or infinite coordinate");

    return finishRead(std::move(mesh), file, {}, options, FormatWelding::PerCorner);  // one vertex per corner in STL: weld identical ones
}

}  // namespace flexfit
