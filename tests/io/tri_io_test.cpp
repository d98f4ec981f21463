// Tests the .tri reader and writer (parseTri, formatTri, readTri, writeTri) against the SPEC.md format: exact round trips of generated meshes, one test per malformed class (line and phrase), and a fixed-seed fuzz.
#include "flexfit/generators.hpp"
#include "float_precision.hpp"
#include "mutations.hpp"
#include "strings.hpp"
#include "flexfit/mesh_io.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace flexfit {
namespace {

namespace fs = std::filesystem;

// A unique path in the system temp directory, removed when the object goes out of scope.
class TempFile {
public:
    explicit TempFile(const std::string& suffix) {
        static int counter = 0;
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        path_ = fs::temp_directory_path() / ("flexfit_tri_io_test_" + std::to_string(::getpid()) + "_" +
                                             (info ? std::string(info->name()) : "x") + "_" +
                                             std::to_string(counter++) + suffix);
    }
    ~TempFile() {
        std::error_code ec;
        fs::remove(path_, ec);
    }
    TempFile(const TempFile&) = delete;
    TempFile& operator=(const TempFile&) = delete;
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

using flexfit::testing::contains;

using flexfit::testing::bitIdentical;

// A valid tetrahedron; line numbers: name 1, counts 2, vertices 3-6, faces 7-10.
const std::string kTet =
    "tet\n"
    "4 4\n"
    "0 0 0\n"
    "1 0 0\n"
    "0 1 0\n"
    "0 0 1\n"
    "0 2 1\n"
    "0 1 3\n"
    "0 3 2\n"
    "1 2 3\n";

void expectTetrahedron(const MeshReadResult& r) {
    EXPECT_EQ(r.mesh.name, "tet");
    ASSERT_EQ(r.mesh.vertices.size(), 4u);
    ASSERT_EQ(r.mesh.faces.size(), 4u);
    EXPECT_EQ(r.mesh.vertices[1], Vec3(1, 0, 0));
    EXPECT_EQ(r.mesh.vertices[3], Vec3(0, 0, 1));
    EXPECT_EQ(r.mesh.faces[0], (Face{0, 2, 1}));
    EXPECT_EQ(r.mesh.faces[3], (Face{1, 2, 3}));
    EXPECT_EQ(r.diagnostics.edgeCount, 6u);
    EXPECT_TRUE(r.diagnostics.closed());
    EXPECT_TRUE(r.diagnostics.warnings.empty());
    EXPECT_EQ(r.weldedVertices, 0u);
    EXPECT_EQ(r.collapsedFaces, 0u);
}

// parseTri must throw InputError naming the source, at `line`, with `phrase` in the problem.
void expectParseError(const std::string& text, std::size_t line, const std::string& phrase, const MeshReadOptions& options = {}) {
    try {
        parseTri(text, "bad.tri", options);
        ADD_FAILURE() << "accepted:\n" << text;
    } catch (const InputError& e) {
        EXPECT_EQ(e.source(), "bad.tri");
        EXPECT_EQ(e.line(), line) << e.what();
        EXPECT_TRUE(contains(e.problem(), phrase)) << "expected '" << phrase << "' in: " << e.problem();
        EXPECT_TRUE(contains(e.what(), "bad.tri")) << e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "not an InputError: " << e.what();
    }
}

// kTet with line `lineNumber` (1-based) replaced.
std::string tetWithLine(std::size_t lineNumber, const std::string& replacement) {
    std::istringstream in(kTet);
    std::string out, line;
    for (std::size_t n = 1; std::getline(in, line); ++n) out += (n == lineNumber ? replacement : line) + "\n";
    return out;
}

// ---------------------------------------------------------------------------------------------
// Valid input

TEST(TriIo, ParsesTheTetrahedron) { expectTetrahedron(parseTri(kTet, "tet.tri")); }

TEST(TriIo, CountsOnOneLineOrTwo) {
    expectTetrahedron(parseTri(tetWithLine(2, "4\n4"), "two-lines.tri"));
    expectTetrahedron(parseTri(tetWithLine(2, "  4 \t 4  "), "spaces.tri"));
}

TEST(TriIo, BlankLinesTolerated) {
    std::string text = "tet\n\n\n4\n\n4\n";
    text += "0 0 0\n\n1 0 0\n  \t \n0 1 0\n0 0 1\n\n";
    text += "0 2 1\n0 1 3\n\n\n0 3 2\n1 2 3\n\n   \n\n";
    expectTetrahedron(parseTri(text, "blank.tri"));
    // No final end of line.
    std::string noFinalNewline = kTet;
    noFinalNewline.pop_back();
    expectTetrahedron(parseTri(noFinalNewline, "no-eol.tri"));
}

TEST(TriIo, CrlfTolerated) {
    std::string crlf;
    for (char c : kTet) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    expectTetrahedron(parseTri(crlf, "crlf.tri"));
    // Line numbers still count CRLF lines: an error on line 9.
    std::string bad;
    for (char c : tetWithLine(9, "0 3 x")) bad += c == '\n' ? std::string("\r\n") : std::string(1, c);
    expectParseError(bad, 9, "not a non-negative integer");
}

TEST(TriIo, TabsAndNumberFormats) {
    const std::string text =
        "  tet with spaces  \n4 4\n"
        "0.0\t0e0\t-0\n1.000000000000000000000 0 0\n0 1E0 0\n0 0 .1e1\n"
        "0 2 1\n0 1 3\n0 3 2\n001 2 3\n";
    const MeshReadResult r = parseTri(text, "formats.tri");
    EXPECT_EQ(r.mesh.name, "tet with spaces");  // trimmed
    EXPECT_EQ(r.mesh.vertices[1], Vec3(1, 0, 0));
    EXPECT_EQ(r.mesh.vertices[3], Vec3(0, 0, 1));
    EXPECT_EQ(r.mesh.faces[3], (Face{1, 2, 3}));
}

TEST(TriIo, OpenAndNonManifoldMeshesAreAcceptedWithWarnings) {
    const MeshReadResult r = parseTri("tri\n3 1\n0 0 0\n1 0 0\n0 1 0\n0 1 2\n", "tri.tri");
    EXPECT_EQ(r.diagnostics.boundaryEdges, 3u);
    EXPECT_FALSE(r.diagnostics.warnings.empty());
    const MeshReadResult n = parseTri(
        "fan\n5 3\n0 0 0\n1 0 0\n0.5 1 0\n0.5 -1 0\n0.5 0 1\n0 1 2\n1 0 3\n0 1 4\n", "fan.tri");
    EXPECT_EQ(n.diagnostics.nonManifoldEdges, 1u);
}

// ---------------------------------------------------------------------------------------------
// Round trips

TEST(TriIo, FormatParseRoundTripIsBitExact) {
    std::vector<TriMesh> meshes = {makeTorus1(), makeTorus2(), makeIcoSphere(1.7, 2), makeUvSphere(0.3, 9, 5),
                                   makeHeart(20.0, 30, 20), makeContainerMouth()};
    // Coordinates with awkward magnitudes and bit patterns.
    TriMesh noisy = makeTorus(3.0, 1.0, 12, 8);
    noisy.name = "noisy";
    std::mt19937 rng(99u);
    std::uniform_real_distribution<double> jitter(-1e-3, 1e-3);
    for (Vec3& v : noisy.vertices) v += Vec3(jitter(rng), jitter(rng), jitter(rng));
    meshes.push_back(noisy);
    TriMesh tiny = makeIcoSphere(3e-20, 1);  // near kMinMeshSize, kMaxMeshCoordinate
    tiny.name = "tiny";
    meshes.push_back(tiny);
    TriMesh huge = makeIcoSphere(0.99e20, 1);
    huge.name = "huge";
    meshes.push_back(huge);
    for (const TriMesh& mesh : meshes) {
        SCOPED_TRACE(mesh.name);
        const MeshReadResult r = parseTri(formatTri(mesh), mesh.name);
        EXPECT_EQ(r.mesh.name, mesh.name);
        EXPECT_TRUE(bitIdentical(r.mesh.vertices, mesh.vertices));
        EXPECT_EQ(r.mesh.faces, mesh.faces);
        // The text is a fixed point.
        EXPECT_EQ(formatTri(r.mesh), formatTri(mesh));
    }
}

TEST(TriIo, FormatTriLayout) {
    TriMesh mesh;
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 0.1, 0}};
    mesh.faces = {{0, 1, 2}};
    const std::string text = formatTri(mesh);
    EXPECT_EQ(text, "unnamed\n3 1\n0 0 0\n1 0 0\n0 0.10000000000000001 0\n0 1 2\n");
    mesh.name = "two\nlines\r";
    const MeshReadResult r = parseTri(formatTri(mesh), "x");
    EXPECT_EQ(r.mesh.name, "two lines");
    EXPECT_EQ(r.mesh.vertices, mesh.vertices);
}

