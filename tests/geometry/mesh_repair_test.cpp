// Tests repairMesh and requireNoDefects: each defect class alone and mixed on an icosphere with
// known damage, the counts against what was done to it, the result against the undamaged mesh
// and a brute-force winding check over every pair of faces; the strict reading's first defect
// and its line.
#include "flexfit/generators.hpp"
#include "strings.hpp"
#include "flexfit/mesh_repair.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <random>

namespace flexfit {
namespace {

using flexfit::testing::contains;

// Brute force: every pair of faces sharing two vertices runs that edge in opposite directions.
bool consistentlyWound(const TriMesh& mesh) {
    auto runs = [](const Face& f, Index u, Index v) {
        for (int k = 0; k < 3; ++k)
            if (f[k] == u && f[(k + 1) % 3] == v) return true;
        return false;
    };
    for (std::size_t f = 0; f < mesh.faces.size(); ++f)
        for (std::size_t g = f + 1; g < mesh.faces.size(); ++g)
            for (int k = 0; k < 3; ++k) {
                const Index u = mesh.faces[f][k], v = mesh.faces[f][(k + 1) % 3];
                if (runs(mesh.faces[g], u, v)) return false;
            }
    return true;
}

Face flipped(Face f) { return {f[0], f[2], f[1]}; }

TEST(MeshRepair, ACleanMeshIsLeftAsItIs) {
    TriMesh mesh = makeIcoSphere(1.0, 2);
    const TriMesh before = mesh;
    const MeshRepairs r = repairMesh(mesh, -1.0, "clean");
    EXPECT_FALSE(r.any());
    EXPECT_TRUE(r.warnings().empty());
    EXPECT_EQ(mesh.vertices, before.vertices);
    EXPECT_EQ(mesh.faces, before.faces);
    EXPECT_NO_THROW(requireNoDefects(before, -1.0, "clean"));
}

TEST(MeshRepair, FlippedFacesAreTurnedBackTheFewerAlwaysYielding) {
    const TriMesh sphere = makeIcoSphere(1.0, 2);  // 320 faces
    ASSERT_TRUE(consistentlyWound(sphere));
    std::mt19937 random(5);
    for (std::size_t count : {1u, 17u, 100u, 220u}) {
        TriMesh mesh = sphere;
        std::vector<std::size_t> order(mesh.faces.size());
        std::iota(order.begin(), order.end(), 0);
        std::shuffle(order.begin(), order.end(), random);
        for (std::size_t i = 0; i < count; ++i) mesh.faces[order[i]] = flipped(mesh.faces[order[i]]);
        const MeshRepairs r = repairMesh(mesh, -1.0, "flipped");
        EXPECT_TRUE(consistentlyWound(mesh)) << count;
        EXPECT_EQ(r.flippedFaces, std::min(count, sphere.faces.size() - count)) << count;
        // The fewer flipped back: the sphere as it was, or all of it inside out.
        const bool inverted = count * 2 > sphere.faces.size();
        for (std::size_t f = 0; f < mesh.faces.size(); ++f)
            EXPECT_EQ(mesh.faces[f], inverted ? flipped(sphere.faces[f]) : sphere.faces[f]) << count << " face " << f;
        ASSERT_EQ(r.warnings().size(), 1u);
        EXPECT_TRUE(contains(r.warnings()[0], std::to_string(r.flippedFaces) + (r.flippedFaces == 1 ? " face" : " faces") + " flipped")) << r.warnings()[0];
    }
}

TEST(MeshRepair, EachPieceIsOrientedOnItsOwn) {
    // Two spheres apart: the first with 3 faces flipped, the second all inside out (a piece of
    // its own: nothing flips it to agree with the first).
    TriMesh a = makeIcoSphere(1.0, 1), b = makeIcoSphere(1.0, 1);
    TriMesh mesh = a;
    const Index offset = Index(a.vertices.size());
    for (const Vec3& v : b.vertices) mesh.vertices.push_back(v + Vec3(5, 0, 0));
    for (const Face& f : b.faces) mesh.faces.push_back(flipped({f[0] + offset, f[1] + offset, f[2] + offset}));
    for (std::size_t f : {0u, 7u, 30u}) mesh.faces[f] = flipped(mesh.faces[f]);
    const MeshRepairs r = repairMesh(mesh, -1.0, "two");
    EXPECT_EQ(r.flippedFaces, 3u);
    EXPECT_TRUE(consistentlyWound(mesh));
    EXPECT_EQ(mesh.faces[a.faces.size()], flipped({b.faces[0][0] + offset, b.faces[0][1] + offset, b.faces[0][2] + offset}));
}

TEST(MeshRepair, AMoebiusStripIsCountedAndLeftAsItIs) {
    // A strip of 8 quads whose ends join with a half twist.
    constexpr int kQuads = 8;
    TriMesh mesh;
    for (int i = 0; i < kQuads; ++i) {
        const double angle = 2.0 * M_PI * i / kQuads, twist = 0.5 * angle;
        const Vec3 centre(3 * std::cos(angle), 3 * std::sin(angle), 0);
        const Vec3 across = std::cos(twist) * Vec3(std::cos(angle), std::sin(angle), 0) + std::sin(twist) * Vec3(0, 0, 1);
        mesh.vertices.push_back(centre - across);
        mesh.vertices.push_back(centre + across);
    }
    for (int i = 0; i < kQuads; ++i) {
        const bool last = i == kQuads - 1;
        const Index a = Index(2 * i), b = a + 1;
        const Index c = last ? 1 : a + 2, d = last ? 0 : a + 3;  // the twist swaps the sides
        mesh.faces.push_back({a, c, b});
        mesh.faces.push_back({b, c, d});
    }
    const TriMesh before = mesh;
    const MeshRepairs r = repairMesh(mesh, -1.0, "moebius");
    EXPECT_EQ(r.nonOrientablePieces, 1u);
    EXPECT_EQ(r.flippedFaces, 0u);
    EXPECT_EQ(mesh.faces, before.faces);
    EXPECT_TRUE(contains(r.warnings().back(), "1 non-orientable piece")) << r.warnings().back();
}

TEST(MeshRepair, DegenerateDuplicateAndUnreferencedAloneAndMixed) {
    const TriMesh sphere = makeIcoSphere(2.0, 2);
    enum Defect { kZeroArea, kRepeated, kDuplicate, kUnreferenced, kNearDuplicate, kFlipped };
    for (unsigned mask = 1; mask < 64; ++mask) {
        TriMesh mesh = sphere;
        MeshRepairs expected;
        // Where each vertex goes, by construction: the sphere's stay, the added ones are removed
        // or welded into the vertex they copy.
        VertexMap expectedMap(sphere.vertices.size());
        std::iota(expectedMap.begin(), expectedMap.end(), Index(0));
        auto has = [&](Defect d) { return (mask >> d) & 1u; };
        if (has(kUnreferenced)) {  // two stray vertices, before the rest is appended
            mesh.vertices.push_back(Vec3(9, 9, 9));
            mesh.vertices.push_back(Vec3(-9, 0, 0));
            expected.unreferencedVertices += 2;
            expectedMap.insert(expectedMap.end(), 2, kNoVertex);
        }
        if (has(kZeroArea)) {  // a vertex on edge (0 1): the face (0 1 x) has no area
            mesh.vertices.push_back(0.5 * (sphere.vertices[0] + sphere.vertices[1]));
            mesh.faces.push_back({0, 1, Index(mesh.vertices.size() - 1)});
            ++expected.degenerateFaces;
            ++expected.unreferencedVertices;  // used only by the dropped face
            expectedMap.push_back(kNoVertex);
        }
        if (has(kRepeated)) {
            mesh.faces.push_back({3, 4, 3});
            ++expected.degenerateFaces;
        }
        if (has(kDuplicate)) {
            mesh.faces.push_back({sphere.faces[9][2], sphere.faces[9][0], sphere.faces[9][1]});
            mesh.faces.push_back(flipped(sphere.faces[40]));
            expected.duplicateFaces += 2;
        }
        if (has(kNearDuplicate)) {  // face 5's first corner duplicated 1e-9 away
            mesh.vertices.push_back(sphere.vertices[sphere.faces[5][0]] + Vec3(1e-9, 0, 0));
            mesh.faces[5][0] = Index(mesh.vertices.size() - 1);
            ++expected.weldedVertices;
            expectedMap.push_back(sphere.faces[5][0]);
        }
        if (has(kFlipped)) {
            for (std::size_t f : {11u, 12u}) mesh.faces[f] = flipped(mesh.faces[f]);
            expected.flippedFaces += 2;
        }
        const MeshRepairs r = repairMesh(mesh, -1.0, "damaged");
        EXPECT_EQ(r.weldedVertices, expected.weldedVertices) << mask;
        EXPECT_EQ(r.degenerateFaces, expected.degenerateFaces) << mask;
        EXPECT_EQ(r.duplicateFaces, expected.duplicateFaces) << mask;
        EXPECT_EQ(r.flippedFaces, expected.flippedFaces) << mask;
        EXPECT_EQ(r.unreferencedVertices, expected.unreferencedVertices) << mask;
        EXPECT_EQ(r.nonOrientablePieces, 0u);
        // What is left is the sphere: its vertices in order, its faces in order.
        EXPECT_EQ(mesh.vertices, sphere.vertices) << mask;
        EXPECT_EQ(mesh.faces, sphere.faces) << mask;
        EXPECT_NO_THROW(validateMesh(mesh, "repaired"));
        if (expected.weldedVertices + expected.unreferencedVertices > 0)
            EXPECT_EQ(r.vertexMap, expectedMap) << mask;
        else
            EXPECT_TRUE(r.vertexMap.empty()) << mask;
        const std::size_t kinds = (expected.weldedVertices > 0) + (expected.degenerateFaces > 0) + (expected.duplicateFaces > 0) +
                                  (expected.flippedFaces > 0) + (expected.unreferencedVertices > 0);
        EXPECT_EQ(r.warnings().size(), kinds)
            << mask;
    }
}

// Random soups over a few vertices (many repeated, duplicate, degenerate and non-manifold
// faces): the repair either leaves a mesh validateMesh accepts, wound consistently wherever two
// faces share an edge and nothing else does, or says that no face is left. Never anything else.
TEST(MeshRepair, RandomSoupsComeOutValidOrRefused) {
    std::mt19937 random(11);
    std::uniform_int_distribution<Index> pick(0, 11);
    std::uniform_int_distribution<int> coordinate(-2, 2);
    for (int trial = 0; trial < 300; ++trial) {
        TriMesh mesh;
        for (int v = 0; v < 12; ++v) mesh.vertices.push_back(Vec3(coordinate(random), coordinate(random), coordinate(random)));
        const int faces = 1 + trial % 30;
        for (int f = 0; f < faces; ++f) mesh.faces.push_back({pick(random), pick(random), pick(random)});
        const std::size_t before = mesh.faces.size();
        const TriMesh input = mesh;
        try {
            const MeshRepairs r = repairMesh(mesh, -1.0, "soup");
            EXPECT_NO_THROW(validateMesh(mesh, "repaired")) << trial;
            EXPECT_EQ(mesh.faces.size() + r.degenerateFaces + r.duplicateFaces, before) << trial;
            // Where each vertex went: to a vertex at its position (the soup's positions are whole
            // numbers: welding merges only equal ones), or removed because no face left uses a
            // vertex there; every vertex left comes from the first input vertex at its position.
            const VertexMap map = r.vertexMap.empty() ? [&] {
                VertexMap identity(input.vertices.size());
                std::iota(identity.begin(), identity.end(), Index(0));
                return identity;
            }() : r.vertexMap;
            ASSERT_EQ(map.size(), input.vertices.size()) << trial;
            std::vector<bool> reached(mesh.vertices.size(), false);
            for (std::size_t u = 0; u < map.size(); ++u) {
                const bool usedThere = std::any_of(mesh.faces.begin(), mesh.faces.end(), [&](const Face& f) {
                    return std::any_of(f.begin(), f.end(), [&](Index v) { return mesh.vertices[v] == input.vertices[u]; });
                });
                if (map[u] == kNoVertex) {
                    EXPECT_FALSE(usedThere) << trial << " vertex " << u;
                    continue;
                }
                ASSERT_LT(map[u], mesh.vertices.size()) << trial;
                EXPECT_EQ(mesh.vertices[map[u]], input.vertices[u]) << trial << " vertex " << u;
                if (!reached[map[u]]) {
                    EXPECT_EQ(std::find(input.vertices.begin(), input.vertices.end(), input.vertices[u]) - input.vertices.begin(), std::ptrdiff_t(u))
                        << trial << ": the first vertex at a position stands for it";
                    reached[map[u]] = true;
                }
            }
            EXPECT_EQ(std::count(reached.begin(), reached.end(), true), std::ptrdiff_t(mesh.vertices.size())) << trial;
            if (r.nonOrientablePieces == 0) {
                // Every edge two faces share is run once each way (edges of three or more faces excepted).
                std::map<std::pair<Index, Index>, int> runs;
                for (const Face& f : mesh.faces)
                    for (int k = 0; k < 3; ++k) ++runs[{f[k], f[(k + 1) % 3]}];
                for (const auto& [edge, count] : runs) {
                    const auto back = runs.find({edge.second, edge.first});
                    const int shared = count + (back == runs.end() ? 0 : back->second);
                    if (shared == 2) {
                        EXPECT_EQ(count, 1) << trial;
                    }
                }
            }
        } catch (const InputError& e) {
            EXPECT_NE(e.problem().find("no face is left"), std::string::npos) << trial << ": " << e.problem();
        }
    }
}

// One vertex 1e19 away makes the mesh's size, and the near-duplicate weld that scales with it,
// huge: every other vertex welds into one and no face is left. The error says why.
TEST(MeshRepair, AFarVertexThatMakesTheWeldSwallowTheMeshIsNamedAsTheCause) {
    TriMesh mesh = makeBox(Vec3(0.5, 0.5, 0.5), 1);
    mesh.vertices.back().x() = 1e19;
    try {
        repairMesh(mesh, -1.0, "far", {});
        ADD_FAILURE() << "faces were left";
    } catch (const InputError& e) {
        EXPECT_NE(e.problem().find("no face is left"), std::string::npos) << e.problem();
        EXPECT_NE(e.problem().find("welded within 1e+13"), std::string::npos) << e.problem();
        EXPECT_NE(e.problem().find("a vertex far from the others"), std::string::npos) << e.problem();
    }
}

TEST(MeshRepair, CorruptInputIsNotRepaired) {
    TriMesh nan = makeIcoSphere(1.0, 1);
    nan.vertices[3].y() = std::numeric_limits<double>::quiet_NaN();
    MeshSourceLines lines;
    for (std::size_t i = 0; i < nan.vertices.size(); ++i) lines.vertexLine.push_back(10 + i);
    try {
        repairMesh(nan, -1.0, "nan.tri", lines);
        ADD_FAILURE() << "repaired a NaN";
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), 13u);
        EXPECT_TRUE(contains(e.problem(), "NaN")) << e.problem();
    }
    TriMesh range = makeIcoSphere(1.0, 1);
    range.faces[2][1] = 999;
    EXPECT_THROW(repairMesh(range, -1.0, "range"), InputError);
}

