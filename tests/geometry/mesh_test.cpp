// Tests validateMesh (each error class, each warning count) and weldVertices, against hand-built meshes and a brute-force O(n^2) welding reference.
#include "flexfit/mesh.hpp"
#include "strings.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace flexfit {
namespace {

// Closed, outward-oriented tetrahedron.
TriMesh tetrahedron() {
    TriMesh mesh;
    mesh.name = "tet";
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    mesh.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    return mesh;
}

// Runs validateMesh and returns the InputError it throws; fails the test if it does not.
InputError expectInvalid(const TriMesh& mesh, const MeshSourceLines& lines = {}) {
    try {
        validateMesh(mesh, "test-source", lines);
    } catch (const InputError& e) {
        EXPECT_EQ(e.source(), "test-source");
        return e;
    }
    ADD_FAILURE() << "validateMesh accepted an invalid mesh";
    return InputError("none", 0, "no error");
}

using flexfit::testing::contains;

// ---------------------------------------------------------------------------------------------
// validateMesh: valid input

TEST(ValidateMesh, ClosedTetrahedronHasNoWarnings) {
    const MeshDiagnostics d = validateMesh(tetrahedron(), "tet");
    EXPECT_EQ(d.edgeCount, 6u);
    EXPECT_EQ(d.boundaryEdges, 0u);
    EXPECT_EQ(d.nonManifoldEdges, 0u);
    EXPECT_EQ(d.unreferencedVertices, 0u);
    EXPECT_TRUE(d.warnings.empty());
    EXPECT_TRUE(d.closed());
}

// ---------------------------------------------------------------------------------------------
// validateMesh: errors

TEST(ValidateMesh, EmptyMeshNoVertices) {
    const InputError e = expectInvalid(TriMesh{});
    EXPECT_EQ(e.line(), 0u);
    EXPECT_TRUE(contains(e.problem(), "empty mesh")) << e.problem();
}

TEST(ValidateMesh, EmptyMeshNoFaces) {
    TriMesh mesh = tetrahedron();
    mesh.faces.clear();
    const InputError e = expectInvalid(mesh);
    EXPECT_TRUE(contains(e.problem(), "empty mesh")) << e.problem();
}

TEST(ValidateMesh, IndexOutOfRange) {
    TriMesh mesh = tetrahedron();
    mesh.faces[2] = {0, 3, 4};
    const InputError e = expectInvalid(mesh, {{}, {11, 12, 13, 14}});
    EXPECT_EQ(e.line(), 13u);
    EXPECT_TRUE(contains(e.problem(), "out of range")) << e.problem();
    EXPECT_TRUE(contains(e.problem(), "index 4")) << e.problem();
}

TEST(ValidateMesh, HugeIndexOutOfRange) {
    TriMesh mesh = tetrahedron();
    mesh.faces[0] = {0, std::numeric_limits<Index>::max(), 1};
    const InputError e = expectInvalid(mesh);
    EXPECT_EQ(e.line(), 0u);  // no source lines given
    EXPECT_TRUE(contains(e.problem(), "out of range")) << e.problem();
}

TEST(ValidateMesh, NaNCoordinate) {
    TriMesh mesh = tetrahedron();
    mesh.vertices[2].y() = std::numeric_limits<double>::quiet_NaN();
    const InputError e = expectInvalid(mesh, {{3, 4, 5, 6}, {}});
    EXPECT_EQ(e.line(), 5u);
    EXPECT_TRUE(contains(e.problem(), "NaN or infinite")) << e.problem();
    EXPECT_TRUE(contains(e.problem(), "vertex 2")) << e.problem();
}

TEST(ValidateMesh, InfiniteCoordinate) {
    for (double bad : {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()}) {
        TriMesh mesh = tetrahedron();
        mesh.vertices[3].z() = bad;
        const InputError e = expectInvalid(mesh, {{3, 4, 5, 6}, {}});
        EXPECT_EQ(e.line(), 6u);
        EXPECT_TRUE(contains(e.problem(), "NaN or infinite")) << e.problem();
    }
}

// Scales whose coordinate products overflow or underflow (collide had printed depth inf and
// a made-up normal for every contact of a torus scaled by 1e200, and by 1e-200) are refused,
// naming the farthest vertex's line; the bounds themselves are accepted.
TEST(ValidateMesh, AScaleBeyondWhatProductsOfCoordinatesTakeIsRefused) {
    auto scaled = [](double factor, const Vec3& shift = Vec3::Zero()) {
        TriMesh mesh = tetrahedron();
        for (Vec3& v : mesh.vertices) v = factor * v + shift;
        return mesh;
    };
    EXPECT_NO_THROW(validateMesh(scaled(0.9 * kMaxMeshCoordinate), "t"));
    EXPECT_NO_THROW(validateMesh(scaled(2.0 * kMinMeshSize), "t"));
    for (double factor : {1e21, 1e200, -1e300}) {
        const InputError e = expectInvalid(scaled(factor), {{3, 4, 5, 6}, {}});
        EXPECT_EQ(e.line(), 4u) << factor;  // vertex 1, the first with the largest coordinate
        EXPECT_TRUE(contains(e.problem(), "vertex 1 has a coordinate of magnitude")) << e.problem();
        EXPECT_TRUE(contains(e.problem(), "rescale")) << e.problem();
    }
    // Small but far out: the size is fine, the coordinate is not.
    EXPECT_TRUE(contains(expectInvalid(scaled(1.0, Vec3(0, 0, 5e20))).problem(), "beyond the 1e+20 units"));
    for (double factor : {1e-21, 1e-200}) {
        const InputError e = expectInvalid(scaled(factor));
        EXPECT_TRUE(contains(e.problem(), "below the 1e-20 units")) << e.problem();
    }
}

TEST(ValidateMesh, NonFiniteUnreferencedVertexIsStillAnError) {
    TriMesh mesh = tetrahedron();
    mesh.vertices.emplace_back(std::numeric_limits<double>::quiet_NaN(), 0, 0);
    const InputError e = expectInvalid(mesh);
    EXPECT_TRUE(contains(e.problem(), "vertex 4")) << e.problem();
}

TEST(ValidateMesh, DegenerateFaceRepeatedIndex) {
    for (const Face bad : {Face{1, 1, 2}, Face{1, 2, 2}, Face{2, 1, 2}, Face{3, 3, 3}}) {
        TriMesh mesh = tetrahedron();
        mesh.faces[1] = bad;
        const InputError e = expectInvalid(mesh, {{}, {21, 22, 23, 24}});
        EXPECT_EQ(e.line(), 22u);
        EXPECT_TRUE(contains(e.problem(), "repeated vertex")) << e.problem();
    }
}

TEST(ValidateMesh, DegenerateFaceZeroArea) {
    // Three collinear vertices, and (separately) two coincident positions under distinct indices.
    TriMesh collinear;
    collinear.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
    collinear.faces = {{0, 1, 2}};
    InputError e = expectInvalid(collinear, {{}, {7}});
    EXPECT_EQ(e.line(), 7u);
    EXPECT_TRUE(contains(e.problem(), "zero area")) << e.problem();

    TriMesh coincident = tetrahedron();
    coincident.vertices.push_back(coincident.vertices[1]);
    coincident.faces.push_back({1, 4, 2});
    e = expectInvalid(coincident, {{}, {1, 2, 3, 4, 5}});
    EXPECT_EQ(e.line(), 5u);
    EXPECT_TRUE(contains(e.problem(), "zero area")) << e.problem();
}

TEST(ValidateMesh, ZeroAreaThresholdIsRelativeToTheMeshSize) {
    // A face of relative area well above 1e-12 passes at any scale; a sliver far below fails.
    for (double scale : {1e-6, 1.0, 1e6}) {
        TriMesh mesh = tetrahedron();
        for (Vec3& v : mesh.vertices) v *= scale;
        EXPECT_NO_THROW(validateMesh(mesh, "scaled")) << scale;

        TriMesh sliver;
        sliver.vertices = {Vec3(0, 0, 0), Vec3(scale, 0, 0), Vec3(0.5 * scale, 1e-14 * scale, 0)};
        sliver.faces = {{0, 1, 2}};
        const InputError e = expectInvalid(sliver);
        EXPECT_TRUE(contains(e.problem(), "zero area")) << scale << ": " << e.problem();
    }
}

// The threshold is documented as relative (1e-12 x diagonal^2), so a valid mesh stays valid at
// every scale validateMesh accepts, up to its bounds (kMinMeshSize, kMaxMeshCoordinate).
TEST(ValidateMesh, ZeroAreaThresholdHoldsAtExtremeScales) {
    for (double scale : {1e-19, 1e-15, 1e15, 0.99e20}) {
        TriMesh mesh = tetrahedron();
        for (Vec3& v : mesh.vertices) v *= scale;
        EXPECT_NO_THROW(validateMesh(mesh, "scaled")) << scale;
    }
}

TEST(ValidateMesh, DuplicateFaceSameWinding) {
    TriMesh mesh = tetrahedron();
    mesh.faces.push_back({1, 2, 3});
    const InputError e = expectInvalid(mesh, {{}, {10, 11, 12, 13, 14}});
    EXPECT_EQ(e.line(), 14u);  // the line of the second occurrence
    EXPECT_TRUE(contains(e.problem(), "duplicates")) << e.problem();
    EXPECT_TRUE(contains(e.problem(), "line 13")) << e.problem();
}

TEST(ValidateMesh, DuplicateFaceDifferentWinding) {
    for (const Face dup : {Face{3, 2, 1}, Face{2, 3, 1}, Face{1, 3, 2}}) {
        TriMesh mesh = tetrahedron();
        mesh.faces.insert(mesh.faces.begin() + 1, dup);  // duplicate of face 4 (1 2 3) at index 1
        const InputError e = expectInvalid(mesh, {{}, {10, 11, 12, 13, 14}});
        EXPECT_EQ(e.line(), 14u);  // the later of the two in file order
        EXPECT_TRUE(contains(e.problem(), "duplicates")) << e.problem();
    }
}

// ---------------------------------------------------------------------------------------------
// validateMesh: warnings

TEST(ValidateMesh, SingleTriangleHasThreeBoundaryEdges) {
    TriMesh mesh;
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    mesh.faces = {{0, 1, 2}};
    const MeshDiagnostics d = validateMesh(mesh, "triangle");
    EXPECT_EQ(d.edgeCount, 3u);
    EXPECT_EQ(d.boundaryEdges, 3u);
    EXPECT_EQ(d.nonManifoldEdges, 0u);
    EXPECT_EQ(d.unreferencedVertices, 0u);
    EXPECT_FALSE(d.closed());
    ASSERT_EQ(d.warnings.size(), 1u);
    EXPECT_TRUE(contains(d.warnings[0], "3 boundary edges")) << d.warnings[0];
}

TEST(ValidateMesh, ThreeTrianglesSharingAnEdgeAreNonManifold) {
    TriMesh mesh;
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0}, {0.5, 0, 1}};
    mesh.faces = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
    const MeshDiagnostics d = validateMesh(mesh, "fan");
    EXPECT_EQ(d.edgeCount, 7u);         // the shared edge + 2 per triangle
    EXPECT_EQ(d.nonManifoldEdges, 1u);  // edge 0-1, used 3 times
    EXPECT_EQ(d.boundaryEdges, 6u);
    EXPECT_EQ(d.unreferencedVertices, 0u);
    EXPECT_FALSE(d.closed());
    ASSERT_EQ(d.warnings.size(), 2u);
    EXPECT_TRUE(contains(d.warnings[0] + d.warnings[1], "1 non-manifold edges"));
    EXPECT_TRUE(contains(d.warnings[0] + d.warnings[1], "6 boundary edges"));
}