TEST(TriIo, WriteReadThroughATempFile) {
    for (const TriMesh& mesh : {makeTorus1(), makeIcoSphere(2.0, 1)}) {
        TempFile file(".tri");
        writeTri(mesh, file.path());
        ASSERT_TRUE(fs::exists(file.path()));
        const MeshReadResult r = readTri(file.path());
        EXPECT_EQ(r.mesh.name, mesh.name);
        EXPECT_TRUE(bitIdentical(r.mesh.vertices, mesh.vertices));
        EXPECT_EQ(r.mesh.faces, mesh.faces);
        EXPECT_TRUE(r.diagnostics.closed());
    }
}

TEST(TriIo, ReadErrorsNameTheFile) {
    TempFile file(".tri");
    {
        std::ofstream out(file.path(), std::ios::binary);
        out << tetWithLine(5, "0 nan 0");
    }
    try {
        readTri(file.path());
        ADD_FAILURE() << "accepted a NaN";
    } catch (const InputError& e) {
        EXPECT_EQ(e.source(), file.path().string());
        EXPECT_EQ(e.line(), 5u);
    }
}

TEST(TriIo, MissingFileAndUnwritablePath) {
    const fs::path missing = fs::temp_directory_path() / "flexfit_tri_io_test_no_such_dir" / "missing.tri";
    EXPECT_THROW(readTri(missing), InputError);
    EXPECT_THROW(writeTri(makeIcoSphere(1.0, 0), missing), InputError);
    EXPECT_FALSE(fs::exists(missing.parent_path()));
}

