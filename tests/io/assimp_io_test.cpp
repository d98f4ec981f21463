// Tests readMesh on small hand-written files: through assimp (STL, glTF 2.0) and, for OBJ, OFF and PLY, through their own readers (obj_io_test.cpp, off_io_test.cpp and ply_io_test.cpp test them further), against hand-counted vertices/faces/edges after welding, the OBJ writer's round trip and the error contract.
#include "flexfit/generators.hpp"
#include "float_precision.hpp"
#include "strings.hpp"
#include "flexfit/mesh_io.hpp"
#include "io/io_internal.hpp"

#include <gtest/gtest.h>

#include "temp_dir.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <tuple>
#include <vector>

namespace flexfit {
namespace {

namespace fs = std::filesystem;

using flexfit::testing::TempDir;

using flexfit::testing::toFloatPrecision;

using flexfit::testing::contains;

double signedVolume(const TriMesh& mesh) {
    double sum = 0.0;
    for (const Face& f : mesh.faces) sum += mesh.vertices[f[0]].dot(mesh.vertices[f[1]].cross(mesh.vertices[f[2]]));
    return sum / 6.0;
}

// Expects readMesh to throw InputError naming the file; returns it.
InputError expectReadError(const fs::path& file, const MeshReadOptions& options = {}) {
    try {
        readMesh(file, options);
    } catch (const InputError& e) {
        EXPECT_EQ(e.source(), file.string());
        return e;
    } catch (const std::exception& e) {
        ADD_FAILURE() << "not an InputError: " << e.what();
        return InputError("none", 0, "none");
    }
    ADD_FAILURE() << "accepted " << file;
    return InputError("none", 0, "none");
}

// Unit cube, outward counter-clockwise quads (1-based OBJ indices).
const std::string kObjCubeVertices =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";
const std::string kObjCubeQuads = "# cube\no cube\n" + kObjCubeVertices +
                                  "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";
const std::string kObjCubeTriangles = "o cube\n" + kObjCubeVertices +
                                      "f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
                                      "f 4 8 7\nf 4 7 3\nf 1 5 8\nf 1 8 4\nf 2 3 7\nf 2 7 6\n";

// Tetrahedron (0,0,0) (1,0,0) (0,1,0) (0,0,1), outward faces (0 2 1) (0 1 3) (0 3 2) (1 2 3).
const double kTetVertices[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
const int kTetFaces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

// ASCII STL of the tetrahedron: one vertex per face corner (12). `perturb` moves the second and
// third copies of each corner by that much (along x and y).
std::string stlTetrahedron(double perturb = 0.0, double scale = 1.0) {
    std::string out = "solid tet\n";
    std::map<int, int> seen;
    char buffer[160];
    for (const auto& face : kTetFaces) {
        out += "  facet normal 0 0 0\n    outer loop\n";
        for (int corner : face) {
            const int copy = seen[corner]++;
            double p[3] = {scale * kTetVertices[corner][0], scale * kTetVertices[corner][1], scale * kTetVertices[corner][2]};
            if (copy == 1) p[0] += perturb;
            if (copy == 2) p[1] += perturb;
            std::snprintf(buffer, sizeof buffer, "      vertex %.17g %.17g %.17g\n", p[0], p[1], p[2]);
            out += buffer;
        }
        out += "    endloop\n  endfacet\n";
    }
    return out + "endsolid tet\n";
}

std::string base64(const std::vector<std::uint8_t>& bytes) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const std::uint32_t b0 = bytes[i], b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0,
                            b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0;
        const std::uint32_t n = (b0 << 16) | (b1 << 8) | b2;
        out += table[(n >> 18) & 63];
        out += table[(n >> 12) & 63];
        out += i + 1 < bytes.size() ? table[(n >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? table[n & 63] : '=';
    }
    return out;
}

TEST(Base64, KnownVectors) {
    EXPECT_EQ(base64({}), "");
    EXPECT_EQ(base64({'f'}), "Zg==");
    EXPECT_EQ(base64({'f', 'o'}), "Zm8=");
    EXPECT_EQ(base64({'f', 'o', 'o'}), "Zm9v");
    EXPECT_EQ(base64({'f', 'o', 'o', 'b', 'a', 'r'}), "Zm9vYmFy");
}

// A minimal glTF 2.0 file of the tetrahedron: float positions and unsigned short indices in one
// buffer embedded as a base64 data: URI.
std::string gltfTetrahedron() {
    std::vector<std::uint8_t> bytes;
    auto append = [&](const void* data, std::size_t size) {
        const auto* p = static_cast<const std::uint8_t*>(data);
        bytes.insert(bytes.end(), p, p + size);  // little-endian host, as glTF requires
    };
    for (const auto& v : kTetVertices)
        for (double c : v) {
            const float f = float(c);
            append(&f, sizeof f);
        }
    for (const auto& face : kTetFaces)
        for (int i : face) {
            const std::uint16_t s = std::uint16_t(i);
            append(&s, sizeof s);
        }
    EXPECT_EQ(bytes.size(), 72u);
    return R"({
  "asset": {"version": "2.0", "generator": "flexfit test"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0, "name": "tet"}],
  "meshes": [{"name": "tet", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 4}]}],
  "buffers": [{"byteLength": 72, "uri": "data:application/octet-stream;base64,)" +
           base64(bytes) + R"("}],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 48, "target": 34962},
    {"buffer": 0, "byteOffset": 48, "byteLength": 24, "target": 34963}
  ],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
    {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}
  ]
}
)";
}

