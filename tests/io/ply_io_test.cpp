// Tests the PLY reader against hand-written files (ASCII, binary little- and big-endian) and
// Debian's assimp PLY test models: the file's vertex order and every bit of its coordinates
// kept, properties of every type and other elements read past, polygons split, and every
// problem named with its line (ASCII) or its element and byte (binary).
#include "flexfit/generators.hpp"
#include "flexfit/mesh_io.hpp"
#include "io/io_internal.hpp"
#include "face_sets.hpp"
#include "shuffled_mesh.hpp"
#include "mesh_read_error.hpp"
#include "temp_dir.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <cmath>
#include <string>

namespace flexfit {
namespace {

using testing::TempDir;

using testing::contains;

InputError readPlyError(const std::string& text) { return testing::meshReadError("m.ply", text); }

std::string asciiPly(const TriMesh& mesh) {
    std::string text = "ply\nformat ascii 1.0\ncomment by hand\nelement vertex " + std::to_string(mesh.vertices.size()) +
                       "\nproperty double x\nproperty double y\nproperty double z\nelement face " + std::to_string(mesh.faces.size()) +
                       "\nproperty list uchar int vertex_indices\nend_header\n";
    return text + testing::vertexAndFaceLines(mesh);
}

// Bytes of a value in the given byte order.
template <class T>
void put(std::string& out, T value, bool bigEndian) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    if (bigEndian != (std::endian::native == std::endian::big)) std::reverse(bytes, bytes + sizeof(T));
    out.append(bytes, sizeof(T));
}

// The mesh as binary PLY: a vertex with a float normal and a uchar colour around the double
// coordinates, an `edge` element between vertices and faces, faces with a uchar flag.
std::string binaryPly(const TriMesh& mesh, bool bigEndian) {
    std::string text = std::string("ply\nformat ") + (bigEndian ? "binary_big_endian" : "binary_little_endian") +
                       " 1.0\nelement vertex " + std::to_string(mesh.vertices.size()) +
                       "\nproperty float nx\nproperty double x\nproperty double y\nproperty uchar red\nproperty double z\n"
                       "element edge 2\nproperty int vertex1\nproperty list ushort short path\n"
                       "element face " + std::to_string(mesh.faces.size()) +
                       "\nproperty uchar flag\nproperty list uchar uint vertex_indices\nend_header\n";
    for (const Vec3& v : mesh.vertices) {
        put(text, 0.5f, bigEndian);
        put(text, v.x(), bigEndian);
        put(text, v.y(), bigEndian);
        put(text, std::uint8_t(200), bigEndian);
        put(text, v.z(), bigEndian);
    }
    for (int e = 0; e < 2; ++e) {
        put(text, std::int32_t(e), bigEndian);
        put(text, std::uint16_t(2), bigEndian);
        put(text, std::int16_t(-1), bigEndian);
        put(text, std::int16_t(7), bigEndian);
    }
    for (const Face& f : mesh.faces) {
        put(text, std::uint8_t(1), bigEndian);
        put(text, std::uint8_t(3), bigEndian);
        for (Index v : f) put(text, std::uint32_t(v), bigEndian);
    }
    return text;
}

TEST(PlyIo, KeepsTheFilesVertexOrderAndEveryBit) {
    // A double mesh in no useful order, as ASCII with 17 digits and as binary in both byte
    // orders: each reads back as it was.
    const TriMesh mesh = flexfit::testing::shuffledVertices(makeIcoSphere(1.7, 2), 4);
    TempDir dir;
    for (const auto& [name, text] : {std::pair<std::string, std::string>{"ascii.ply", asciiPly(mesh)},
                                     {"little.ply", binaryPly(mesh, false)},
                                     {"big.ply", binaryPly(mesh, true)}}) {
        const MeshReadResult r = readMesh(dir.write(name, text));
        EXPECT_EQ(r.mesh.vertices, mesh.vertices) << name;
        EXPECT_EQ(r.mesh.faces, mesh.faces) << name;
        EXPECT_TRUE(r.diagnostics.warnings.empty()) << name;
    }
}

TEST(PlyIo, EveryScalarTypeAndElementsInAnyOrder) {
    // Faces before vertices, coordinates of three integer types, unused properties of every
    // other type (ASCII values of unused properties are not read as numbers), quads.
    const std::string text =
        "ply\nformat ascii 1.0\nelement face 6\nproperty list uint8 int32 vertex_index\nproperty float32 quality\n"
        "element vertex 8\nproperty char x\nproperty short y\nproperty uint z\nproperty ushort a\nproperty int8 b\n"
        "property list uchar double uv\nelement material 1\nproperty float64 shine\nend_header\n"
        "4 0 3 2 1 0.5\n4 4 5 6 7 0.5\n4 0 1 5 4 1\n4 3 7 6 2 1\n4 0 4 7 3 1\n4 1 2 6 5 1\n"
        "0 0 0 1 -1 2 0.5 0.5\n1 0 0 1 -1 0\n1 1 0 1 -1 0\n0 1 0 1 -1 0\n0 0 1 1 -1 0\n1 0 1 1 -1 0\n1 1 1 65535 -128 0\n"
        "0 1 1 1 -1 1 n/a\n2.5\n";
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("cube.ply", text));
    ASSERT_EQ(r.mesh.vertices.size(), 8u);
    EXPECT_EQ(r.mesh.vertices[6], Vec3(1, 1, 1));
    EXPECT_EQ(r.mesh.faces.size(), 12u);
    EXPECT_TRUE(r.diagnostics.closed());
}

