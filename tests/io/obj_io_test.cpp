// Tests the OBJ reader against hand-written files: the file's vertex order and every bit of its
// coordinates kept, corner forms (i, i/t, i//n, i/t/n), negative (relative) and forward
// indices, polygons split as fans, repeated positions welded as the format's welding, and every
// problem named with its line.
#include "flexfit/generators.hpp"
#include "flexfit/mesh_io.hpp"
#include "shuffled_mesh.hpp"
#include "mesh_read_error.hpp"
#include "temp_dir.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <sstream>
#include <string>

namespace flexfit {
namespace {

using testing::TempDir;

using testing::contains;

InputError readObjError(const std::string& text, const MeshReadOptions& options = {}) { return testing::meshReadError("m.obj", text, options); }

TEST(ObjIo, KeepsTheFilesVertexOrderAndEveryBit) {
    // A double mesh in no useful order, written with 17 digits: it reads back as it was.
    const TriMesh mesh = flexfit::testing::shuffledVertices(makeIcoSphere(1.7, 2), 8);
    TempDir dir;
    writeObj(mesh, dir.path() / "sphere.obj");
    const MeshReadResult r = readMesh(dir.path() / "sphere.obj");
    EXPECT_EQ(r.mesh.vertices, mesh.vertices);
    EXPECT_EQ(r.mesh.faces, mesh.faces);
    EXPECT_EQ(r.mesh.name, "sphere");
    EXPECT_EQ(r.weldedVertices, 0u);
    EXPECT_TRUE(r.diagnostics.warnings.empty());
}

TEST(ObjIo, AByteOrderMarkAndClassicMacLineEndsReadAsPlainText) {
    // A BOM in front had made the first line an unknown keyword: its vertex was skipped and every
    // index after it shifted. Lines ended by '\r' alone had read as one line.
    const std::string plain = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
    std::string mac = plain;
    std::replace(mac.begin(), mac.end(), '\n', '\r');
    TempDir dir;
    const MeshReadResult expected = readMesh(dir.write("plain.obj", plain));
    // Mixed: a '\r' alone in a file of "\r\n" and '\n' (it had merged two lines into one, whose
    // second vertex was dropped as an OBJ w coordinate).
    const std::string mixed = "v 0 0 0\r\nv 1 0 0\rv 0 1 0\nv 0 0 1\r\rf 1 3 2\nf 1 2 4\r\nf 2 3 4\rf 1 4 3";
    for (const auto& [name, text] :
         {std::pair{"bom.obj", "\xEF\xBB\xBF" + plain}, std::pair{"mac.obj", mac}, std::pair{"mixed.obj", mixed}}) {
        const MeshReadResult r = readMesh(dir.write(name, text));
        EXPECT_EQ(r.mesh.vertices, expected.mesh.vertices) << name;
        EXPECT_EQ(r.mesh.faces, expected.mesh.faces) << name;
        EXPECT_TRUE(r.diagnostics.warnings.empty()) << name;
    }
    // Line numbers count '\r' lines too.
    const InputError e = readObjError("v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 7\r");
    EXPECT_EQ(e.line(), 4u) << e.what();
    EXPECT_EQ(readObjError("v 0 0 0\r\nv 1 0 0\rv 0 1 0\n\r\nf 1 2 7\n").line(), 5u);
}

TEST(ObjIo, CornerFormsNegativeAndForwardIndices) {
    // A tetrahedron: corners as i/t, i//n, i/t/n (a face written before its last vertex) and
    // relative indices; texture coordinates, normals, groups and materials ignored.
    const std::string text = "# a tetrahedron\nmtllib x.mtl\no tet\ng side\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                             "vt 0 0\nvn 0 0 1\ns off\nusemtl red\n"
                             "f 1/1 3/1 2/1\nf 1//1 2//1 4//1\nv 0 0 1\nf 2/1/1 3/1/1 4/1/1\nf -4 -1 -2\n";
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("tet.obj", text));
    ASSERT_EQ(r.mesh.vertices.size(), 4u);
    EXPECT_EQ(r.mesh.vertices[3], Vec3(0, 0, 1));
    EXPECT_EQ(r.mesh.faces, (std::vector<Face>{{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}}));
    EXPECT_TRUE(r.diagnostics.closed());
    EXPECT_TRUE(r.diagnostics.warnings.empty());
    const InputError before = readObjError("v 0 0 0\nv 1 0 0\nf -3 -2 -1\nv 0 1 0\n");
    EXPECT_EQ(before.line(), 3u) << before.what();
    EXPECT_TRUE(contains(before.problem(), "refers before the first vertex (2 vertices read so far)")) << before.problem();
}

// Triangles of a planar polygon cover it exactly when each turns the polygon's way and their
// areas add up to its area (a fan over a concave polygon has a triangle turned the other way).
void expectExactCover(const TriMesh& mesh, double polygonArea) {
    double area = 0.0;
    for (const Face& f : mesh.faces) {
        const Vec3 n = (mesh.vertices[f[1]] - mesh.vertices[f[0]]).cross(mesh.vertices[f[2]] - mesh.vertices[f[0]]);
        EXPECT_GT(n.z(), 0.0) << "a triangle turned against the polygon";
        area += 0.5 * n.z();
    }
    EXPECT_NEAR(area, polygonArea, 1e-12 * polygonArea);
}

TEST(ObjIo, PolygonsAreSplitAsFans) {
    const std::string cube = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                             "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("cube.obj", cube));
    ASSERT_EQ(r.mesh.faces.size(), 12u);
    EXPECT_EQ(r.mesh.faces[0], (Face{0, 3, 2}));
    EXPECT_EQ(r.mesh.faces[1], (Face{0, 2, 1}));
    EXPECT_TRUE(r.diagnostics.closed());
}

TEST(ObjIo, ConvexPolygonsAreFansUnlessACornerIsOnAStraightEdge) {
    TempDir dir;
    const MeshReadResult hexagon = readMesh(dir.write("hex.obj", "v 2 0 0\nv 1 2 0\nv -1 2 0\nv -2 0 0\nv -1 -2 0\nv 1 -2 0\nf 1 2 3 4 5 6\n"));
    EXPECT_EQ(hexagon.mesh.faces.size(), 4u);
    expectExactCover(hexagon.mesh, 12.0);
    // A square with a corner in the middle of an edge (a T-junction): a fan from the first corner
    // would make a flat triangle; strict reading accepts it whole.
    const std::string square = "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nf 1 2 3 4 5\n";
    const MeshReadResult t = readMesh(dir.write("t.obj", square), {.weldTolerance = std::nullopt, .repair = false});
    EXPECT_EQ(t.mesh.faces.size(), 3u);
    expectExactCover(t.mesh, 4.0);
}

// `text` as UTF-16 bytes with its byte order mark, in either byte order.
std::string utf16Bytes(const std::u16string& text, bool bigEndian) {
    std::string out = bigEndian ? "\xFE\xFF" : "\xFF\xFE";
    for (const char16_t unit : text) {
        const char high = char(unit >> 8), low = char(unit & 0xFF);
        out += bigEndian ? std::string{high, low} : std::string{low, high};
    }
    return out;
}

TEST(ObjIo, UTF16TextReadsAsItsUTF8) {
    // Windows tools write UTF-16 (PowerShell's redirection, Notepad's "Unicode"): it had read as
    // an empty mesh. A comment beyond the basic plane (a surrogate pair) and one beyond ASCII.
    const std::u16string text = u"# gr\u00f6\u00dfe \U0001F600\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";
    TempDir dir;
    const MeshReadResult expected = readMesh(dir.write("plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n"));
    for (const bool bigEndian : {true, false}) {
        const MeshReadResult r = readMesh(dir.write("u16.obj", utf16Bytes(text, bigEndian)));
        EXPECT_EQ(r.mesh.vertices, expected.mesh.vertices) << bigEndian;
        EXPECT_EQ(r.mesh.faces, expected.mesh.faces) << bigEndian;
        EXPECT_TRUE(r.diagnostics.warnings.empty()) << bigEndian;
        // The file's lines: a bad face on line 3 is named there.
        const InputError e = readObjError(utf16Bytes(u"v 0 0 0\nv 1 0 0\nf 1 2 9\n", bigEndian));
        EXPECT_EQ(e.line(), 3u) << e.what();
    }
    // Cut short, an unpaired surrogate (on line 2), and UTF-32: refused, saying why.
    std::string odd = utf16Bytes(u"v 0 0 0\n", true);
    odd.pop_back();
    EXPECT_TRUE(contains(readObjError(odd).what(), "UTF-16 text cut short")) << readObjError(odd).what();
    const InputError lone = readObjError(utf16Bytes(u"v 0 0 0\n# \xD800 x\n", false));
    EXPECT_EQ(lone.line(), 2u);
    EXPECT_TRUE(contains(lone.what(), "a high surrogate with no low one")) << lone.what();
    EXPECT_EQ(readObjError(utf16Bytes(u"v 0 0 0\r\nv 1 0 0\r# \xD800\n", true)).line(), 3u);  // "\r\n" and '\r' end lines
    const InputError low = readObjError(utf16Bytes(u"# \xDC00\n", true));
    EXPECT_TRUE(contains(low.what(), "a low surrogate with no high one")) << low.what();
    EXPECT_TRUE(contains(readObjError(std::string("\xFF\xFE\0\0v 0 0 0\n", 12)).what(), "UTF-32"));
    // Debian's assimp test model in UTF-16 (big-endian): the box its UTF-8 twin holds.
    const std::filesystem::path models = "/usr/share/assimp/models/OBJ";
    if (!std::filesystem::exists(models / "box_UTF16BE.obj")) GTEST_SKIP() << "assimp-testmodels not installed";
    const MeshReadResult box = readMesh(models / "box.obj"), box16 = readMesh(models / "box_UTF16BE.obj");
    EXPECT_EQ(box16.mesh.vertices, box.mesh.vertices);
    EXPECT_EQ(box16.mesh.faces, box.mesh.faces);
    EXPECT_EQ(box16.mesh.faces.size(), 12u);
}

TEST(ObjIo, ConcavePolygonsAreClippedByEars) {
    // An L of area 3, started at a corner that does not see every other one.
    TempDir dir;
    const MeshReadResult l = readMesh(dir.write("l.obj", "v 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 2 0 0\nf 1 2 3 4 5 6\n"));
    ASSERT_EQ(l.mesh.faces.size(), 4u);
    expectExactCover(l.mesh, 3.0);
    // Debian's assimp test model: a 64-vertex concave polygon with a bridged hole (two corners
    // met twice), 66 corners: 64 triangles, no duplicate, covering its area.
    const std::filesystem::path keyhole = "/usr/share/assimp/models/OBJ/concave_polygon.obj";
    if (!std::filesystem::exists(keyhole)) GTEST_SKIP() << "assimp-testmodels not installed";
    const MeshReadResult k = readMesh(keyhole);
    EXPECT_EQ(k.mesh.faces.size(), 64u);
    EXPECT_EQ(k.repairs.duplicateFaces, 0u);
    EXPECT_EQ(k.diagnostics.nonManifoldEdges, 0u);
}

// A zigzag band of n corners, as one OBJ polygon: only the band's two ends are ears at first,
// and the corners are rotated so those ends lie inside the list. Its area by the shoelace formula.
std::pair<std::string, double> zigzagBand(std::size_t n) {
    std::vector<Eigen::Vector2d> bottom, top;
    for (std::size_t k = 0; k < n / 2; ++k) {
        const double x = double(k), y = k % 2 == 0 ? 0.0 : 1.0;
        bottom.emplace_back(x, y - 0.1);
        top.emplace_back(x, y + 0.1);
    }
    std::vector<Eigen::Vector2d> ring = bottom;  // counter-clockwise: along the bottom, back along the top
    ring.insert(ring.end(), top.rbegin(), top.rend());
    std::rotate(ring.begin(), ring.begin() + std::ptrdiff_t(ring.size() / 4), ring.end());
    std::ostringstream obj, face;
    face << "f";
    double twiceArea = 0.0;
    for (std::size_t i = 0; i < ring.size(); ++i) {
        obj << "v " << ring[i].x() << ' ' << ring[i].y() << " 0\n";
        face << ' ' << i + 1;
        const Eigen::Vector2d& q = ring[(i + 1) % ring.size()];
        twiceArea += ring[i].x() * q.y() - q.x() * ring[i].y();
    }
    obj << face.str() << '\n';
    return {obj.str(), 0.5 * twiceArea};
}

TEST(ObjIo, APolygonWithFewEarsIsClippedWhole) {
    // Ear clipping that rescanned from the first corner after each ear took a minute on 10,000
    // corners of this band (O(n^3)); each corner's ear is now checked again only when a
    // neighbour is clipped.
    TempDir dir;
    for (const std::size_t n : {12u, 2000u}) {
        const auto [obj, area] = zigzagBand(n);
        const MeshReadResult r = readMesh(dir.write("zigzag.obj", obj), {.weldTolerance = std::nullopt, .repair = false});
        EXPECT_EQ(r.mesh.faces.size(), n - 2) << n;
        expectExactCover(r.mesh, area);
        for (const std::string& w : r.diagnostics.warnings) EXPECT_FALSE(contains(w, "cross themselves")) << w;
    }
}

TEST(ObjIo, ASelfIntersectingPolygonIsFannedWithAWarning) {
    // A bow tie drawn as one quad: its two halves turn opposite ways, so no ear can be clipped.
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("bow.obj", "v 0 0 0\nv 2 2 0\nv 2 0 0\nv 0 2 0\nv 1 1 5\nf 1 2 3 4\nf 1 3 5\n"));
    ASSERT_FALSE(r.diagnostics.warnings.empty());
    EXPECT_TRUE(contains(r.diagnostics.warnings[0], "1 polygons cross themselves")) << r.diagnostics.warnings[0];
    // One that doubles back along its own edges (8 2, 5 2, 9 2): ears are clipped until none is
    // left, then every corner is checked again from one still there, and the polygon fanned.
    // (A first version of the ear ring checked from a clipped corner there and never returned.)
    const MeshReadResult back = readMesh(dir.write("back.obj", "v 8 8 0\nv 0 9 0\nv 2 7 0\nv 1 5 0\nv 0 2 0\nv 1 1 0\nv 3 0 0\n"
                                                               "v 1 4 0\nv 2 2 0\nv 8 2 0\nv 5 2 0\nv 9 2 0\nv 9 3 0\nv 9 4 0\n"
                                                               "v 6 5 0\nv 4 6 0\nv 9 6 0\nv 9 8 0\n"
                                                               "f 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18\n"));
    ASSERT_FALSE(back.diagnostics.warnings.empty());
    EXPECT_TRUE(contains(back.diagnostics.warnings[0], "1 polygons cross themselves")) << back.diagnostics.warnings[0];
}