TEST(ValidateMesh, NonManifoldWithoutBoundaryIsNotClosed) {
    // Two tetrahedra glued along one edge (0-1): that edge has four faces, every other edge two.
    TriMesh mesh = tetrahedron();
    mesh.vertices.push_back({0, -1, 0});
    mesh.vertices.push_back({0, 0, -1});
    // Second tetrahedron over vertices 0, 1, 4, 5, outward.
    mesh.faces.push_back({0, 1, 4});
    mesh.faces.push_back({0, 5, 1});
    mesh.faces.push_back({0, 4, 5});
    mesh.faces.push_back({1, 5, 4});
    const MeshDiagnostics d = validateMesh(mesh, "bowtie");
    EXPECT_EQ(d.edgeCount, 11u);
    EXPECT_EQ(d.boundaryEdges, 0u);
    EXPECT_EQ(d.nonManifoldEdges, 1u);
    EXPECT_FALSE(d.closed());
    EXPECT_EQ(d.warnings.size(), 1u);
}

TEST(ValidateMesh, UnreferencedVertexIsCounted) {
    TriMesh mesh = tetrahedron();
    mesh.vertices.push_back({5, 5, 5});
    mesh.vertices.push_back({6, 5, 5});
    const MeshDiagnostics d = validateMesh(mesh, "tet+2");
    EXPECT_EQ(d.unreferencedVertices, 2u);
    EXPECT_EQ(d.edgeCount, 6u);
    EXPECT_TRUE(d.closed());  // closedness is about edges only
    ASSERT_EQ(d.warnings.size(), 1u);
    EXPECT_TRUE(contains(d.warnings[0], "2 vertices used by no face")) << d.warnings[0];
}