TEST(MeshRepair, StrictReadingNamesTheFirstDefectAndItsLine) {
    const TriMesh sphere = makeIcoSphere(1.0, 1);
    MeshSourceLines lines;
    for (std::size_t i = 0; i < sphere.vertices.size() + 1; ++i) lines.vertexLine.push_back(3 + i);
    for (std::size_t i = 0; i < sphere.faces.size(); ++i) lines.faceLine.push_back(100 + i);
    auto problem = [&](const TriMesh& mesh) {
        try {
            requireNoDefects(mesh, -1.0, "strict.tri", lines);
        } catch (const InputError& e) {
            return std::to_string(e.line()) + ": " + e.problem();
        }
        return std::string("accepted");
    };
    TriMesh unreferenced = sphere;
    unreferenced.vertices.push_back(Vec3(7, 7, 7));
    const Index last = Index(sphere.vertices.size());
    EXPECT_TRUE(contains(problem(unreferenced), std::to_string(3 + last) + ": vertex " + std::to_string(last))) << problem(unreferenced);
    EXPECT_TRUE(contains(problem(unreferenced), "used by no face")) << problem(unreferenced);

    TriMesh crack = sphere;
    crack.vertices.push_back(sphere.vertices[2] + Vec3(0, 1e-10, 0));
    const auto usesTwo = std::find_if(crack.faces.begin(), crack.faces.end(), [](const Face& f) { return std::count(f.begin(), f.end(), 2u) > 0; });
    ASSERT_NE(usesTwo, crack.faces.end());
    std::replace(usesTwo->begin(), usesTwo->end(), Index(2), last);
    EXPECT_TRUE(contains(problem(crack), "is within")) << problem(crack);
    EXPECT_TRUE(contains(problem(crack), "of vertex 2 (line 5)")) << problem(crack);

    // One face flipped: reported at the earliest face of an inconsistent pair's later member
    // (brute force over its neighbours).
    TriMesh wound = sphere;
    wound.faces[30] = flipped(wound.faces[30]);
    std::size_t reported = sphere.faces.size();
    for (std::size_t g = 0; g < sphere.faces.size(); ++g) {
        int shared = 0;
        for (Index a : sphere.faces[g]) shared += int(std::count(sphere.faces[30].begin(), sphere.faces[30].end(), a));
        if (g != 30 && shared == 2) reported = std::min(reported, std::max<std::size_t>(g, 30));
    }
    EXPECT_TRUE(contains(problem(wound), std::to_string(100 + reported) + ": face " + std::to_string(reported))) << problem(wound);
    EXPECT_TRUE(contains(problem(wound), "inconsistent winding")) << problem(wound);
    EXPECT_EQ(problem(sphere), "accepted");
}

TEST(MeshRepair, AnAskedToleranceWeldsWiderAndIsReported) {
    TriMesh mesh = makeIcoSphere(1.0, 1);
    const Index near = Index(mesh.vertices.size());
    mesh.vertices.push_back(mesh.vertices[0] + Vec3(1e-4, 0, 0));
    for (Face& f : mesh.faces)
        if (f[0] == 0) {
            f[0] = near;
            break;
        }
    TriMesh wide = mesh;
    const MeshRepairs auto_ = repairMesh(mesh, -1.0, "auto");  // 1e-4 is beyond 1e-6 of the diagonal
    EXPECT_EQ(auto_.weldedVertices, 0u);
    const MeshRepairs asked = repairMesh(wide, 1e-3, "asked");
    EXPECT_EQ(asked.weldedVertices, 1u);
    EXPECT_EQ(asked.weldTolerance, 1e-3);
    EXPECT_TRUE(contains(asked.warnings()[0], "within 0.001")) << asked.warnings()[0];
}

}  // namespace
}  // namespace flexfit
