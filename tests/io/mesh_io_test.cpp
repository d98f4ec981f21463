// Tests the format dispatch of writeMesh/readMesh and readMesh's weld tolerance on .tri files, against meshes written and counted by hand.
#include "flexfit/generators.hpp"
#include "float_precision.hpp"
#include "mutations.hpp"
#include "strings.hpp"
#include "flexfit/mesh_io.hpp"

#include <gtest/gtest.h>

#include "temp_dir.hpp"

#include <unistd.h>

#include <csignal>
#include <sys/resource.h>
#include <algorithm>
#include <vector>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <string>

namespace flexfit {
namespace {

namespace fs = std::filesystem;

using flexfit::testing::TempDir;

std::string slurp(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream buffer;
    buffer << in.rdbuf();
    return buffer.str();
}

using flexfit::testing::toFloatPrecision;

using flexfit::testing::contains;

bool bitIdentical(const TriMesh& a, const TriMesh& b) { return a.faces == b.faces && testing::bitIdentical(a.vertices, b.vertices); }

// ---------------------------------------------------------------------------------------------
// writeMesh dispatch

TEST(MeshIo, WriteMeshTriIsFormatTri) {
    const TriMesh mesh = makeIcoSphere(1.3, 1);
    TempDir dir;
    for (const char* name : {"ico.tri", "ICO2.TRI", "ico3.Tri"}) {
        const fs::path file = dir.path() / name;
        writeMesh(mesh, file);
        EXPECT_EQ(slurp(file), formatTri(mesh)) << name;
        EXPECT_TRUE(bitIdentical(readMesh(file).mesh, mesh)) << name;
    }
}

TEST(MeshIo, WriteMeshObjIsWriteObj) {
    const TriMesh mesh = makeTorus(3.0, 1.0, 5, 4);
    TempDir dir;
    const fs::path viaDispatch = dir.path() / "a.obj", direct = dir.path() / "b.obj", upper = dir.path() / "c.OBJ";
    writeMesh(mesh, viaDispatch);
    writeObj(mesh, direct);
    writeMesh(mesh, upper);
    const std::string text = slurp(viaDispatch);
    EXPECT_EQ(text, slurp(direct));
    EXPECT_EQ(text, slurp(upper));
    EXPECT_EQ(text.rfind("# written by flexfit\n", 0), 0u);
    EXPECT_TRUE(contains(text, "\no torus\n"));
    EXPECT_TRUE(contains(text, "\nf 1 5 6\n"));  // 1-based: the first face (0 4 5)
    const MeshReadResult r = readMesh(viaDispatch);
    EXPECT_EQ(r.mesh.vertices.size(), 20u);
    EXPECT_EQ(r.mesh.faces.size(), 40u);
    EXPECT_EQ(r.diagnostics.edgeCount, 60u);
    EXPECT_TRUE(r.diagnostics.closed());
}

TEST(MeshIo, WriteMeshRejectsOtherExtensions) {
    const TriMesh mesh = makeIcoSphere(1.0, 0);
    TempDir dir;
    for (const char* name : {"out.stl", "out.ply", "out.gltf", "out", "out.tri.bak"}) {
        const fs::path file = dir.path() / name;
        try {
            writeMesh(mesh, file);
            ADD_FAILURE() << name << " accepted";
        } catch (const InputError& e) {
            EXPECT_EQ(e.source(), file.string());
            EXPECT_TRUE(contains(e.problem(), "supported output formats are .tri and .obj")) << e.problem();
        }
        EXPECT_FALSE(fs::exists(file)) << name << ": nothing may be written";
    }
}

TEST(MeshIo, WritersRejectUnwritablePaths) {
    const TriMesh mesh = makeIcoSphere(1.0, 0);
    TempDir dir;
    const fs::path missingDir = dir.path() / "no" / "such" / "dir";
    EXPECT_THROW(writeMesh(mesh, missingDir / "m.tri"), InputError);
    EXPECT_THROW(writeMesh(mesh, missingDir / "m.obj"), InputError);
    EXPECT_THROW(writeObj(mesh, dir.path()), InputError);  // a directory
    EXPECT_THROW(writeTri(mesh, dir.path()), InputError);
}

// Runs `write` as a full disk would let it: with the file-size limit at 0 (SIGXFSZ ignored, so
// a write fails with EFBIG instead of ending the process); the limit and the signal's handling
// are restored before it returns.
template <class Write>
void withNoRoomToWrite(Write write) {
    rlimit old{};
    ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
    struct sigaction ignore {}, previous{};
    ignore.sa_handler = SIG_IGN;
    ::sigaction(SIGXFSZ, &ignore, &previous);
    rlimit none = old;
    none.rlim_cur = 0;
    ::setrlimit(RLIMIT_FSIZE, &none);
    write();
    ::setrlimit(RLIMIT_FSIZE, &old);
    ::sigaction(SIGXFSZ, &previous, nullptr);
}

std::vector<std::string> namesIn(const fs::path& dir) {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

// A write that fails at its end (the last buffer, flushed when the file closes) is an error, and
// leaves the earlier file as it was, or none, and no temporary: `flexfit convert` once reported
// success and left an empty or cut-off mesh.
TEST(MeshIo, AFailedWriteLeavesTheEarlierFileOrNone) {
    const TriMesh mesh = makeIcoSphere(1.0, 1);
    TempDir dir;
    const fs::path earlier = dir.write("earlier.obj", "earlier\n");
    std::vector<std::string> errors;
    withNoRoomToWrite([&] {
        for (const fs::path& file : {earlier, dir.path() / "new.tri", dir.path() / "new.obj"}) {
            try {
                writeMesh(mesh, file);
                errors.push_back("no error for " + file.string());
            } catch (const InputError& e) {
                if (e.source() != file.string() || e.problem() != "write failed") errors.push_back(e.what());
            }
        }
    });
    EXPECT_TRUE(errors.empty()) << errors.front();
    std::ifstream in(earlier);
    EXPECT_EQ(std::string(std::istreambuf_iterator<char>(in), {}), "earlier\n");
    EXPECT_EQ(namesIn(dir.path()), std::vector<std::string>{"earlier.obj"});
    if (fs::exists("/dev/full")) {  // a device is written in place, and its failure seen
        EXPECT_THROW(writeObj(mesh, "/dev/full"), InputError);
        EXPECT_THROW(writeTri(mesh, "/dev/full"), InputError);
    }
    writeMesh(mesh, earlier);  // with room, the file is replaced whole
    EXPECT_EQ(readMesh(earlier).mesh.faces.size(), mesh.faces.size());
    EXPECT_EQ(namesIn(dir.path()), std::vector<std::string>{"earlier.obj"});
}

// An OBJ reader continues a line that ends in a backslash: a model named "C:\parts\" would
// swallow the first vertex. Line breaks would start a line of their own.
TEST(MeshIo, ObjectNamesStayOnTheirLine) {
    EXPECT_EQ(objObjectName("C:\\parts\\"), "C:\\parts_");
    EXPECT_EQ(objObjectName("two\nlines\r"), "two lines ");
    EXPECT_EQ(objObjectName("plain"), "plain");
    TempDir dir;
    for (const std::string name : {"C:\\parts\\", "a\nb"}) {
        TriMesh mesh = makeIcoSphere(1.0, 0);
        mesh.name = name;
        writeObj(mesh, dir.path() / "m.obj");
        const MeshReadResult back = readMesh(dir.path() / "m.obj");
        EXPECT_EQ(back.mesh.vertices.size(), mesh.vertices.size()) << name;
        EXPECT_EQ(back.mesh.faces.size(), mesh.faces.size()) << name;
    }
}

// ---------------------------------------------------------------------------------------------
// readMesh of .tri

// Tetrahedron whose vertex 0 is split: vertex 4 lies 1e-9 from vertex 0 and face (0 1 3) uses it.
const std::string kSplitTet =
    "split tet\n5 4\n"
    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1e-9 0 0\n"
    "0 2 1\n4 1 3\n0 3 2\n1 2 3\n";

TEST(MeshIo, ReadMeshTriRepairsANearDuplicateByDefault) {
    TempDir dir;
    const fs::path file = dir.write("split.tri", kSplitTet);
    // Vertex 4 lies 1e-9 from vertex 0, within 1e-6 of the diagonal: a crack, welded and reported.
    const MeshReadResult r = readMesh(file);
    EXPECT_EQ(r.mesh.name, "split tet");
    EXPECT_EQ(r.mesh.vertices.size(), 4u);
    EXPECT_EQ(r.weldedVertices, 0u);  // none asked for
    EXPECT_EQ(r.repairs.weldedVertices, 1u);
    EXPECT_DOUBLE_EQ(r.repairs.weldTolerance, 1e-6 * std::sqrt(3.0));
    EXPECT_TRUE(r.diagnostics.closed());
    ASSERT_EQ(r.diagnostics.warnings.size(), 1u);
    EXPECT_TRUE(contains(r.diagnostics.warnings[0], "1 vertex welded")) << r.diagnostics.warnings[0];
    // Strict: refused, naming both vertices and the line of the later one.
    try {
        readMesh(file, MeshReadOptions{.weldTolerance = std::nullopt, .repair = false});
        ADD_FAILURE() << "accepted a near-duplicate vertex";
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), 7u);
        EXPECT_TRUE(contains(e.problem(), "vertex 4 (line 7) is within")) << e.problem();
        EXPECT_TRUE(contains(e.problem(), "of vertex 0 (line 3)")) << e.problem();
    }
    // Welding asked for at 0 (identical positions only) keeps the split, as the file says.
    const MeshReadResult exact = readMesh(file, MeshReadOptions{0.0});
    EXPECT_EQ(exact.mesh.vertices.size(), 5u);
    EXPECT_EQ(exact.weldedVertices, 0u);
    EXPECT_EQ(exact.diagnostics.edgeCount, 8u);  // 6 + the split edges 4-1, 4-3
    EXPECT_EQ(exact.diagnostics.boundaryEdges, 4u);
    EXPECT_FALSE(exact.diagnostics.closed());
}

TEST(MeshIo, ReadMeshTriWeldsWithinTolerance) {
    TempDir dir;
    const fs::path file = dir.write("split.tri", kSplitTet);
    // Below the gap: still split.
    const MeshReadResult tight = readMesh(file, MeshReadOptions{1e-10});
    EXPECT_EQ(tight.mesh.vertices.size(), 5u);
    EXPECT_EQ(tight.weldedVertices, 0u);
    EXPECT_FALSE(tight.diagnostics.closed());
    // Above the gap: welded into the closed tetrahedron, keeping vertex 0 (the first).
    const MeshReadResult r = readMesh(file, MeshReadOptions{1e-6});
    ASSERT_EQ(r.mesh.vertices.size(), 4u);
    EXPECT_EQ(r.mesh.vertices[0], Vec3(0, 0, 0));
    EXPECT_EQ(r.weldedVertices, 1u);
    EXPECT_EQ(r.collapsedFaces, 0u);
    EXPECT_EQ(r.mesh.faces[1], (Face{0, 1, 3}));
    EXPECT_EQ(r.diagnostics.edgeCount, 6u);
    EXPECT_TRUE(r.diagnostics.closed());
    EXPECT_TRUE(r.diagnostics.warnings.empty());
    EXPECT_EQ(r.mesh.name, "split tet");
}

TEST(MeshIo, ReadMeshTriWeldingCollapsesFaces) {
    TempDir dir;
    // The tetrahedron plus a sliver face (0 4 2), vertex 4 1e-4 from vertex 0.
    const std::string text =
        "sliver\n5 5\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1e-4 0 0\n0 2 1\n0 1 3\n0 3 2\n1 2 3\n0 4 2\n";
    const fs::path file = dir.write("sliver.tri", text);
    const MeshReadResult before = readMesh(file);
    EXPECT_EQ(before.diagnostics.nonManifoldEdges, 1u);
    const MeshReadResult r = readMesh(file, MeshReadOptions{1e-3});
    EXPECT_EQ(r.weldedVertices, 1u);
    EXPECT_EQ(r.collapsedFaces, 1u);
    EXPECT_EQ(r.mesh.faces.size(), 4u);
    EXPECT_TRUE(r.diagnostics.closed());
    // A tolerance as large as the mesh collapses every face: said so, not "empty mesh".
    try {
        readMesh(file, MeshReadOptions{1e300});
        ADD_FAILURE() << "every face collapsed, yet the mesh was read";
    } catch (const InputError& e) {
        EXPECT_EQ(e.problem(), "welding within 1e+300 collapsed all 5 faces: the weld tolerance is as large as the mesh");
    }
}

TEST(MeshIo, ReadMeshTriWeldingThatMakesDuplicatesIsRepairedOrRefused) {
    TempDir dir;
    // Welding at 0.6 merges vertex 3 into vertex 0 (and into no other): the two faces become duplicates.
    const std::string text = "dup\n4 2\n0 0 0\n1 0 0\n0 1 0\n0 0 0.5\n0 1 2\n3 1 2\n";
    const fs::path file = dir.write("dup.tri", text);
    EXPECT_EQ(readMesh(file).mesh.faces.size(), 2u);
    const MeshReadResult r = readMesh(file, MeshReadOptions{0.6});
    EXPECT_EQ(r.weldedVertices, 1u);
    EXPECT_EQ(r.repairs.duplicateFaces, 1u);
    EXPECT_EQ(r.mesh.faces.size(), 1u);
    try {
        readMesh(file, MeshReadOptions{.weldTolerance = 0.6, .repair = false});
        ADD_FAILURE() << "accepted duplicate faces after welding";
    } catch (const InputError& e) {
        EXPECT_EQ(e.source(), file.string());
        EXPECT_TRUE(contains(e.problem(), "duplicates")) << e.problem();
    }
}

TEST(MeshIo, ReadMeshTriErrorsCarryTheLine) {
    TempDir dir;
    const fs::path file = dir.write("bad.tri", "tet\n4 4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 2 1\n0 1 3\n0 3 9\n1 2 3\n");
    for (double tolerance : {0.0, 1e-6}) {
        try {
            readMesh(file, MeshReadOptions{tolerance});
            ADD_FAILURE() << "accepted";
        } catch (const InputError& e) {
            EXPECT_EQ(e.source(), file.string());
            EXPECT_EQ(e.line(), 9u);
            EXPECT_TRUE(contains(e.problem(), "out of range")) << e.problem();
        }
    }
}

TEST(MeshIo, ReadMeshRejectsBadWeldTolerance) {
    TempDir dir;
    const fs::path file = dir.path() / "t.tri";
    writeTri(makeIcoSphere(1.0, 0), file);
    for (double bad : {-1.0, -1e-300, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
        try {
            readMesh(file, MeshReadOptions{bad});
            ADD_FAILURE() << bad << " accepted";
        } catch (const InputError& e) {
            EXPECT_TRUE(contains(e.problem(), "weld tolerance")) << e.problem();
        }
    }
}

TEST(MeshIo, ReadMeshMissingTriFile) {
    const fs::path missing = fs::temp_directory_path() / "flexfit_mesh_io_test_missing.tri";
    try {
        readMesh(missing);
        ADD_FAILURE() << "accepted a missing file";
    } catch (const InputError& e) {
        EXPECT_EQ(e.source(), missing.string());
        EXPECT_TRUE(contains(e.problem(), "cannot open")) << e.problem();
    }
}

TEST(MeshIo, ReadMeshOfADirectoryThrows) {
    TempDir dir;
    for (const char* name : {"d.tri", "d.obj", "d.stl", "no_extension"}) {  // the same words whatever the reader
        const fs::path sub = dir.path() / name;
        fs::create_directories(sub);
        try {
            readMesh(sub);
            ADD_FAILURE() << name << " accepted";
        } catch (const InputError& e) {
            EXPECT_EQ(e.source(), sub.string());
            EXPECT_NE(e.problem().find("not a regular file"), std::string::npos) << e.problem();
        }
    }
}

TEST(MeshIo, TriAndObjOfTheSameMeshAgree) {
    // Float-representable coordinates, so that a single-precision assimp reads the OBJ exactly.
    TriMesh mesh = makeIcoSphere(2.0, 2);
    for (Vec3& v : mesh.vertices) v = toFloatPrecision(v);
    TempDir dir;
    writeMesh(mesh, dir.path() / "m.tri");
    writeMesh(mesh, dir.path() / "m.obj");
    const MeshReadResult tri = readMesh(dir.path() / "m.tri");
    const MeshReadResult obj = readMesh(dir.path() / "m.obj");
    EXPECT_EQ(tri.mesh.vertices.size(), obj.mesh.vertices.size());
    EXPECT_EQ(tri.mesh.faces.size(), obj.mesh.faces.size());
    EXPECT_EQ(tri.diagnostics.edgeCount, obj.diagnostics.edgeCount);
    EXPECT_EQ(boundingBox(tri.mesh).min(), boundingBox(obj.mesh).min());
    EXPECT_EQ(boundingBox(tri.mesh).max(), boundingBox(obj.mesh).max());
    // The faces agree as sets of positions, in order.
    for (std::size_t f = 0; f < tri.mesh.faces.size(); ++f)
        for (int k = 0; k < 3; ++k)
            EXPECT_EQ(tri.mesh.vertices[tri.mesh.faces[f][k]], obj.mesh.vertices[obj.mesh.faces[f][k]]);
}

// ---------------------------------------------------------------------------------------------
// The file's vertices (MeshReadResult::fileVertices) through the format's welding and the repair

// An icosphere as a file might give it: a stray vertex no face uses in the middle of the list,
// a vertex repeated exactly (split normals; welded by OBJ / OFF / PLY's format welding, by the
// repair in .tri) and one repeated 1e-9 away (welded by the repair), each used by one face.
TriMesh damagedSphere() {
    TriMesh mesh = makeIcoSphere(1.0, 1);
    mesh.vertices.insert(mesh.vertices.begin() + 7, Vec3(5, 5, 5));
    for (Face& f : mesh.faces)
        for (Index& v : f) v += v >= 7 ? 1 : 0;
    const Index exact = mesh.faces[3][1], near = mesh.faces[20][2];
    mesh.vertices.push_back(mesh.vertices[exact]);
    mesh.faces[3][1] = Index(mesh.vertices.size() - 1);
    mesh.vertices.push_back(mesh.vertices[near] + Vec3(1e-9, 0, 0));
    mesh.faces[20][2] = Index(mesh.vertices.size() - 1);
    return mesh;
}

std::string asText(const TriMesh& mesh, const std::string& format) {
    std::ostringstream out;
    char line[128];
    const std::size_t base = format == "obj" ? 1 : 0;
    if (format == "tri") out << "damaged\n" << mesh.vertices.size() << " " << mesh.faces.size() << "\n";
    if (format == "off") out << "OFF\n" << mesh.vertices.size() << " " << mesh.faces.size() << " 0\n";
    if (format == "ply")
        out << "ply\nformat ascii 1.0\nelement vertex " << mesh.vertices.size() << "\nproperty double x\nproperty double y\nproperty double z\n"
            << "element face " << mesh.faces.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (const Vec3& v : mesh.vertices) {
        std::snprintf(line, sizeof line, "%s%.17g %.17g %.17g\n", format == "obj" ? "v " : "", v.x(), v.y(), v.z());
        out << line;
    }
    for (const Face& f : mesh.faces)
        out << (format == "obj" ? "f " : format == "tri" ? "" : "3 ") << f[0] + base << " " << f[1] + base << " " << f[2] + base << "\n";
    return out.str();
}

TEST(MeshIo, FileVerticesFollowEveryWeldAndRemovalInEveryFormat) {
    TempDir dir;
    const TriMesh file = damagedSphere();
    for (const std::string format : {"tri", "obj", "off", "ply"}) {
        const MeshReadResult r = readMesh(dir.write("damaged." + format, asText(file, format)));
        ASSERT_EQ(r.mesh.vertices.size(), file.vertices.size() - 3) << format;
        const FileVertices& fv = r.fileVertices;
        ASSERT_EQ(fv.count(), file.vertices.size()) << format;
        EXPECT_EQ(fv.positions, file.vertices) << format << ": the file's positions, as read";
        // Brute force: a vertex some face of the file uses goes to the mesh vertex closest to it
        // (within the weld tolerance); the stray one is removed.
        for (std::size_t u = 0; u < fv.count(); ++u) {
            if (u == 7) {
                EXPECT_EQ(fv.meshVertex[u], kNoVertex) << format;
                continue;
            }
            std::size_t closest = 0;
            for (std::size_t v = 1; v < r.mesh.vertices.size(); ++v)
                if ((r.mesh.vertices[v] - file.vertices[u]).norm() < (r.mesh.vertices[closest] - file.vertices[u]).norm()) closest = v;
            EXPECT_EQ(fv.meshVertex[u], closest) << format << " file vertex " << u;
            EXPECT_LT((r.mesh.vertices[closest] - file.vertices[u]).norm(), 1e-8) << format;
        }
        // The mesh in the file's numbering has the file's faces but for the welded corners.
        const TriMesh numbered = inFileOrder(r.mesh, fv);
        ASSERT_EQ(numbered.faces.size(), file.faces.size()) << format;
        std::size_t differing = 0;
        for (std::size_t f = 0; f < file.faces.size(); ++f) differing += numbered.faces[f] != file.faces[f];
        EXPECT_EQ(differing, 2u) << format << ": faces 3 and 20 name the first vertex at the repeated positions";
    }
    // A clean file: the mesh's vertices are the file's, no map.
    const MeshReadResult clean = readMesh(dir.write("clean.obj", asText(makeIcoSphere(1.0, 1), "obj")));
    EXPECT_TRUE(clean.fileVertices.empty());
}

// STL stores one vertex per face corner: its welded vertices (first-use order) are the file's
// numbering, so a clean STL has no map, and one whose repair welds a near-duplicate maps the
// welded vertices, not its 3F corners.
TEST(MeshIo, StlIsNumberedByItsWeldedVertices) {
    TempDir dir;
    TriMesh sphere = makeIcoSphere(1.0, 1);
    const auto stl = [](const TriMesh& mesh) {
        std::ostringstream out;
        out << "solid s\n";
        char line[160];
        for (const Face& f : mesh.faces) {
            out << "facet normal 0 0 0\nouter loop\n";
            for (Index v : f) {
                std::snprintf(line, sizeof line, "vertex %.9g %.9g %.9g\n", mesh.vertices[v].x(), mesh.vertices[v].y(), mesh.vertices[v].z());
                out << line;
            }
            out << "endloop\nendfacet\n";
        }
        out << "endsolid s\n";
        return out.str();
    };
    const MeshReadResult clean = readMesh(dir.write("clean.stl", stl(sphere)));
    EXPECT_EQ(clean.mesh.vertices.size(), sphere.vertices.size());
    EXPECT_TRUE(clean.fileVertices.empty());
    // Face 7's first corner written 1e-6 away (a crack the repair welds; float-exact apart).
    TriMesh cracked = sphere;
    cracked.vertices.push_back(sphere.vertices[sphere.faces[7][0]] + Vec3(1e-6, 0, 0));
    cracked.faces[7][0] = Index(cracked.vertices.size() - 1);
    const MeshReadResult r = readMesh(dir.write("cracked.stl", stl(cracked)));
    EXPECT_EQ(r.mesh.vertices.size(), sphere.vertices.size());
    EXPECT_EQ(r.repairs.weldedVertices, 1u);
    EXPECT_EQ(r.fileVertices.count(), sphere.vertices.size() + 1) << "the welded vertices, not the 3F corners";
}


// ---------------------------------------------------------------------------------------------
// Fuzz: mutations of valid OBJ, OFF, PLY and STL files (ASCII and binary; STL through assimp)
// either read to a valid mesh
// (validateMesh passes again, every coordinate finite) or throw InputError with a problem;
// nothing else may escape, and the sanitizer build checks that nothing reads out of bounds.

// A binary little-endian PLY tetrahedron: double coordinates, a colour byte, uint indices.
std::string binaryPlyTetrahedron() {
    std::string out = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
                      "property double z\nproperty uchar red\nelement face 4\nproperty list uchar uint vertex_indices\nend_header\n";
    const double corners[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const std::uint32_t faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    const auto append = [&](const void* p, std::size_t n) { out.append(static_cast<const char*>(p), n); };
    for (const auto& c : corners) append(c, sizeof c), out.push_back('\7');
    for (const auto& f : faces) out.push_back('\3'), append(f, sizeof f);
    return out;
}

// The same tetrahedron as an ASCII STL (one vertex per face corner) and a binary one (float
// corners, a zero normal and attribute count per face), which assimp reads and readMesh welds.
std::string asciiStlTetrahedron() {
    return "solid tet\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\nendfacet\n"
           "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\nendloop\nendfacet\n"
           "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\nvertex 0 1 0\nendloop\nendfacet\n"
           "facet normal 0 0 0\nouter loop\nvertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1\nendloop\nendfacet\nendsolid tet\n";
}

std::string binaryStlTetrahedron() {
    std::string out(80, ' ');
    const auto append = [&](const void* p, std::size_t n) { out.append(static_cast<const char*>(p), n); };
    const std::uint32_t count = 4;
    append(&count, sizeof count);
    const float corners[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    const float normal[3] = {0, 0, 0};
    const std::uint16_t attributes = 0;
    for (const auto& f : faces) {
        append(normal, sizeof normal);
        for (int v : f) append(corners[v], sizeof corners[v]);
        append(&attributes, sizeof attributes);
    }
    return out;
}

// 1 when read, 0 when refused with InputError; a test failure otherwise.
int readOrReject(const fs::path& file, bool repair, const std::string& label) {
    return flexfit::testing::readOrRefused([&] {
        MeshReadOptions options;
        options.repair = repair;
        const MeshReadResult r = readMesh(file, options);
        EXPECT_NO_THROW(validateMesh(r.mesh, "again")) << label;
        for (const Vec3& p : r.mesh.vertices) EXPECT_TRUE(p.allFinite()) << label;
        EXPECT_FALSE(r.mesh.faces.empty()) << label;
    }, label);
}

TEST(MeshIoFuzz, MutationsOfValidObjOffPlyAndStlFiles) {
    const std::string obj = "# tet\no tet\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 1\nvt 0 0\n"
                            "f 1/1/1 3/1/1 2/1/1\nf 1//1 2//1 4//1\nf -4 -1 -2\nf 2 3 4\n";
    const std::string quadObj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                                "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    const std::string off = "OFF\n# tet\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3 255 0 0\n3 0 3 2\n3 1 2 3\n";
    const std::string ply = "ply\nformat ascii 1.0\ncomment tet\nelement vertex 4\nproperty float x\nproperty float y\n"
                            "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
                            "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    const std::string interesting = "0123456789 -+./\n\r\tenaifvpOFsoldtcrx";
    const struct {
        std::string name, text;
    } seeds[] = {{"tet.obj", obj},      {"box.obj", quadObj}, {"tet.off", off}, {"tet.ply", ply}, {"binary.ply", binaryPlyTetrahedron()},
                 {"tet.stl", asciiStlTetrahedron()}, {"binary.stl", binaryStlTetrahedron()}};
    TempDir dir;
    std::mt19937 rng(20261206u);
    for (const auto& seed : seeds) {
        const fs::path file = dir.write(seed.name, seed.text);
        ASSERT_EQ(readOrReject(file, true, seed.name), 1);
        int read = 0;
        for (int i = 0; i < 1500; ++i) {
            dir.write(seed.name, flexfit::testing::mutated(seed.text, rng, interesting));
            read += readOrReject(file, i % 2 == 0, seed.name + " mutation " + std::to_string(i));
            if (::testing::Test::HasFailure()) return;
        }
        // Some mutations (comments, whitespace) leave the file valid; most do not.
        EXPECT_GT(read, 0) << seed.name;
        EXPECT_LT(read, 1500) << seed.name;
    }
}

}  // namespace
}  // namespace flexfit