TEST(PlyIo, ElementsWithoutPropertiesAndAFinalEndOfLine) {
    // An element of no properties (its instances take no bytes) before the vertices, however
    // many it declares, and an end of line after the binary data: read as if absent.
    const TriMesh mesh = makeIcoSphere(1.0, 0);
    std::string text = binaryPly(mesh, false);
    text.insert(text.find("element vertex"), "element marker 1000000000000000000\n");
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("m.ply", text + "\n"));
    EXPECT_EQ(r.mesh.vertices, mesh.vertices);
}

TEST(PlyIo, AByteOrderMarkBeforeTheHeaderIsSkipped) {
    // The binary data starts after the header as the file has it, the mark included.
    const TriMesh mesh = makeIcoSphere(1.0, 0);
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("m.ply", "\xEF\xBB\xBF" + binaryPly(mesh, false)));
    EXPECT_EQ(r.mesh.vertices, mesh.vertices);
    EXPECT_EQ(r.mesh.faces, mesh.faces);
}

// Every line end (\n, \r\n, a lone \r) in the header as in the ASCII body, as the other text
// readers; before binary data a lone \r cannot be told from the data's first byte and is refused.
std::string withLineEnds(std::string text, const std::string& end) {
    std::string out;
    for (char c : text) c == '\n' ? out += end : out += c;
    return out;
}

TEST(PlyIo, EveryLineEndReadsTheSameMesh) {
    const TriMesh mesh = flexfit::testing::shuffledVertices(makeIcoSphere(1.7, 1), 3);
    TempDir dir;
    for (const std::string end : {"\r\n", "\r"}) {
        const MeshReadResult ascii = readMesh(dir.write("a.ply", withLineEnds(asciiPly(mesh), end)));
        EXPECT_EQ(ascii.mesh.vertices, mesh.vertices) << int(end.size());
        EXPECT_EQ(ascii.mesh.faces, mesh.faces) << int(end.size());
    }
    const std::string binary = binaryPly(mesh, false);
    const std::size_t body = binary.find("end_header\n") + 11;
    const std::string header = binary.substr(0, body), data = binary.substr(body);
    const MeshReadResult crlf = readMesh(dir.write("b.ply", withLineEnds(header, "\r\n") + data));
    EXPECT_EQ(crlf.mesh.vertices, mesh.vertices);
    const InputError lone = readPlyError(withLineEnds(header, "\r") + data);
    EXPECT_EQ(lone.line(), 15u) << lone.what();
    EXPECT_TRUE(contains(lone.problem(), "lone \\r")) << lone.what();
    // Data whose first byte is 0x0A after a lone \r reads as "\r\n": the first line tells.
    const InputError newlineByte = readPlyError(withLineEnds(header, "\r") + "\n" + data);
    EXPECT_TRUE(contains(newlineByte.problem(), "lone \\r")) << newlineByte.what();
    const MeshReadResult mark = readMesh(dir.write("c.ply", "\xEF\xBB\xBF" + withLineEnds(header, "\r\n") + data));
    EXPECT_EQ(mark.mesh.vertices, mesh.vertices);
    const InputError typo = readPlyError(withLineEnds("plyy\nformat ascii 1.0\n", "\r"));
    EXPECT_EQ(typo.line(), 1u);
    EXPECT_TRUE(contains(typo.problem(), "not a PLY file")) << typo.what();
    const InputError unended = readPlyError(withLineEnds("ply\nformat ascii 1.0\nelement vertex 0\n", "\r"));
    EXPECT_EQ(unended.line(), 3u) << unended.what();
    EXPECT_TRUE(contains(unended.problem(), "no end_header")) << unended.what();
}

