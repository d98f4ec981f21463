// Tests the OFF reader against hand-written files and Debian's assimp OFF test models: the
// file's vertex order and every bit of its coordinates kept, the header's variants (prefixes,
// counts on its line, none at all), comments, colours and normals ignored, polygons split, and
// every problem named with its line.
#include "flexfit/generators.hpp"
#include "flexfit/mesh_io.hpp"
#include "io/io_internal.hpp"
#include "face_sets.hpp"
#include "shuffled_mesh.hpp"
#include "mesh_read_error.hpp"
#include "temp_dir.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <filesystem>
#include <map>
#include <set>
#include <string>

namespace flexfit {
namespace {

using testing::TempDir;

using testing::contains;

std::string offText(const TriMesh& mesh) {
    std::string text = "OFF\n" + std::to_string(mesh.vertices.size()) + " " + std::to_string(mesh.faces.size()) + " 0\n";
    return text + testing::vertexAndFaceLines(mesh);
}

const std::string kCubeVertices = "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n";
const std::string kCubeFaces = "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 3 7 6 2\n4 0 4 7 3\n4 1 2 6 5\n";

void expectCube(const MeshReadResult& r) {
    ASSERT_EQ(r.mesh.vertices.size(), 8u);
    EXPECT_EQ(r.mesh.vertices[6], Vec3(1, 1, 1));
    EXPECT_EQ(r.mesh.faces.size(), 12u);
    EXPECT_TRUE(r.diagnostics.closed());
    EXPECT_TRUE(r.diagnostics.warnings.empty());
}

TEST(OffIo, KeepsTheFilesVertexOrderAndEveryBit) {
    // A double mesh in no useful order, written with 17 digits: it reads back as it was.
    const TriMesh mesh = flexfit::testing::shuffledVertices(makeIcoSphere(1.7, 2), 5);
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("sphere.off", offText(mesh)));
    EXPECT_EQ(r.mesh.vertices, mesh.vertices);
    EXPECT_EQ(r.mesh.faces, mesh.faces);
    EXPECT_EQ(r.mesh.name, "sphere");
    EXPECT_TRUE(r.diagnostics.warnings.empty());
}

TEST(OffIo, AnUnusedVertexKeepsTheOthersInPlace) {
    // assimp drops vertex 0 and renumbers the rest; the reader keeps the file's numbers, and the
    // repair removes the unused vertex with a warning (the others then shift by one, as counted).
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("cube.off", "OFF\n9 6 0\n5 5 5\n" + kCubeVertices +
                                                                 "4 1 4 3 2\n4 5 6 7 8\n4 1 2 6 5\n4 4 8 7 3\n4 1 5 8 4\n4 2 3 7 6\n"));
    ASSERT_EQ(r.mesh.vertices.size(), 8u);
    EXPECT_EQ(r.mesh.vertices[0], Vec3(0, 0, 0));
    EXPECT_EQ(r.repairs.unreferencedVertices, 1u);
}

TEST(OffIo, RepeatedPositionsAreWeldedAsTheFormatsWelding) {
    // A cube made of two pieces whose seam repeats vertices 2 and 3 as 8 and 9: welded into
    // their first, the rest in the file's order, with a warning that says indices moved.
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("pieces.off", "OFF\n10 6 0\n" + kCubeVertices + "1 1 0\n0 1 0\n" +
                                                                    "4 0 9 8 1\n4 4 5 6 7\n4 0 1 5 4\n4 3 7 6 2\n4 0 4 7 3\n4 1 2 6 5\n"));
    ASSERT_EQ(r.mesh.vertices.size(), 8u);
    EXPECT_EQ(r.weldedVertices, 2u);
    EXPECT_TRUE(r.diagnostics.closed());
    ASSERT_FALSE(r.diagnostics.warnings.empty());
    EXPECT_TRUE(contains(r.diagnostics.warnings[0], "2 vertices repeat an earlier one's position")) << r.diagnostics.warnings[0];
}