TEST(ValidateMesh, BoundingBox) {
    const Eigen::AlignedBox3d box = boundingBox(tetrahedron());
    EXPECT_EQ(box.min(), Vec3(0, 0, 0));
    EXPECT_EQ(box.max(), Vec3(1, 1, 1));
    EXPECT_TRUE(boundingBox(TriMesh{}).isEmpty());
}

// ---------------------------------------------------------------------------------------------
// weldVertices

TEST(WeldVertices, ExactModeMergesIdenticalPositionsOnly) {
    const double next = std::nextafter(1.0, 2.0);
    TriMesh mesh;
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {next, 0, 0}, {0, 1, 0}};
    mesh.faces = {{0, 1, 2}, {3, 4, 5}};
    const std::size_t collapsed = weldVertices(mesh, 0.0);
    EXPECT_EQ(collapsed, 0u);
    ASSERT_EQ(mesh.vertices.size(), 4u);
    EXPECT_EQ(mesh.vertices[0], Vec3(0, 0, 0));
    EXPECT_EQ(mesh.vertices[1], Vec3(1, 0, 0));
    EXPECT_EQ(mesh.vertices[2], Vec3(0, 1, 0));
    EXPECT_EQ(mesh.vertices[3], Vec3(next, 0, 0));  // one ulp away: kept apart
    ASSERT_EQ(mesh.faces.size(), 2u);
    EXPECT_EQ(mesh.faces[0], (Face{0, 1, 2}));
    EXPECT_EQ(mesh.faces[1], (Face{1, 3, 2}));
}