TEST(PlyIo, FloatCoordinatesAreTheFloatsValues) {
    TempDir dir;
    std::string text = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                       "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    for (float v : {0.1f, 0.0f, 0.0f, 1.0f, 0.3f, 0.0f, 0.0f, 1.0f, 0.7f}) put(text, v, false);
    put(text, std::uint8_t(3), false);
    for (std::int32_t v : {0, 1, 2}) put(text, v, false);
    const MeshReadResult r = readMesh(dir.write("t.ply", text));
    ASSERT_EQ(r.mesh.vertices.size(), 3u);
    EXPECT_EQ(r.mesh.vertices[0].x(), double(0.1f));
    EXPECT_EQ(r.mesh.vertices[2].z(), double(0.7f));
}

TEST(PlyIo, AHeaderLineThatIsNotPlyIsReadPastWithAWarning) {
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("b.ply", "ply\nformat ascii 1.0\nCreated by Blender3D 247\nelement vertex 3\n"
                                                         "property float x\nproperty float y\nproperty float z\nelement face 1\n"
                                                         "property list uchar uint vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"));
    ASSERT_FALSE(r.diagnostics.warnings.empty());
    EXPECT_TRUE(contains(r.diagnostics.warnings[0], "line 3")) << r.diagnostics.warnings[0];
}

// Triangle strips: a height field of (kColumns + 1) x (kRows + 1) vertices, one strip per row of
// cells zig-zagging between the row's upper (a) and lower (b) vertices, -1 between rows. The
// reference is each cell's two triangles written out, both wound with +z up.
constexpr Index kColumns = 5, kRows = 3;
Index gridVertex(Index column, Index row) { return row * (kColumns + 1) + column; }

std::vector<Vec3> gridVertices() {
    std::vector<Vec3> vertices;
    for (Index row = 0; row <= kRows; ++row)
        for (Index column = 0; column <= kColumns; ++column)
            vertices.push_back(Vec3(column, row, 0.1 * std::sin(double(column + 2 * row))));
    return vertices;
}

std::vector<std::int64_t> gridStrips() {
    std::vector<std::int64_t> strips;
    for (Index row = 0; row < kRows; ++row) {
        if (row > 0) strips.push_back(-1);
        for (Index column = 0; column <= kColumns; ++column) {
            strips.push_back(gridVertex(column, row + 1));
            strips.push_back(gridVertex(column, row));
        }
    }
    strips.push_back(gridVertex(kColumns, kRows - 1));  // a repeated corner: a degenerate triangle, no face
    return strips;
}

// A triangle as its corners turned to start at the smallest index (same winding).
Face canonical(Face f) {
    std::rotate(f.begin(), std::min_element(f.begin(), f.end()), f.end());
    return f;
}

std::set<Face> canonicalFaces(const std::vector<Face>& faces) {
    std::set<Face> out;
    for (const Face& f : faces) out.insert(canonical(f));
    return out;
}