void expectTetrahedronResult(const MeshReadResult& r) {
    EXPECT_EQ(r.mesh.vertices.size(), 4u);
    EXPECT_EQ(r.mesh.faces.size(), 4u);
    EXPECT_EQ(r.diagnostics.edgeCount, 6u);
    EXPECT_TRUE(r.diagnostics.closed());
    EXPECT_TRUE(r.diagnostics.warnings.empty());
    EXPECT_NEAR(signedVolume(r.mesh), 1.0 / 6.0, 1e-12);
    // Each input corner position is present.
    for (const auto& v : kTetVertices) {
        bool found = false;
        for (const Vec3& p : r.mesh.vertices) found = found || p == Vec3(v[0], v[1], v[2]);
        EXPECT_TRUE(found) << v[0] << " " << v[1] << " " << v[2];
    }
}

void expectCubeResult(const MeshReadResult& r) {
    EXPECT_EQ(r.mesh.vertices.size(), 8u);
    EXPECT_EQ(r.mesh.faces.size(), 12u);
    EXPECT_EQ(r.diagnostics.edgeCount, 18u);
    EXPECT_TRUE(r.diagnostics.closed());
    EXPECT_TRUE(r.diagnostics.warnings.empty());
    EXPECT_EQ(r.collapsedFaces, 0u);
    EXPECT_NEAR(signedVolume(r.mesh), 1.0, 1e-12);  // outward orientation preserved
    const Eigen::AlignedBox3d box = boundingBox(r.mesh);
    EXPECT_EQ(box.min(), Vec3(0, 0, 0));
    EXPECT_EQ(box.max(), Vec3(1, 1, 1));
}

// ---------------------------------------------------------------------------------------------
// Formats

TEST(AssimpIo, ObjCubeOfQuadsIsTriangulated) {
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("cube.obj", kObjCubeQuads));
    expectCubeResult(r);
    EXPECT_EQ(r.mesh.name, "cube");  // the file's stem
}

TEST(AssimpIo, ObjCubeOfTriangles) {
    TempDir dir;
    expectCubeResult(readMesh(dir.write("cube.obj", kObjCubeTriangles)));
}

TEST(AssimpIo, AsciiStlTetrahedronIsWelded) {
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("tet.stl", stlTetrahedron()));
    expectTetrahedronResult(r);
    EXPECT_EQ(r.weldedVertices, 8u);  // 12 corners -> 4 vertices
    EXPECT_EQ(r.collapsedFaces, 0u);
}