// ---------------------------------------------------------------------------------------------
// Malformed input: one test per class, with the line and a phrase of the problem.

TEST(TriIoErrors, EmptyFile) {
    expectParseError("", 0, "empty file");
    expectParseError(" \n\t\r\n\n", 0, "empty file");
}

TEST(TriIoErrors, MissingCounts) {
    expectParseError("tet\n", 1, "expected the vertex and face counts");
    expectParseError("tet", 1, "expected the vertex and face counts");
    expectParseError("tet\n\n\n", 3, "expected the vertex and face counts");
}

TEST(TriIoErrors, MissingFaceCount) { expectParseError("tet\n4\n", 2, "expected the face count"); }

TEST(TriIoErrors, TooManyCountValues) { expectParseError(tetWithLine(2, "4 4 4"), 2, "found 3 values"); }

TEST(TriIoErrors, NonIntegerCount) {
    expectParseError(tetWithLine(2, "4.0 4"), 2, "vertex count '4.0' is not a non-negative integer");
    expectParseError(tetWithLine(2, "-4 4"), 2, "vertex count '-4' is not a non-negative integer");
    expectParseError(tetWithLine(2, "four 4"), 2, "is not a non-negative integer");
    expectParseError(tetWithLine(2, "4 4x"), 2, "face count '4x' is not a non-negative integer");
    expectParseError(tetWithLine(2, "4\n+4"), 3, "face count '+4' is not a non-negative integer");
    expectParseError(tetWithLine(2, "99999999999999999999999 4"), 2, "is not a non-negative integer");
}

TEST(TriIoErrors, VertexCountAboveTheIndexRange) {
    expectParseError(tetWithLine(2, "4294967296 4"), 2, "exceeds the supported maximum");
}

TEST(TriIoErrors, VertexLineWithTwoValues) {
    expectParseError(tetWithLine(4, "1 0"), 4, "vertex 1 needs 3 coordinates, found 2");
}