TEST(WeldVertices, ToleranceModeMergesWithinToleranceKeepingTheFirst) {
    TriMesh mesh;
    mesh.vertices = {{0.5e-3, 0, 0}, {0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0.9e-3, 0}, {0, 1.0005, 0}};
    mesh.faces = {{1, 3, 2}, {4, 3, 5}};
    const std::size_t collapsed = weldVertices(mesh, 1e-3);
    EXPECT_EQ(collapsed, 0u);
    // 1 merges into 0 (distance 0.5e-3); 4 is 1.03e-3 from 0 (kept), 5 merges into 2.
    ASSERT_EQ(mesh.vertices.size(), 4u);
    EXPECT_EQ(mesh.vertices[0], Vec3(0.5e-3, 0, 0));  // the first of the cluster, unmoved
    EXPECT_EQ(mesh.vertices[1], Vec3(0, 1, 0));
    EXPECT_EQ(mesh.vertices[2], Vec3(1, 0, 0));
    EXPECT_EQ(mesh.vertices[3], Vec3(0, 0.9e-3, 0));
    EXPECT_EQ(mesh.faces[0], (Face{0, 2, 1}));
    EXPECT_EQ(mesh.faces[1], (Face{3, 2, 1}));
}

TEST(WeldVertices, ToleranceIsInclusiveAndEuclidean) {
    TriMesh mesh;
    // (0.6, 0.6, 0) x 1e-3 is 0.85e-3 away: merged; (0.8, 0.8, 0) x 1e-3 is 1.13e-3 away: kept,
    // although each coordinate differs by less than the tolerance.
    mesh.vertices = {{0, 0, 0}, {0.6e-3, 0.6e-3, 0}, {0.8e-3, 0.8e-3, 0}, {0.25, 0, 0}, {0.5, 0, 0}};
    mesh.faces = {{0, 1, 2}};
    const std::size_t collapsed = weldVertices(mesh, 1e-3);
    EXPECT_EQ(collapsed, 1u);  // 0 and 1 merged: the face collapses
    ASSERT_EQ(mesh.vertices.size(), 4u);
    EXPECT_EQ(mesh.vertices[1], Vec3(0.8e-3, 0.8e-3, 0));
    EXPECT_TRUE(mesh.faces.empty());

    TriMesh exact;
    exact.vertices = {{0, 0, 0}, {0.25, 0, 0}};  // 0.25 is exact in binary: distance == tolerance
    exact.faces = {};
    weldVertices(exact, 0.25);
    EXPECT_EQ(exact.vertices.size(), 1u);
}