TEST(OffIo, HeaderVariantsCommentsColoursAndNormals) {
    TempDir dir;
    expectCube(readMesh(dir.write("a.off", "OFF\n8 6 12\n" + kCubeVertices + kCubeFaces)));
    expectCube(readMesh(dir.write("b.off", "OFF 8 6 0\n" + kCubeVertices + kCubeFaces)));            // counts on the header line
    expectCube(readMesh(dir.write("c.off", "8 6 0\n" + kCubeVertices + kCubeFaces)));                // no keyword
    expectCube(readMesh(dir.write("d.off", "nOFF 3\n8 6\n" + kCubeVertices + kCubeFaces)));          // dimension given
    expectCube(readMesh(dir.write("g.off", "OFF8 6 0\n" + kCubeVertices + kCubeFaces)));             // ModelNet's keyword run into the count
    expectCube(readMesh(dir.write("h.off", "OFF\n8\n6 0\n" + kCubeVertices + kCubeFaces)));          // counts over two lines
    expectCube(readMesh(dir.write("e.off", "# made by hand\n\nOFF # header\n# counts next\n8 6 0\n" + kCubeVertices + kCubeFaces +
                                               "# the end\n")));
    // COFF / NOFF / STCNOFF vertices carry colours, normals, texture coordinates; faces a colour.
    std::string coloured = "CNOFF\n8 6 0\n";
    for (const char* v : {"0 0 0", "1 0 0", "1 1 0", "0 1 0", "0 0 1", "1 0 1", "1 1 1", "0 1 1"})
        coloured += std::string(v) + " 0 0 1 0.5 0.5 0.5 1\n";
    for (const char* f : {"4 0 3 2 1 255 0 0", "4 4 5 6 7 1 0 0 1", "4 0 1 5 4", "4 3 7 6 2 7", "4 0 4 7 3", "4 1 2 6 5"})
        coloured += std::string(f) + "\n";
    expectCube(readMesh(dir.write("f.off", coloured)));
}

TEST(OffIo, ConcavePolygonsAreClippedByEars) {
    // An L-shaped hexagon (corner 3 reflex): a fan from corner 0 would fold over it.
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("l.off", "OFF\n6 1 0\n0 0 0\n2 0 0\n2 1 0\n1 1 0\n1 2 0\n0 2 0\n6 0 1 2 3 4 5\n"));
    ASSERT_EQ(r.mesh.faces.size(), 4u);
    double area = 0.0;
    for (const Face& f : r.mesh.faces) {
        const Vec3 n = (r.mesh.vertices[f[1]] - r.mesh.vertices[f[0]]).cross(r.mesh.vertices[f[2]] - r.mesh.vertices[f[0]]);
        EXPECT_GT(n.z(), 0.0);  // every triangle in the polygon's winding
        area += 0.5 * n.z();
    }
    EXPECT_DOUBLE_EQ(area, 3.0);
}

TEST(OffIo, ProblemsNameTheirLine) {
    const std::string tri = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n";
    testing::expectReadErrors("m.off", {
        {"", 0, "empty file"},
        {"# nothing\n\n", 0, "empty file"},
        {"ply\nformat ascii 1.0\n", 1, "not an OFF file"},
        {"OFF BINARY\n", 1, "binary OFF"},
        {"4OFF\n3 1 0\n", 1, "4D"},
        {"nOFF 4\n3 1 0\n", 1, "only 3"},
        {"OFF\n", 1, "ends before the vertex and face counts"},
        {"OFF\n3\n", 2, "found one number"},
        {"OFF\n-3 1 0\n", 2, "vertex count '-3'"},
        {"OFF\n3 x 0\n", 2, "face count 'x'"},
        {"OFF\n3 1 0\n0 0 0\n1 0 0\n", 4, "ends after 2 of its 3 vertices"},
        {"OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n", 4, "a vertex needs 3 coordinates, found 2"},
        {"OFF\n3 1 0\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n", 4, "coordinate 'zero' is not a number"},
        {"OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n", 4, "NaN or infinite"},
        {tri, 5, "ends after 0 of its 1 faces"},
        {tri + "2 0 1\n", 6, "a face needs 3 corners, found 2"},
        {tri + "4 0 1 2\n", 6, "has 4 corners but lists 3"},
        {tri + "3 0 1 3\n", 6, "face corner 3 out of range"},
        {tri + "3 0 -1 2\n", 6, "face corner -1 out of range"},
        {tri + "3 0 1.5 2\n", 6, "face corner '1.5' is not a vertex index"},
        {tri + "three 0 1 2\n", 6, "starts with its corner count"},
        {tri + "3 0 1 2\n3 0 2 1\n", 7, "more data after the 3 vertices and 1 faces"},
    });
}