TEST(TriIoErrors, VertexLineWithFourValues) {
    expectParseError(tetWithLine(4, "1 0 0 0"), 4, "vertex 1 needs 3 coordinates, found 4");
}

TEST(TriIoErrors, NonNumericCoordinate) {
    expectParseError(tetWithLine(4, "1 x 0"), 4, "coordinate 'x' is not a number");
    expectParseError(tetWithLine(5, "0 1,5 0"), 5, "is not a number");
    expectParseError(tetWithLine(6, "0 0 1f"), 6, "is not a number");
    expectParseError(tetWithLine(6, "0 0 0x1"), 6, "is not a number");
}

TEST(TriIoErrors, CoordinateOutOfDoubleRange) {
    expectParseError(tetWithLine(5, "0 1e999 0"), 5, "out of the range of a double");
}

TEST(TriIoErrors, NaNCoordinate) {
    expectParseError(tetWithLine(5, "0 nan 0"), 5, "NaN or infinite");
    expectParseError(tetWithLine(6, "NaN 0 1"), 6, "NaN or infinite");
}

TEST(TriIoErrors, InfCoordinate) {
    expectParseError(tetWithLine(4, "inf 0 0"), 4, "NaN or infinite");
    expectParseError(tetWithLine(3, "0 -infinity 0"), 3, "NaN or infinite");
}

TEST(TriIoErrors, FaceWithFourIndices) { expectParseError(tetWithLine(8, "0 1 3 2"), 8, "triangles"); }

TEST(TriIoErrors, FaceWithTwoIndices) { expectParseError(tetWithLine(9, "0 3"), 9, "face 2 needs 3 vertex indices, found 2"); }

TEST(TriIoErrors, NonIntegerIndex) {
    expectParseError(tetWithLine(9, "0 3 -2"), 9, "vertex index '-2' is not a non-negative integer");
    expectParseError(tetWithLine(9, "0 3 2.0"), 9, "is not a non-negative integer");
}

TEST(TriIoErrors, IndexOutOfRange) {
    expectParseError(tetWithLine(10, "1 2 4"), 10, "index 4 out of range");
    expectParseError(tetWithLine(7, "0 4294967296 1"), 7, "out of range");
}

// Geometric defects: refused with their line when strict, repaired with a warning otherwise.
const MeshReadOptions kStrict{.weldTolerance = std::nullopt, .repair = false};

void expectRepaired(const std::string& text, std::size_t faces, const std::string& warning) {
    const MeshReadResult r = parseTri(text, "defect.tri");
    EXPECT_EQ(r.mesh.faces.size(), faces);
    ASSERT_FALSE(r.diagnostics.warnings.empty());
    EXPECT_TRUE(contains(r.diagnostics.warnings[0], warning)) << r.diagnostics.warnings[0];
}

TEST(TriIoErrors, DegenerateFaceRepeatedIndex) {
    expectParseError(tetWithLine(8, "0 1 1"), 8, "repeated vertex", kStrict);
    expectRepaired(tetWithLine(8, "0 1 1"), 3, "1 degenerate face");
}

TEST(TriIoErrors, ZeroAreaFace) {
    // Vertex 3 moved onto the line through 0 and 1: face 1 (0 1 3), line 8, has zero area.
    expectParseError(tetWithLine(6, "2 0 0"), 8, "zero area", kStrict);
    expectRepaired(tetWithLine(6, "2 0 0"), 3, "1 degenerate face");
}

TEST(TriIoErrors, DuplicateFace) {
    std::string text = tetWithLine(2, "4 5") + "2 1 0\n";  // same vertices as line 7, reversed
    expectParseError(text, 11, "duplicates face 0 (line 7)", kStrict);
    expectRepaired(text, 4, "1 duplicate face");
}

TEST(TriIoErrors, TrailingDataAfterFaces) {
    expectParseError(kTet + "\n0 1 2\n", 12, "unexpected data after the last face");
    expectParseError(tetWithLine(2, "4 3"), 10, "unexpected data after the last face");
}