TEST(WeldVertices, CollapsedFacesAreCountedAndRemoved) {
    TriMesh mesh;
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {1e-9, 0, 0}, {1, 0, 0}};
    mesh.faces = {{0, 1, 2}, {0, 3, 2}, {4, 5, 1}, {3, 4, 2}, {2, 1, 3}};
    // Exact: 3 -> 0 and 5 -> 1; (0 3 2) and (4 5 1) collapse; 4 is not identical to 0.
    EXPECT_EQ(weldVertices(mesh, 0.0), 2u);
    EXPECT_EQ(mesh.vertices.size(), 4u);
    ASSERT_EQ(mesh.faces.size(), 3u);
    EXPECT_EQ(mesh.faces[0], (Face{0, 1, 2}));
    EXPECT_EQ(mesh.faces[1], (Face{0, 3, 2}));
    EXPECT_EQ(mesh.faces[2], (Face{2, 1, 0}));

    TriMesh again;
    again.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0}, {1e-9, 0, 0}, {1, 0, 0}};
    again.faces = {{0, 1, 2}, {0, 3, 2}, {4, 5, 1}, {3, 4, 2}, {2, 1, 3}};
    EXPECT_EQ(weldVertices(again, 1e-6), 3u);  // (0 3 2), (4 5 1), (3 4 2) collapse
    EXPECT_EQ(again.vertices.size(), 3u);
    ASSERT_EQ(again.faces.size(), 2u);
    EXPECT_EQ(again.faces[0], (Face{0, 1, 2}));
    EXPECT_EQ(again.faces[1], (Face{2, 1, 0}));
}

TEST(WeldVertices, NothingToWeldLeavesMeshUnchanged) {
    TriMesh mesh = tetrahedron();
    const TriMesh before = mesh;
    EXPECT_EQ(weldVertices(mesh, 0.0), 0u);
    EXPECT_EQ(mesh.vertices, before.vertices);
    EXPECT_EQ(mesh.faces, before.faces);
    EXPECT_EQ(weldVertices(mesh, 0.1), 0u);
    EXPECT_EQ(mesh.vertices, before.vertices);
    EXPECT_EQ(mesh.faces, before.faces);
}