TEST(ObjIo, RepeatedPositionsAreWeldedAsTheFormatsWelding) {
    // A square of two triangles, its diagonal's ends written twice (a split-normal export).
    const std::string text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 4 5 6\n";
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("square.obj", text));
    EXPECT_EQ(r.mesh.vertices.size(), 4u);
    EXPECT_EQ(r.weldedVertices, 2u);
    ASSERT_FALSE(r.diagnostics.warnings.empty());
    EXPECT_TRUE(contains(r.diagnostics.warnings[0], "2 vertices repeat an earlier one's position")) << r.diagnostics.warnings[0];
    EXPECT_EQ(r.mesh.faces[1], (Face{0, 2, 3}));
    EXPECT_EQ(r.mesh.vertices[3], Vec3(0, 1, 0));
}

TEST(ObjIo, CommentsEndAnyLine) {
    // `#` starts a comment anywhere on a line, after a face's corners too.
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("c.obj", "v 0 0 0 # origin\nv 1 0 0#x\nv 0 1 0\nv 0 0 1\n# faces\n"
                                                         "f 1 3 2 # bottom\nf 1 2 4\nf 2 3 4 #\nf 1 4 3#last\n"));
    EXPECT_EQ(r.mesh.vertices.size(), 4u);
    EXPECT_EQ(r.mesh.faces, (std::vector<Face>{{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}}));
    EXPECT_TRUE(r.diagnostics.closed());
}