TEST(AssimpIo, BinaryStlTetrahedronIsWelded) {
    std::string stl(80, ' ');
    stl.replace(0, 9, "flexfit 1");  // a header that does not start with "solid"
    auto append = [&](const void* data, std::size_t size) { stl.append(static_cast<const char*>(data), size); };
    const std::uint32_t count = 4;
    append(&count, sizeof count);
    for (const auto& face : kTetFaces) {
        const float normal[3] = {0, 0, 0};
        append(normal, sizeof normal);
        for (int corner : face) {
            const float p[3] = {float(kTetVertices[corner][0]), float(kTetVertices[corner][1]), float(kTetVertices[corner][2])};
            append(p, sizeof p);
        }
        const std::uint16_t attributes = 0;
        append(&attributes, sizeof attributes);
    }
    ASSERT_EQ(stl.size(), 84u + 4 * 50);
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("tet_binary.stl", stl));
    expectTetrahedronResult(r);
    EXPECT_EQ(r.weldedVertices, 8u);
    // Some exporters start a binary header with "solid": its size still says binary.
    stl.replace(0, 9, "solid bin");
    expectTetrahedronResult(readMesh(dir.write("tet_binary_solid.stl", stl)));
    // Cut short, or a count that disagrees with the size: said so (assimp named neither).
    stl.replace(0, 9, "flexfit 1");
    for (const std::string& bad : {stl.substr(0, stl.size() - 20), stl + std::string(50, '\0'), stl.substr(0, 60)}) {
        const InputError e = expectReadError(dir.write("bad_binary.stl", bad));
        EXPECT_TRUE(contains(e.problem(), "neither an ASCII STL")) << e.problem();
        if (bad.size() >= 84) {
            EXPECT_TRUE(contains(e.problem(), "its header counts 4 facets (284 bytes) but the file has")) << e.problem();
        }
    }
}

TEST(AssimpIo, AsciiPlyByItsOwnReader) {
    TempDir dir;
    std::string ply =
        "ply\nformat ascii 1.0\ncomment tetrahedron\nelement vertex 4\n"
        "property float x\nproperty float y\nproperty float z\n"
        "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
    for (const auto& v : kTetVertices) ply += std::to_string(v[0]) + " " + std::to_string(v[1]) + " " + std::to_string(v[2]) + "\n";
    for (const auto& f : kTetFaces) ply += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
    expectTetrahedronResult(readMesh(dir.write("tet.ply", ply)));
}

TEST(AssimpIo, AsciiPlyCubeOfQuadsByItsOwnReader) {
    TempDir dir;
    const std::string ply =
        "ply\nformat ascii 1.0\nelement vertex 8\nproperty double x\nproperty double y\nproperty double z\n"
        "element face 6\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
        "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 3 7 6 2\n4 0 4 7 3\n4 1 2 6 5\n";
    expectCubeResult(readMesh(dir.write("cube.ply", ply)));
}

TEST(AssimpIo, OffByItsOwnReader) {
    TempDir dir;
    const std::string off =
        "OFF\n8 6 12\n"
        "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
        "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 3 7 6 2\n4 0 4 7 3\n4 1 2 6 5\n";
    expectCubeResult(readMesh(dir.write("cube.off", off)));
}

TEST(AssimpIo, OffTetrahedronByItsOwnReader) {
    TempDir dir;
    std::string off = "OFF\n4 4 6\n";
    for (const auto& v : kTetVertices) off += std::to_string(v[0]) + " " + std::to_string(v[1]) + " " + std::to_string(v[2]) + "\n";
    for (const auto& f : kTetFaces) off += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
    expectTetrahedronResult(readMesh(dir.write("tet.off", off)));
}

TEST(AssimpIo, GltfWithEmbeddedBuffer) {
    TempDir dir;
    const MeshReadResult r = readMesh(dir.write("tet.gltf", gltfTetrahedron()));
    expectTetrahedronResult(r);
}

TEST(AssimpIo, ExtensionIsCaseInsensitive) {
    TempDir dir;
    expectCubeResult(readMesh(dir.write("CUBE.OBJ", kObjCubeQuads)));
}