TEST(WeldVertices, NonFiniteVerticesAreNeverMerged) {
    // Welding must not crash on non-finite input (validateMesh rejects it afterwards). NaN is
    // equal to nothing, so NaN vertices stay apart.
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    TriMesh mesh;
    mesh.vertices = {{nan, 0, 0}, {nan, 0, 0}, {0, 0, 0}, {inf, 0, 0}, {0, -inf, 0}};
    mesh.faces = {{0, 1, 2}};
    EXPECT_EQ(weldVertices(mesh, 0.0), 0u);
    EXPECT_EQ(mesh.vertices.size(), 5u);
    TriMesh tol = mesh;
    EXPECT_NO_THROW(weldVertices(tol, 1e-3));
    EXPECT_EQ(tol.vertices.size(), 5u);
}

// Coordinates far larger than the tolerance (200 with a 1e-9 tolerance: cell index 2e11) must
// weld correctly and without undefined behaviour (the cell hash once overflowed signed
// arithmetic here; the asan preset checks it).
TEST(WeldVertices, LargeCoordinatesRelativeToTheTolerance) {
    TriMesh mesh;
    mesh.vertices = {{200, 0, 0}, {0, 0, 0}, {0, 1, 0}, {200 + 1e-10, 0, 0}, {1e300, 0, 0}, {1e300, 0, 0}};
    mesh.faces = {{0, 1, 2}, {3, 1, 2}};
    // 3 joins 0, so the second face becomes a duplicate of the first (not a collapsed face).
    EXPECT_EQ(weldVertices(mesh, 1e-9), 0u);
    EXPECT_EQ(mesh.vertices.size(), 4u);
    EXPECT_EQ(mesh.faces[1], (Face{0, 1, 2}));
    TriMesh exact;
    exact.vertices = {{2e11, 0, 0}, {0, 0, 0}, {2e11, 0, 0}};
    exact.faces = {{0, 1, 2}};
    EXPECT_EQ(weldVertices(exact, 0.0), 1u);
    EXPECT_EQ(exact.vertices.size(), 2u);
}

// ---------------------------------------------------------------------------------------------
// weldVertices against a brute-force O(n^2) reference.

struct WeldReference {
    std::vector<Vec3> vertices;  // representatives, in input order
    std::vector<Index> remap;    // input vertex -> representative (the earliest one within tolerance)
    std::vector<Face> faces;
    std::size_t collapsed = 0;
};

bool sameOrClose(const Vec3& a, const Vec3& b, double tolerance) {
    return tolerance > 0 ? (a - b).norm() <= tolerance : a == b;
}

WeldReference bruteForceWeld(const TriMesh& mesh, double tolerance) {
    WeldReference ref;
    for (const Vec3& p : mesh.vertices) {
        Index match = Index(-1);
        for (Index k = 0; k < ref.vertices.size(); ++k)
            if (sameOrClose(ref.vertices[k], p, tolerance)) {
                match = k;
                break;
            }
        if (match == Index(-1)) {
            match = Index(ref.vertices.size());
            ref.vertices.push_back(p);
        }
        ref.remap.push_back(match);
    }
    for (const Face& f : mesh.faces) {
        const Face g{ref.remap[f[0]], ref.remap[f[1]], ref.remap[f[2]]};
        if (g[0] == g[1] || g[1] == g[2] || g[0] == g[2])
            ++ref.collapsed;
        else
            ref.faces.push_back(g);
    }
    return ref;
}