TEST(OffIo, StrictReadingNamesTheDefectsLine) {
    // A zero-area face: repaired (dropped) by default, refused with its line when strict.
    const std::string text = "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n2 0 0\n0 0 1\n3 0 1 2\n3 0 1 3\n3 0 2 4\n";
    TempDir dir;
    const auto file = dir.write("d.off", text);
    EXPECT_EQ(readMesh(file).repairs.degenerateFaces, 1u);
    MeshReadOptions strict;
    strict.repair = false;
    try {
        readMesh(file, strict);
        ADD_FAILURE() << "strict reading accepted a degenerate face";
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), 9u) << e.what();
        EXPECT_TRUE(contains(e.problem(), "degenerate")) << e.what();
    }
}

// Debian's assimp OFF test models (assimp-testmodels): the reader gives the file's vertices, in
// its order and to the bit (compared with the file's lines read here with fscanf; positions the
// file repeats welded into their first), and the same triangles as assimp's importer.
std::vector<Vec3> offVertices(const std::filesystem::path& file) {
    std::FILE* f = std::fopen(file.c_str(), "rb");
    char keyword[16];
    long vertices = 0, faces = 0, edges = 0;
    EXPECT_EQ(std::fscanf(f, "%15s %ld %ld %ld", keyword, &vertices, &faces, &edges), 4) << file;
    std::vector<Vec3> out(std::size_t(std::max(vertices, 0L)));
    for (Vec3& v : out) EXPECT_EQ(std::fscanf(f, "%lf %lf %lf", &v.x(), &v.y(), &v.z()), 3) << file;
    std::fclose(f);
    return out;
}

TEST(OffIo, DebiansTestModelsAsTheFileOrdersThem) {
    const std::filesystem::path directory = "/usr/share/assimp/models/OFF";
    if (!std::filesystem::exists(directory / "Wuson.off")) GTEST_SKIP() << "assimp-testmodels not installed";
    for (const char* name : {"Cube.off", "Wuson.off"}) {
        const std::filesystem::path file = directory / name;
        MeshReadOptions exact;
        exact.weldTolerance = 0.0;  // only identical positions welded (Wuson has 18 pairs 3.7e-6 apart)
        const MeshReadResult ours = readMesh(file, exact);
        // The file's vertices, a position met again (Wuson repeats some along its pieces' seams)
        // welded into its first: the rest in the file's order.
        std::vector<Vec3> expected;
        std::set<std::array<double, 3>> seen;
        for (const Vec3& v : offVertices(file))
            if (seen.insert({v.x(), v.y(), v.z()}).second) expected.push_back(v);
        EXPECT_EQ(ours.mesh.vertices, expected) << name;
        EXPECT_EQ(ours.weldedVertices, offVertices(file).size() - expected.size()) << name;
        const MeshReadResult theirs = readWithAssimp(file, exact);
        EXPECT_EQ(flexfit::testing::facesOnlyOneHas(ours.mesh, theirs.mesh), 0) << name << ": faces only one reader has";
        EXPECT_EQ(ours.mesh.faces.size(), theirs.mesh.faces.size()) << name;
    }
}

}  // namespace
}  // namespace flexfit