// ---------------------------------------------------------------------------------------------
// OBJ round trip through writeObj

// Matches every read vertex to an original one within `tolerance` (a bijection), then checks the
// faces are the same faces in the same order with the same winding.
void expectSameMeshUpToVertexOrder(const TriMesh& original, const TriMesh& read, double tolerance) {
    ASSERT_EQ(read.vertices.size(), original.vertices.size());
    ASSERT_EQ(read.faces.size(), original.faces.size());
    // OBJ stores the faces in order; the importer may renumber vertices (one per face corner,
    // then welded in first-use order), so map through the faces.
    std::vector<Index> toOriginal(read.vertices.size(), Index(-1));
    for (std::size_t f = 0; f < read.faces.size(); ++f)
        for (int k = 0; k < 3; ++k) {
            const Index r = read.faces[f][k], o = original.faces[f][k];
            if (toOriginal[r] == Index(-1)) toOriginal[r] = o;
            ASSERT_EQ(toOriginal[r], o) << "face " << f << " corner " << k;
        }
    std::vector<int> hits(original.vertices.size(), 0);
    double worst = 0.0;
    for (std::size_t v = 0; v < read.vertices.size(); ++v) {
        ASSERT_NE(toOriginal[v], Index(-1));
        ++hits[toOriginal[v]];
        worst = std::max(worst, (read.vertices[v] - original.vertices[toOriginal[v]]).cwiseAbs().maxCoeff());
    }
    for (int h : hits) EXPECT_EQ(h, 1);
    EXPECT_LE(worst, tolerance);
}

TEST(AssimpIo, ObjRoundTripOfFloatRepresentableMesh) {
    // Coordinates that are exact floats survive any reader exactly.
    TriMesh mesh = makeTorus1();
    for (Vec3& v : mesh.vertices) v = toFloatPrecision(v);
    TempDir dir;
    const fs::path file = dir.path() / "torus.obj";
    writeObj(mesh, file);
    const MeshReadResult r = readMesh(file);
    expectSameMeshUpToVertexOrder(mesh, r.mesh, 1e-12);
    EXPECT_TRUE(r.diagnostics.closed());
    EXPECT_EQ(r.diagnostics.edgeCount, 1728u);
}

TEST(AssimpIo, ObjRoundTripOfDoubleMesh) {
    // writeObj writes 17 significant digits and the OBJ reader reads doubles: a general double
    // mesh comes back bit for bit, in its order (assimp, ai_real = float, read it only to
    // relative 2^-24, in first-use order).
    for (const TriMesh& mesh : {makeTorus1(), makeIcoSphere(3.0, 2), makeHeart(20.0, 24, 12)}) {
        SCOPED_TRACE(mesh.name);
        TempDir dir;
        const fs::path file = dir.path() / "mesh.obj";
        writeObj(mesh, file);
        const MeshReadResult r = readMesh(file);
        EXPECT_EQ(r.mesh.vertices, mesh.vertices);
        EXPECT_EQ(r.mesh.faces, mesh.faces);
        EXPECT_TRUE(r.diagnostics.closed());
    }
}

// ---------------------------------------------------------------------------------------------
// Errors

TEST(AssimpIo, ObjWithOnlyLineElementsIsRejected) {
    TempDir dir;
    const InputError e = expectReadError(dir.write("line.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n"));
    EXPECT_TRUE(contains(e.problem(), "cannot be triangulated")) << e.problem();
}

TEST(AssimpIo, ObjMixingTrianglesAndLinesIsRejected) {
    TempDir dir;
    const InputError e = expectReadError(dir.write("mixed.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nl 1 2\n"));
    EXPECT_TRUE(contains(e.problem(), "cannot be triangulated")) << e.problem();
}