// Random faces over distinct input indices.
std::vector<Face> randomFaces(std::mt19937& rng, std::size_t vertexCount, std::size_t faceCount) {
    std::uniform_int_distribution<Index> pick(0, Index(vertexCount - 1));
    std::vector<Face> faces;
    while (faces.size() < faceCount) {
        const Face f{pick(rng), pick(rng), pick(rng)};
        if (f[0] != f[1] && f[1] != f[2] && f[0] != f[2]) faces.push_back(f);
    }
    return faces;
}

TEST(WeldVertices, ExactModeMatchesBruteForceOnRandomClouds) {
    std::mt19937 rng(20240601u);
    for (int trial = 0; trial < 20; ++trial) {
        // A small pool of positions sampled with repetition, plus one-ulp neighbours.
        std::uniform_real_distribution<double> coord(-10.0, 10.0);
        std::vector<Vec3> pool(40);
        for (Vec3& p : pool) p = {coord(rng), coord(rng), coord(rng)};
        std::uniform_int_distribution<std::size_t> pickPool(0, pool.size() - 1);
        std::uniform_int_distribution<int> kind(0, 9);
        TriMesh mesh;
        for (int i = 0; i < 300; ++i) {
            Vec3 p = pool[pickPool(rng)];
            if (kind(rng) == 0) p.x() = std::nextafter(p.x(), 100.0);
            mesh.vertices.push_back(p);
        }
        mesh.faces = randomFaces(rng, mesh.vertices.size(), 200);
        const WeldReference ref = bruteForceWeld(mesh, 0.0);

        const std::size_t collapsed = weldVertices(mesh, 0.0);
        EXPECT_EQ(collapsed, ref.collapsed) << "trial " << trial;
        EXPECT_EQ(mesh.vertices, ref.vertices) << "trial " << trial;
        EXPECT_EQ(mesh.faces, ref.faces) << "trial " << trial;
    }
}

TEST(WeldVertices, ToleranceModeMatchesBruteForceOnSeparatedClusters) {
    // Clusters far apart (centres on a 1.0 grid), members within tolerance/2 of the centre, so
    // every pair in a cluster is within the tolerance and no two clusters are: the welding is
    // unambiguous and must equal the reference exactly.
    std::mt19937 rng(7u);
    const double tolerance = 1e-3;
    for (int trial = 0; trial < 20; ++trial) {
        std::uniform_int_distribution<int> cell(-20, 20);
        std::vector<Vec3> centres(60);
        for (Vec3& c : centres) c = Vec3(cell(rng), cell(rng), cell(rng)) + Vec3(0.3, 0.3, 0.3);
        std::uniform_int_distribution<std::size_t> pick(0, centres.size() - 1);
        std::normal_distribution<double> gauss(0.0, 1.0);
        std::uniform_real_distribution<double> radius(0.0, 0.49 * tolerance);
        TriMesh mesh;
        for (int i = 0; i < 400; ++i) {
            Vec3 dir(gauss(rng), gauss(rng), gauss(rng));
            dir.normalize();
            mesh.vertices.push_back(centres[pick(rng)] + radius(rng) * dir);
        }
        mesh.faces = randomFaces(rng, mesh.vertices.size(), 300);
        const WeldReference ref = bruteForceWeld(mesh, tolerance);

        const std::size_t collapsed = weldVertices(mesh, tolerance);
        EXPECT_EQ(collapsed, ref.collapsed) << "trial " << trial;
        EXPECT_EQ(mesh.vertices, ref.vertices) << "trial " << trial;
        EXPECT_EQ(mesh.faces, ref.faces) << "trial " << trial;
    }
}