TEST(PlyIo, TriangleStripsGiveEachCellsTwoTrianglesInTheStripsWinding) {
    std::vector<Face> expected;
    for (Index row = 0; row < kRows; ++row)
        for (Index column = 0; column < kColumns; ++column) {
            const Index a = gridVertex(column, row + 1), b = gridVertex(column, row);
            const Index a1 = gridVertex(column + 1, row + 1), b1 = gridVertex(column + 1, row);
            expected.push_back({a, b, a1});
            expected.push_back({a1, b, b1});
        }
    const std::vector<Vec3> vertices = gridVertices();
    const std::vector<std::int64_t> strips = gridStrips();
    std::string ascii = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(vertices.size()) +
                        "\nproperty double x\nproperty double y\nproperty double z\nelement tristrips 1\n"
                        "property list int int vertex_indices\nend_header\n";
    char line[96];
    for (const Vec3& v : vertices) {
        std::snprintf(line, sizeof line, "%.17g %.17g %.17g\n", v.x(), v.y(), v.z());
        ascii += line;
    }
    ascii += std::to_string(strips.size());
    for (std::int64_t v : strips) {
        ascii += ' ';
        ascii += std::to_string(v);
    }
    ascii += "\n";
    std::string binary = "ply\nformat binary_big_endian 1.0\nelement vertex " + std::to_string(vertices.size()) +
                         "\nproperty double x\nproperty double y\nproperty double z\nelement tristrips 1\n"
                         "property list uint short vertex_indices\nend_header\n";
    for (const Vec3& v : vertices)
        for (int k = 0; k < 3; ++k) put(binary, v[k], true);
    put(binary, std::uint32_t(strips.size()), true);
    for (std::int64_t v : strips) put(binary, std::int16_t(v), true);
    TempDir dir;
    for (const auto& [name, text] : {std::pair<std::string, std::string>{"strips.ply", ascii}, {"strips_binary.ply", binary}}) {
        const MeshReadResult r = readMesh(dir.write(name, text));
        EXPECT_EQ(r.mesh.vertices, vertices) << name;
        EXPECT_EQ(r.mesh.faces.size(), expected.size()) << name;
        EXPECT_EQ(canonicalFaces(r.mesh.faces), canonicalFaces(expected)) << name;
        // Nothing repaired (no face dropped or flipped): only the grid's border is reported.
        ASSERT_EQ(r.diagnostics.warnings.size(), 1u) << name << ": " << r.diagnostics.warnings[0];
        EXPECT_TRUE(contains(r.diagnostics.warnings[0], std::to_string(2 * (kColumns + kRows)) + " boundary edges")) << r.diagnostics.warnings[0];
    }
    // A strip corner out of range is named with its line; a file of strips that give no
    // triangle has no faces.
    const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                               "element tristrips 1\nproperty list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    testing::expectReadErrors("m.ply", {
        {header + "4 0 1 -1 5\n", 13, "strip corner 5 out of range"},
        {header + "4 0 1 -1 -2\n", 13, "strip corner -2 out of range"},
        {header + "3 0 1 1\n", 0, "no triangles"},
    });
}