TEST(ObjIo, ABackslashEndingALineContinuesItsStatement) {
    // The tetrahedron of CommentsEndAnyLine with statements split over lines, the backslash
    // alone or after a token, a comment after a continued part; and the same file unsplit.
    TempDir dir;
    const MeshReadResult split = readMesh(dir.write("split.obj", "v 0 0 \\\n  0\nv 1\\\n 0 0\nv 0 1 0\nv 0 0 1\n"
                                                                   "f 1 3 \\\n2 # bottom\nf \\\n 1 \\\n 2 \\\n 4\nf 2 3 4\nf 1 4 3 \\\n"));
    const MeshReadResult whole = readMesh(dir.write("whole.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n"));
    EXPECT_EQ(split.mesh.vertices, whole.mesh.vertices);
    EXPECT_EQ(split.mesh.faces, whole.mesh.faces);
    EXPECT_EQ(split.mesh.faces, (std::vector<Face>{{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}}));
    // A problem in a continued statement is named at its first line.
    const InputError e = readObjError("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 \\\n 2 \\\n 9\n");
    EXPECT_EQ(e.line(), 4u) << e.what();
    EXPECT_TRUE(contains(e.problem(), "face corner 9 out of range")) << e.what();
}

TEST(ObjIo, ProblemsNameTheirLine) {
    struct Case {
        const char* text;
        std::size_t line;
        const char* problem;
    };
    const Case cases[] = {
        {"v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n", 2, "a vertex needs 3 coordinates, found 2"},
        {"v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n", 2, "coordinate 'x' is not a number"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 3.1+e2\nf 1 2 3\n", 3, "coordinate '3.1+e2' is not a number"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", 4, "a face needs 3 corners, found 2"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", 4, "OBJ indices start at 1"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 9\n", 5, "face corner 9 out of range (the file has 3 vertices)"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 a/1\n", 4, "face corner 'a/1' is not a vertex index"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nl 1 2\n", 5, "cannot be triangulated"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\ncstype bspline\n", 4, "free-form geometry ('cstype')"},
        {"v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n", 2, "NaN or infinite"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\n", 0, "empty mesh: no triangles"},
        {"\n  \n", 0, "empty file"},
    };
    for (const Case& c : cases) {
        const InputError e = readObjError(c.text);
        EXPECT_EQ(e.line(), c.line) << c.text << e.what();
        EXPECT_TRUE(contains(e.problem(), c.problem)) << c.text << e.what();
    }
    // Strict: a degenerate face is refused at its line (repaired by default), after a quad split
    // in two triangles (each keeps the quad's line).
    const InputError strict = readObjError("v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 5 4\n# flat\nf 1 2 3\n",
                                        {.weldTolerance = std::nullopt, .repair = false});
    EXPECT_EQ(strict.line(), 8u) << strict.what();
}

}  // namespace
}  // namespace flexfit