TEST(WeldVertices, ToleranceModeMatchesBruteForceOnDenseUniformClouds) {
    // Uniform points with the tolerance close to their spacing: clusters chain and a vertex can be
    // within tolerance of several representatives. The representatives (the positions kept) are
    // still fully determined: a vertex starts a new one exactly when no earlier representative is
    // within tolerance, so they must equal the reference's. Which of several representatives a
    // vertex joins is not specified; it must be one within tolerance, and the only one when only
    // one is. The library's remap is read back through probe faces (v, A, B) with A and B far away.
    std::mt19937 rng(12345u);
    for (double tolerance : {0.05, 0.1, 0.2}) {
        for (int trial = 0; trial < 10; ++trial) {
            std::uniform_real_distribution<double> coord(-1.0, 1.0);
            TriMesh mesh;
            for (int i = 0; i < 500; ++i) mesh.vertices.emplace_back(coord(rng), coord(rng), coord(rng));
            const Index n = Index(mesh.vertices.size());
            mesh.vertices.emplace_back(100.0, 0.0, 0.0);
            mesh.vertices.emplace_back(0.0, 100.0, 0.0);
            for (Index v = 0; v < n; ++v) mesh.faces.push_back({v, n, n + 1});
            const TriMesh input = mesh;
            const WeldReference ref = bruteForceWeld(input, tolerance);

            EXPECT_EQ(weldVertices(mesh, tolerance), 0u);
            ASSERT_EQ(mesh.vertices, ref.vertices) << "tolerance " << tolerance << " trial " << trial;
            ASSERT_EQ(mesh.faces.size(), std::size_t(n));
            const Index a = Index(ref.vertices.size() - 2);
            for (Index v = 0; v < n; ++v) {
                const Face& f = mesh.faces[v];
                ASSERT_EQ(f[1], a);
                ASSERT_EQ(f[2], a + 1);
                const Index chosen = f[0];
                ASSERT_LT(chosen, a);
                EXPECT_LE((mesh.vertices[chosen] - input.vertices[v]).norm(), tolerance);
                std::size_t within = 0;
                for (Index r = 0; r < a; ++r)
                    if ((ref.vertices[r] - input.vertices[v]).norm() <= tolerance) ++within;
                if (within == 1) {
                    EXPECT_EQ(chosen, ref.remap[v]) << "vertex " << v;
                }
                // A representative maps to itself.
                if (ref.vertices[ref.remap[v]] == input.vertices[v]) {
                    EXPECT_EQ(chosen, ref.remap[v]);
                }
            }
        }
    }
}

}  // namespace
}  // namespace flexfit

TEST(Mesh, InFileOrderRefusesFileVerticesThatDoNotFitTheMesh) {
    // A public helper given a map that names a vertex the mesh does not have, or fewer
    // positions than file vertices: an error, not a read or write outside the arrays.
    TriMesh tet;
    tet.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    tet.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    FileVertices file;
    file.meshVertex = {0, 9};
    file.positions = {Vec3::Zero(), Vec3::Zero()};
    EXPECT_THROW((void)inFileOrder(tet, file), InputError);
    file.meshVertex = {0, 1};
    file.positions = {Vec3::Zero()};
    EXPECT_THROW((void)inFileOrder(tet, file), InputError);
    EXPECT_THROW((void)firstFileVertices(file, 4), InputError);
}

TEST(Mesh, WeldingAndComposingMapsRefuseIndicesBeyondTheirArrays) {
    // A face naming vertex 1000 of 3, a map entry beyond the map it goes through, a tolerance
    // that is no length: errors, where they read past the arrays (AddressSanitizer) or welded
    // everything into one vertex.
    TriMesh mesh;
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    mesh.faces = {{0, 1, 1000}};
    EXPECT_THROW((void)weldVertices(mesh, 0.0), InputError);
    mesh.faces = {{0, 1, 2}};
    for (const double bad : {std::nan(""), -1.0, double(INFINITY)}) EXPECT_THROW((void)weldVertices(mesh, bad), InputError) << bad;
    EXPECT_EQ(weldVertices(mesh, 0.0), 0u);
    VertexMap map{0, 5};
    EXPECT_THROW(composeVertexMap(map, VertexMap{0}), InputError);
    EXPECT_EQ(map, (VertexMap{0, 5}));
    map = {1, kNoVertex};
    composeVertexMap(map, VertexMap{7, 3});
    EXPECT_EQ(map, (VertexMap{3, kNoVertex}));
}