TEST(AssimpIo, ObjWithOnlyPointsIsRejected) {
    TempDir dir;
    const InputError e = expectReadError(dir.write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\np 1 2 3\n"));
    EXPECT_TRUE(contains(e.problem(), "cannot be triangulated")) << e.problem();
}

TEST(AssimpIo, ObjWithNaNCoordinateNamesTheLineOfTheVertex) {
    TempDir dir;
    const std::string obj = "o cube\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 nan 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                            "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";
    const InputError e = expectReadError(dir.write("nan.obj", obj));
    EXPECT_EQ(e.line(), 5u) << e.what();
    EXPECT_TRUE(contains(e.problem(), "NaN or infinite")) << e.problem();
}

TEST(AssimpIo, StlWithNaNCoordinateNamesTheLineOfTheVertex) {
    TempDir dir;
    std::string stl = stlTetrahedron();
    // Line 1 "solid tet", 2 "facet normal", 3 "outer loop", 4-6 the first facet's vertices.
    const std::size_t at = stl.find("vertex 1 0 0");
    ASSERT_NE(at, std::string::npos);
    stl.replace(at, 12, "vertex 1 NaN 0");
    const InputError e = expectReadError(dir.write("nan.stl", stl));
    EXPECT_EQ(e.line(), 6u) << e.what();
    EXPECT_TRUE(contains(e.problem(), "NaN or infinite")) << e.problem();
    // Finite, but beyond a float (assimp reads STL coordinates as 32-bit floats): said so.
    std::string large = stlTetrahedron();
    large.replace(large.find("vertex 1 0 0"), 12, "vertex 1 1e39 0");
    const InputError beyond = expectReadError(dir.write("large.stl", large));
    EXPECT_EQ(beyond.line(), 6u) << beyond.what();
    EXPECT_TRUE(contains(beyond.problem(), "coordinate '1e39' is beyond single precision")) << beyond.problem();
}

TEST(AssimpIo, ObjWithInfCoordinateNamesTheLineOfTheVertex) {
    TempDir dir;
    const InputError e = expectReadError(dir.write("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n"));
    EXPECT_EQ(e.line(), 3u) << e.what();
}

// The line reported must be that of the 'v' record, even when earlier lines hold words that
// start with "nan"/"inf" (comments, object and material names).
TEST(AssimpIo, ObjNaNLineIgnoresWordsInCommentsAndNames) {
    TempDir dir;
    const std::string obj = "# information: a triangle\no infinity_pool\nv 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n";
    const InputError e = expectReadError(dir.write("words.obj", obj));
    EXPECT_EQ(e.line(), 4u) << e.what();
}

TEST(AssimpIo, CoordinateBeyondSinglePrecision) {
    // 1e39 is a finite double but a single-precision assimp (ai_real = float, as in Debian's
    // build) reads it as infinity: the file is then rejected as holding a non-finite coordinate.
    // A double-precision assimp reads it, and then it is refused as beyond kMaxMeshCoordinate,
    // as the OBJ, OFF and PLY readers (doubles) refuse it. Either way: no crash, no half-built mesh.
    TempDir dir;
    const fs::path file = dir.write("big.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1e39 0 0\n"
                                               "vertex 0 1e39 0\nendloop\nendfacet\nendsolid t\n");
    for (const fs::path& path :
         {dir.write("big.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1e39 0\nf 1 2 3\n"), dir.write("big.off", "OFF\n3 1 0\n0 0 0\n1e39 0 0\n0 1e39 0\n3 0 1 2\n"),
          dir.write("big.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
                               "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                               "0 0 0\n1e39 0 0\n0 1e39 0\n3 0 1 2\n")}) {
        try {
            readMesh(path);
            ADD_FAILURE() << path << " was read";
        } catch (const InputError& e) {
            EXPECT_TRUE(contains(e.problem(), "vertex 1 has a coordinate of magnitude 1e+39")) << e.problem();
        }
    }
    try {
        readMesh(file);
        ADD_FAILURE() << "big.stl was read";
    } catch (const InputError& e) {
        EXPECT_TRUE(contains(e.problem(), "beyond single precision") || contains(e.problem(), "beyond the 1e+20 units")) << e.problem();
    }
}

TEST(AssimpIo, NonexistentFile) {
    const fs::path missing = fs::temp_directory_path() / "flexfit_assimp_io_test_no_such_file.obj";
    const InputError e = expectReadError(missing);
    EXPECT_TRUE(contains(e.problem(), "does not exist")) << e.problem();
    expectReadError(fs::temp_directory_path() / "flexfit_assimp_io_test_no_such_file.stl");
    expectReadError(fs::temp_directory_path() / "flexfit_assimp_io_test_no_such_file.gltf");
}

TEST(AssimpIo, GarbageFilesAreRejected) {
    TempDir dir;
    expectReadError(dir.write("garbage.obj", "this is not an obj file\n\x01\x02\x03"));
    expectReadError(dir.write("empty.obj", ""));
    expectReadError(dir.write("garbage.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [ {"));
    expectReadError(dir.write("unknown.xyz123", "1 2 3\n"));
}

// Damaged copies of assimp-testmodels files on which assimp 5.2.5's importers crash (MD5, COB)
// or never return (OpenGEX): each is an InputError naming the file, and this process goes on.
TEST(AssimpIo, FilesThatCrashOrHangTheImporterAreErrors) {
    const fs::path models = "/usr/share/assimp/models";
    if (!fs::exists(models / "MD5/SimpleCube.md5mesh")) GTEST_SKIP() << "assimp-testmodels is not installed (Debian package)";
    TempDir dir;
    const auto cut = [&](const fs::path& from, std::size_t bytes, const std::string& name) {
        std::ifstream in(models / from, std::ios::binary);
        std::string head(bytes, '\0');
        in.read(head.data(), std::streamsize(bytes));
        head.resize(std::size_t(in.gcount()));
        return dir.write(name, head);
    };
    const detail::ScopedImportTimeLimit limit(3.0);
    for (const auto& [from, bytes, name] : {std::tuple<fs::path, std::size_t, std::string>{"MD5/SimpleCube.md5mesh", 1200, "cut.md5mesh"},
                                            {"COB/molecule.cob", 18000, "cut.cob"},
                                            {"OpenGEX/Example.ogex", 3797, "cut.ogex"}}) {
        if (!fs::exists(models / from)) continue;
        const InputError e = expectReadError(cut(from, bytes, name));
        EXPECT_TRUE(contains(e.problem(), "cannot import")) << e.problem();
    }
    expectTetrahedronResult(readMesh(dir.write("whole.stl", stlTetrahedron())));  // and imports go on
}

TEST(AssimpIo, TruncatedAsciiStlIsRejected) {
    // Cut inside a facet (assimp 5.2.5 would throw and leak ~2.4 kB inside libassimp: the check
    // for 'endsolid' now refuses it before assimp reads it), and cut between facets, which assimp
    // had read as a smaller, open mesh with only a warning.
    TempDir dir;
    expectReadError(dir.write("garbage.stl", "solid x\n  facet normal 0 0 0\n    outer loop\n      vertex 0 0\n"));
    const std::string whole = stlTetrahedron();
    const std::string cut = whole.substr(0, whole.find("  facet", whole.find("endfacet")));  // the first facet only
    try {
        readMesh(dir.write("cut.stl", cut));
        ADD_FAILURE() << "a cut STL was read";
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), 8u) << e.what();  // its last line, the first facet's endfacet
        EXPECT_TRUE(contains(e.problem(), "without an 'endsolid' line")) << e.problem();
    }
    // Whole files read: trailing blank lines, CRLF, and a binary STL whose header says "solid".
    expectTetrahedronResult(readMesh(dir.write("trailing.stl", whole + "\n  \n")));
    std::string crlf;
    for (char c : whole) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    expectTetrahedronResult(readMesh(dir.write("crlf.stl", crlf)));
    std::string indented = whole;
    indented.replace(indented.rfind("endsolid"), 0, "   ");
    expectTetrahedronResult(readMesh(dir.write("indented.stl", indented)));
    expectTetrahedronResult(readMesh(dir.write("padded.stl", whole + std::string("\0\0\x1a", 3))));
    // A long file is checked by its last 4 KiB: the endsolid there is found, a cut one refused.
    const std::string longer = "solid tet\n" + std::string(10000, ' ') + "\n" + whole.substr(whole.find('\n') + 1);
    expectTetrahedronResult(readMesh(dir.write("long.stl", longer)));
    EXPECT_THROW(readMesh(dir.write("long_cut.stl", longer.substr(0, longer.rfind("endsolid")))), InputError);
}

// An ASCII STL's structure is checked before assimp reads it: each defect is refused at its line
// with what was expected (assimp 5.2.5 leaked its buffers on a loop of other than three vertices
// and on facets and vertices that disagree); several solids in one file are read.
TEST(AssimpIo, MalformedAsciiStlIsRefusedAtTheLine) {
    TempDir dir;
    const std::string whole = stlTetrahedron();  // lines: 1 solid, 2 facet, 3 outer loop, 4-6 vertices, 7 endloop, 8 endfacet
    const auto refusal = [&](const std::string& text) {
        const InputError e = expectReadError(dir.write("bad.stl", text));
        return std::to_string(e.line()) + ": " + e.problem();
    };
    const auto edited = [&](const std::string& from, const std::string& to) {
        std::string text = whole;
        text.replace(text.find(from), from.size(), to);
        return text;
    };
    EXPECT_EQ(refusal(edited("      vertex 1 0 0\n", "")), "6: a facet with 2 vertices: STL facets are triangles");
    EXPECT_EQ(refusal(edited("      vertex 1 0 0\n", "      vertex 1 0 0\n      vertex 1 1 1\n")),
              "7: a facet with more than three vertices: STL facets are triangles");
    EXPECT_EQ(refusal(edited("  endfacet\n", "")), "8: expected 'endfacet', found 'facet'");
    EXPECT_EQ(refusal(edited("facet normal 0 0 0", "facet normal 0 0")), "2: 'facet normal' needs three numbers");
    EXPECT_EQ(refusal(edited("vertex 1 0 0", "vertex 1 a 0")), "6: 'vertex': 'a' is not a number");
    EXPECT_EQ(refusal(edited("    outer loop\n", "")), "3: expected 'outer loop'");
    EXPECT_EQ(refusal(whole + "trailing words\n"), "31: 'trailing' after 'endsolid'");
    EXPECT_EQ(refusal(edited("    endloop\n", "    endloop\n    endloop\n")), "8: expected 'endfacet', found 'endloop'");
    // Two solids: both read (the tetrahedron and a copy 5 along x).
    std::string moved = "solid moved\n";
    for (const auto& face : kTetFaces) {
        moved += "facet normal 0 0 0\nouter loop\n";
        for (int corner : face)
            moved += "vertex " + std::to_string(kTetVertices[corner][0] + 5.0) + " " + std::to_string(kTetVertices[corner][1]) + " " +
                     std::to_string(kTetVertices[corner][2]) + "\n";
        moved += "endloop\nendfacet\n";
    }
    const MeshReadResult two = readMesh(dir.write("two.stl", whole + moved + "endsolid moved\n"));
    EXPECT_EQ(two.mesh.faces.size(), 8u);
    EXPECT_EQ(two.mesh.vertices.size(), 8u);
}

TEST(AssimpIo, DegenerateAndDuplicateFacesAreRepairedOrRefused) {
    TempDir dir;
    const MeshReadOptions strict{.weldTolerance = std::nullopt, .repair = false};
    // Zero-area face: refused when strict; the repair drops it, and then nothing is left.
    const fs::path flat = dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
    EXPECT_TRUE(contains(expectReadError(flat, strict).problem(), "zero area"));
    EXPECT_TRUE(contains(expectReadError(flat).problem(), "no face is left"));
    // Duplicate faces (the same triangle twice, opposite winding).
    const fs::path dup = dir.write("dup.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 3 2 1\n");
    EXPECT_TRUE(contains(expectReadError(dup, strict).problem(), "duplicates"));
    const MeshReadResult r = readMesh(dup);
    EXPECT_EQ(r.mesh.faces.size(), 1u);
    EXPECT_EQ(r.repairs.duplicateFaces, 1u);
}

TEST(AssimpIo, NegativeOrNaNWeldToleranceIsRejected) {
    TempDir dir;
    const fs::path file = dir.write("tet.stl", stlTetrahedron());
    expectReadError(file, MeshReadOptions{-1e-6});
    expectReadError(file, MeshReadOptions{std::nan("")});
    expectReadError(file, MeshReadOptions{INFINITY});
}

// ---------------------------------------------------------------------------------------------
// Weld tolerance

TEST(AssimpIo, WeldTolerance) {
    TempDir dir;
    // Corners 0.5 apart with copies perturbed by 1e-7 (representable apart in float at this scale).
    const fs::path file = dir.write("perturbed.stl", stlTetrahedron(1e-7, 0.5));

    const MeshReadResult split = readMesh(file, MeshReadOptions{0.0});
    EXPECT_EQ(split.mesh.vertices.size(), 12u);  // nothing identical: every corner its own vertex
    EXPECT_EQ(split.mesh.faces.size(), 4u);
    EXPECT_EQ(split.weldedVertices, 0u);
    EXPECT_EQ(split.diagnostics.edgeCount, 12u);
    EXPECT_EQ(split.diagnostics.boundaryEdges, 12u);
    EXPECT_FALSE(split.diagnostics.closed());
    ASSERT_FALSE(split.diagnostics.warnings.empty());
    EXPECT_TRUE(contains(split.diagnostics.warnings[0], "12 boundary edges")) << split.diagnostics.warnings[0];

    const MeshReadResult welded = readMesh(file, MeshReadOptions{1e-5});
    EXPECT_EQ(welded.mesh.vertices.size(), 4u);
    EXPECT_EQ(welded.weldedVertices, 8u);
    EXPECT_EQ(welded.collapsedFaces, 0u);
    EXPECT_EQ(welded.diagnostics.edgeCount, 6u);
    EXPECT_TRUE(welded.diagnostics.closed());
    EXPECT_TRUE(welded.diagnostics.warnings.empty());
    // The first copy of each corner (unperturbed) is kept.
    for (const auto& v : kTetVertices) {
        bool found = false;
        for (const Vec3& p : welded.mesh.vertices) found = found || p == 0.5 * Vec3(v[0], v[1], v[2]);
        EXPECT_TRUE(found);
    }
}

TEST(AssimpIo, WeldingThatCollapsesFacesIsCountedAndWarned) {
    TempDir dir;
    // The tetrahedron plus a sliver triangle whose two corners weld together at 1e-3.
    std::string obj;
    for (const auto& v : kTetVertices) obj += "v " + std::to_string(v[0]) + " " + std::to_string(v[1]) + " " + std::to_string(v[2]) + "\n";
    obj += "v 0.0001 0 0\n";
    for (const auto& f : kTetFaces) obj += "f " + std::to_string(f[0] + 1) + " " + std::to_string(f[1] + 1) + " " + std::to_string(f[2] + 1) + "\n";
    obj += "f 1 5 3\n";
    const fs::path file = dir.write("sliver.obj", obj);
    const MeshReadResult unwelded = readMesh(file);
    EXPECT_EQ(unwelded.mesh.vertices.size(), 5u);
    EXPECT_EQ(unwelded.collapsedFaces, 0u);
    const MeshReadResult r = readMesh(file, MeshReadOptions{1e-3});
    EXPECT_EQ(r.mesh.vertices.size(), 4u);
    EXPECT_EQ(r.mesh.faces.size(), 4u);
    EXPECT_EQ(r.collapsedFaces, 1u);
    EXPECT_TRUE(r.diagnostics.closed());
    ASSERT_EQ(r.diagnostics.warnings.size(), 1u);
    EXPECT_TRUE(contains(r.diagnostics.warnings[0], "1 faces collapsed")) << r.diagnostics.warnings[0];
}

}  // namespace
}  // namespace flexfit