TEST(TriIoErrors, TruncatedFileFewerVerticesThanAnnounced) {
    expectParseError("tet\n4 4\n0 0 0\n1 0 0\n0 1 0\n", 5, "the header announces 4 vertices, found 3");
    expectParseError("tet\n4 4\n0 0 0\n1 0 0\n0 1 0\n\n\n", 7, "the header announces 4 vertices, found 3");
}

TEST(TriIoErrors, TruncatedFileFewerFacesThanAnnounced) {
    expectParseError("tet\n4 4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 2 1\n0 1 3\n", 8, "the header announces 4 faces, found 2");
}

TEST(TriIoErrors, VertexCountZeroIsAnEmptyMesh) {
    expectParseError("tet\n0 0\n", 2, "empty mesh");
    expectParseError("tet\n0 1\n0 1 2\n", 2, "empty mesh: the vertex count is 0");
    expectParseError("tet\n0\n0\n", 3, "empty mesh");
}

TEST(TriIoErrors, FaceCountZeroIsAnEmptyMesh) {
    expectParseError("tet\n3 0\n0 0 0\n1 0 0\n0 1 0\n", 2, "empty mesh: the face count is 0");
}

// ---------------------------------------------------------------------------------------------
// Fuzz: random bytes and mutations of a valid file either parse to a valid mesh or throw
// InputError; nothing else may escape.

// Returns 1 when parsed, 0 when rejected with InputError; fails the test otherwise.
int parseOrReject(const std::string& text, const std::string& label) {
    return flexfit::testing::readOrRefused([&] {
        const MeshReadResult r = parseTri(text, "fuzz.tri");
        MeshDiagnostics again;
        EXPECT_NO_THROW(again = validateMesh(r.mesh, "fuzz.tri")) << label;
        EXPECT_EQ(again.edgeCount, r.diagnostics.edgeCount) << label;
        EXPECT_EQ(again.boundaryEdges, r.diagnostics.boundaryEdges) << label;
        EXPECT_EQ(again.nonManifoldEdges, r.diagnostics.nonManifoldEdges) << label;
        EXPECT_FALSE(r.mesh.vertices.empty());
        EXPECT_FALSE(r.mesh.faces.empty());
    }, label);
}

TEST(TriIoFuzz, RandomByteStrings) {
    std::mt19937 rng(0xF1E7F17u);
    std::uniform_int_distribution<int> length(0, 300);
    std::uniform_int_distribution<int> byte(0, 255);
    // Half the strings from a .tri-like alphabet, so that some get past the header.
    const std::string alphabet = "0123456789 \n\n\n\r\t.-+eEnaifNI";
    std::uniform_int_distribution<std::size_t> letter(0, alphabet.size() - 1);
    for (int i = 0; i < 2000; ++i) {
        std::string text(std::size_t(length(rng)), '\0');
        const bool structured = i % 2 == 1;
        for (char& c : text) c = structured ? alphabet[letter(rng)] : char(byte(rng));
        parseOrReject(text, "random string " + std::to_string(i));
        if (::testing::Test::HasFailure()) break;
    }
}

TEST(TriIoFuzz, MutationsOfAValidFile) {
    // A small valid file: an octahedron.
    const std::string valid =
        "octahedron\n6 8\n"
        "1 0 0\n-1 0 0\n0 1 0\n0 -1 0\n0 0 1\n0 0 -1\n"
        "0 2 4\n2 1 4\n1 3 4\n3 0 4\n2 0 5\n1 2 5\n3 1 5\n0 3 5\n";
    ASSERT_EQ(parseOrReject(valid, "valid"), 1);

    std::mt19937 rng(20240602u);
    const std::string interesting = "0123456789 -.\ne\r\tnan";
    int parsed = 0;
    for (int i = 0; i < 2000; ++i) {
        const std::string text = flexfit::testing::mutated(valid, rng, interesting);
        parsed += parseOrReject(text, "mutation " + std::to_string(i));
        if (::testing::Test::HasFailure()) break;
    }
    // Some mutations (in the name, or whitespace changes) leave the file valid.
    EXPECT_GT(parsed, 0);
    EXPECT_LT(parsed, 2000);
}

}  // namespace
}  // namespace flexfit