TEST(PlyIo, ProblemsNameTheirLine) {
    const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                               "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const std::string vertices = "0 0 0\n1 0 0\n0 1 0\n";
    testing::expectReadErrors("m.ply", {
        {"", 0, "no end_header"},
        {"PLY\nformat ascii 1.0\nend_header\n", 1, "not a PLY file"},
        {"ply\nformat utf8 1.0\nend_header\n", 2, "unknown format 'utf8'"},
        {"ply\nformat ascii 2.0\nend_header\n", 2, "format version '2.0'"},
        {"ply\nformat ascii 1.0\nelement vertex 3\nproperty real x\nend_header\n", 4, "unknown property type 'real'"},
        {"ply\nformat ascii 1.0\nproperty float x\nend_header\n", 3, "property before any element"},
        {"ply\nformat ascii 1.0\nelement vertex -3\nend_header\n", 3, "integer >= 0"},
        {"ply\nformat ascii 1.0\nelement vertex 1e6\nend_header\n", 3, "integer >= 0"},
        {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement vertex 3\n"
         "property float x\nproperty float y\nproperty float z\nend_header\n", 0, "two 'vertex' elements"},
        {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n", 4, "no end_header"},
        {"ply\nelement vertex 0\nend_header\n", 3, "no format line"},
        {"ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n3 0 1 2\n", 0, "no vertex element"},
        {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nend_header\n", 0, "x, y and z"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n", 0,
              "point cloud"},
        {header + vertices + "2 0 1\n", 13, "face 0: a face needs 3 corners, found 2"},
        {header + vertices + "3 0 1 3\n", 13, "face corner 3 out of range"},
        {header + vertices + "3 0 1 2.0\n", 13, "value '2.0' is not an integer"},
        {header + vertices + "300 0 1 2\n", 13, "value '300' does not fit its type"},
        {header + vertices + "3 0 1\n", 13, "fewer values than its properties hold"},
        {header + vertices + "3 0 1 2 7\n", 13, "1 values more than its properties hold"},
        {header + "0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n", 11, "coordinate 'x' is not a number"},
        {header + "0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n", 11, "NaN or infinite"},
        {header + "0 0 0\n1 0 0\n", 11, "ends after 2 of its 3 vertex elements"},
        {header + vertices + "3 0 1 2\n3 0 2 1\n", 14, "more data after the last element"},
    });
}

TEST(PlyIo, BinaryProblemsNameTheirElementAndByte) {
    const TriMesh mesh = makeIcoSphere(1.0, 0);
    const std::string whole = binaryPly(mesh, false);
    const std::size_t body = whole.find("end_header\n") + 11;
    const InputError cut = readPlyError(whole.substr(0, body + 29 * 3 + 10));  // inside vertex 3 (29 bytes each)
    EXPECT_TRUE(contains(cut.problem(), "vertex 3 (byte")) << cut.what();
    EXPECT_TRUE(contains(cut.problem(), "ends inside it")) << cut.what();
    const InputError extra = readPlyError(whole + "xy");
    EXPECT_TRUE(contains(extra.problem(), "2 bytes after the last element")) << extra.what();
    std::string outOfRange = whole;
    const std::size_t lastIndex = outOfRange.size() - 4;
    std::string index;
    put(index, std::uint32_t(12), false);  // 12 vertices: numbered 0..11
    outOfRange.replace(lastIndex, 4, index);
    const InputError range = readPlyError(outOfRange);
    EXPECT_TRUE(contains(range.problem(), "face 19")) << range.what();
    EXPECT_TRUE(contains(range.problem(), "face corner 12 out of range")) << range.what();
}

// Debian's assimp PLY test models (assimp-testmodels), ASCII and binary: as many vertices and the
// same triangles as assimp's importer (face_sets.hpp); point clouds refused.
TEST(PlyIo, DebiansTestModelsGiveAssimpsTriangles) {
    const std::filesystem::path directory = "/usr/share/assimp/models/PLY";
    if (!std::filesystem::exists(directory / "Wuson.ply")) GTEST_SKIP() << "assimp-testmodels not installed";
    MeshReadOptions exact;
    exact.weldTolerance = 0.0;
    for (const char* name : {"cube.ply", "cube_binary.ply", "cube_uv.ply", "float-color.ply", "Wuson.ply"}) {
        const std::filesystem::path file = directory / name;
        const MeshReadResult ours = readMesh(file, exact);
        const MeshReadResult theirs = readWithAssimp(file, exact);
        EXPECT_EQ(flexfit::testing::facesOnlyOneHas(ours.mesh, theirs.mesh), 0) << name << ": faces only one reader has";
        EXPECT_EQ(ours.mesh.vertices.size(), theirs.mesh.vertices.size()) << name;
        EXPECT_EQ(ours.mesh.faces.size(), theirs.mesh.faces.size()) << name;
    }
    for (const char* name : {"points.ply", "pond.0.ply"}) {
        try {
            readMesh(directory / name);
            ADD_FAILURE() << name << ": a point cloud was accepted";
        } catch (const InputError& e) {
            EXPECT_TRUE(contains(e.problem(), "point cloud")) << e.what();
        }
    }
}

}  // namespace
}  // namespace flexfit
