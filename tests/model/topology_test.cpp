// Tests buildTopology's CSR arrays (edges, edge face counts, vertex neighbours/edges/faces, face neighbours) against an independent brute-force reference built with std::set and O(F^2) face comparisons.
#include "flexfit/generators.hpp"
#include "flexfit/part_model.hpp"
#include "flexfit/topology.hpp"

#include <gtest/gtest.h>

#include "unit_cube.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace flexfit {
namespace {

struct Reference {
    std::vector<std::pair<Index, Index>> edges;  // sorted, a < b
    std::map<std::pair<Index, Index>, Index> faceCount;
    std::vector<std::vector<Index>> neighbours;   // per vertex, ascending
    std::vector<std::vector<Index>> vertexFaces;  // per vertex, ascending
    std::vector<std::vector<Index>> faceFaces;    // per face, ascending
};

Reference bruteForce(const std::vector<Face>& faces, std::size_t vertexCount) {
    Reference ref;
    std::set<std::pair<Index, Index>> edgeSet;
    for (const Face& f : faces)
        for (int k = 0; k < 3; ++k) {
            const Index a = f[k], b = f[(k + 1) % 3];
            const std::pair<Index, Index> e{std::min(a, b), std::max(a, b)};
            edgeSet.insert(e);
            ++ref.faceCount[e];
        }
    ref.edges.assign(edgeSet.begin(), edgeSet.end());

    // Dense adjacency: fine for the small meshes used here.
    std::vector<std::vector<bool>> adjacent(vertexCount, std::vector<bool>(vertexCount, false));
    for (const auto& [a, b] : edgeSet) adjacent[a][b] = adjacent[b][a] = true;
    ref.neighbours.resize(vertexCount);
    for (Index v = 0; v < vertexCount; ++v)
        for (Index w = 0; w < vertexCount; ++w)
            if (adjacent[v][w]) ref.neighbours[v].push_back(w);

    ref.vertexFaces.resize(vertexCount);
    for (Index v = 0; v < vertexCount; ++v)
        for (Index f = 0; f < faces.size(); ++f)
            if (std::find(faces[f].begin(), faces[f].end(), v) != faces[f].end()) ref.vertexFaces[v].push_back(f);

    // Two distinct faces share an edge exactly when they share two vertices.
    ref.faceFaces.resize(faces.size());
    for (Index f = 0; f < faces.size(); ++f)
        for (Index g = 0; g < faces.size(); ++g) {
            if (f == g) continue;
            int shared = 0;
            for (Index v : faces[f]) shared += int(std::count(faces[g].begin(), faces[g].end(), v));
            if (shared >= 2) ref.faceFaces[f].push_back(g);
        }
    return ref;
}

template <class Span>
std::vector<Index> toVector(Span s) {
    return std::vector<Index>(s.begin(), s.end());
}

void expectMatchesReference(const std::vector<Face>& faces, std::size_t vertexCount) {
    const Topology topo = buildTopology(faces, vertexCount);
    const Reference ref = bruteForce(faces, vertexCount);

    EXPECT_EQ(topo.vertexCount, vertexCount);
    EXPECT_EQ(topo.faceCount, faces.size());

    // Edges, sorted (a, b) with a < b, and how many faces use each.
    ASSERT_EQ(topo.edgeCount(), ref.edges.size());
    ASSERT_EQ(topo.edgeA.size(), ref.edges.size());
    ASSERT_EQ(topo.edgeB.size(), ref.edges.size());
    ASSERT_EQ(topo.edgeFaceCount.size(), ref.edges.size());
    for (std::size_t e = 0; e < ref.edges.size(); ++e) {
        EXPECT_EQ(topo.edgeA[e], ref.edges[e].first) << "edge " << e;
        EXPECT_EQ(topo.edgeB[e], ref.edges[e].second) << "edge " << e;
        EXPECT_EQ(topo.edgeFaceCount[e], ref.faceCount.at(ref.edges[e])) << "edge " << e;
    }

    // CSR shapes.
    ASSERT_EQ(topo.vertexNeighborAdr.size(), vertexCount + 1);
    EXPECT_EQ(topo.vertexNeighborAdr.front(), 0u);
    EXPECT_EQ(topo.vertexNeighborAdr.back(), 2 * ref.edges.size());
    EXPECT_EQ(topo.vertexNeighbors.size(), 2 * ref.edges.size());
    EXPECT_EQ(topo.vertexEdges.size(), 2 * ref.edges.size());
    ASSERT_EQ(topo.vertexFaceAdr.size(), vertexCount + 1);
    EXPECT_EQ(topo.vertexFaceAdr.front(), 0u);
    EXPECT_EQ(topo.vertexFaceAdr.back(), 3 * faces.size());
    EXPECT_EQ(topo.vertexFaces.size(), 3 * faces.size());
    ASSERT_EQ(topo.faceNeighborAdr.size(), faces.size() + 1);
    EXPECT_EQ(topo.faceNeighborAdr.front(), 0u);
    EXPECT_EQ(topo.faceNeighborAdr.back(), topo.faceNeighbors.size());

    for (Index v = 0; v < vertexCount; ++v) {
        // mass -> masses, ascending.
        EXPECT_EQ(toVector(topo.neighborsOf(v)), ref.neighbours[v]) << "vertex " << v;
        // mass -> springs, aligned: edge k joins v and neighbour k.
        const auto neighbours = topo.neighborsOf(v);
        const auto edges = topo.edgesOf(v);
        ASSERT_EQ(edges.size(), neighbours.size());
        for (std::size_t k = 0; k < edges.size(); ++k) {
            const Index e = edges[k];
            ASSERT_LT(e, topo.edgeCount());
            const std::pair<Index, Index> expected{std::min(v, neighbours[k]), std::max(v, neighbours[k])};
            EXPECT_EQ(std::make_pair(topo.edgeA[e], topo.edgeB[e]), expected) << "vertex " << v << " slot " << k;
        }
        // mass -> faces.
        EXPECT_EQ(toVector(topo.facesOf(v)), ref.vertexFaces[v]) << "vertex " << v;
    }
    // face -> faces sharing an edge.
    for (Index f = 0; f < faces.size(); ++f) EXPECT_EQ(toVector(topo.faceNeighborsOf(f)), ref.faceFaces[f]) << "face " << f;
}

TriMesh cube() { return flexfit::testing::unitCube(); }

TEST(Topology, Cube) {
    const TriMesh mesh = cube();
    ASSERT_NO_THROW(validateMesh(mesh, "cube"));
    expectMatchesReference(mesh.faces, mesh.vertices.size());
    const Topology topo = buildTopology(mesh.faces, mesh.vertices.size());
    EXPECT_EQ(topo.edgeCount(), 18u);
    for (Index c : topo.edgeFaceCount) EXPECT_EQ(c, 2u);
    for (Index f = 0; f < mesh.faces.size(); ++f) EXPECT_EQ(topo.faceNeighborsOf(f).size(), 3u);
}

TEST(Topology, IcoSphere1) {
    const TriMesh mesh = makeIcoSphere(1.0, 1);
    expectMatchesReference(mesh.faces, mesh.vertices.size());
    const Topology topo = buildTopology(mesh.faces, mesh.vertices.size());
    EXPECT_EQ(topo.edgeCount(), 120u);
    // 12 valence-5 vertices, 30 valence-6.
    int five = 0, six = 0;
    for (Index v = 0; v < mesh.vertices.size(); ++v) {
        five += topo.neighborsOf(v).size() == 5;
        six += topo.neighborsOf(v).size() == 6;
    }
    EXPECT_EQ(five, 12);
    EXPECT_EQ(six, 30);
}

TEST(Topology, Torus5x4) {
    const TriMesh mesh = makeTorus(3.0, 1.0, 5, 4);
    expectMatchesReference(mesh.faces, mesh.vertices.size());
    const Topology topo = buildTopology(mesh.faces, mesh.vertices.size());
    EXPECT_EQ(topo.edgeCount(), 60u);
    for (Index v = 0; v < mesh.vertices.size(); ++v) EXPECT_EQ(topo.neighborsOf(v).size(), 6u);
}

TEST(Topology, NonManifoldEdge) {
    // Three triangles sharing edge 0-1.
    const std::vector<Face> faces = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
    expectMatchesReference(faces, 5);
    const Topology topo = buildTopology(faces, 5);
    ASSERT_EQ(topo.edgeCount(), 7u);
    EXPECT_EQ(topo.edgeA[0], 0u);
    EXPECT_EQ(topo.edgeB[0], 1u);
    EXPECT_EQ(topo.edgeFaceCount[0], 3u);
    // Every face neighbours the other two through the shared edge.
    EXPECT_EQ(toVector(topo.faceNeighborsOf(0)), (std::vector<Index>{1, 2}));
    EXPECT_EQ(toVector(topo.faceNeighborsOf(1)), (std::vector<Index>{0, 2}));
    EXPECT_EQ(toVector(topo.faceNeighborsOf(2)), (std::vector<Index>{0, 1}));
}

TEST(Topology, TwoTetrahedraGluedAlongAnEdge) {
    const std::vector<Face> faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3},
                                     {0, 1, 4}, {0, 5, 1}, {0, 4, 5}, {1, 5, 4}};
    expectMatchesReference(faces, 6);
    const Topology topo = buildTopology(faces, 6);
    EXPECT_EQ(topo.edgeFaceCount[0], 4u);  // edge 0-1
    EXPECT_EQ(topo.faceNeighborsOf(0).size(), 5u);  // 3 others on 0-1, plus 2 across its other edges
}

TEST(Topology, OpenSingleTriangle) {
    const std::vector<Face> faces = {{2, 0, 1}};
    expectMatchesReference(faces, 3);
    const Topology topo = buildTopology(faces, 3);
    EXPECT_EQ(topo.edgeCount(), 3u);
    for (Index c : topo.edgeFaceCount) EXPECT_EQ(c, 1u);
    EXPECT_TRUE(topo.faceNeighborsOf(0).empty());
}

// solidDefect against meshes whose answer is known by construction: a cube and a torus bound
// solids; the cube with a face removed is open, with one face turned over inconsistent, with
// every face turned over inside out; two tetrahedra glued along an edge are not manifold.
TEST(Topology, SolidDefectNamesWhatKeepsAMeshFromBoundingASolid) {
    auto defect = [](const TriMesh& mesh) { return solidDefect(mesh.vertices, mesh.faces, buildTopology(mesh.faces, mesh.vertices.size())); };
    const TriMesh box = cube();
    EXPECT_EQ(defect(box), SolidDefect::None);
    EXPECT_EQ(defect(makeTorus(3.0, 1.0, 5, 4)), SolidDefect::None);
    TriMesh open = box;
    open.faces.pop_back();
    EXPECT_EQ(defect(open), SolidDefect::Open);
    TriMesh turned = box;
    std::swap(turned.faces[3][1], turned.faces[3][2]);
    EXPECT_EQ(defect(turned), SolidDefect::Inconsistent);
    TriMesh insideOut = box;
    for (Face& f : insideOut.faces) std::swap(f[1], f[2]);
    EXPECT_EQ(defect(insideOut), SolidDefect::InsideOut);
    TriMesh glued;
    glued.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, -1, 0}, {0, 0, -1}};
    glued.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}, {0, 1, 4}, {0, 5, 1}, {0, 4, 5}, {1, 5, 4}};
    EXPECT_EQ(defect(glued), SolidDefect::Open);
    EXPECT_EQ(defect(TriMesh{}), SolidDefect::Open);
}

TEST(Topology, UnreferencedVerticesHaveEmptyRanges) {
    // Vertices 0, 3 and 6 are used by no face.
    const std::vector<Face> faces = {{1, 2, 4}, {4, 2, 5}};
    expectMatchesReference(faces, 7);
    const Topology topo = buildTopology(faces, 7);
    for (Index v : {0u, 3u, 6u}) {
        EXPECT_TRUE(topo.neighborsOf(v).empty());
        EXPECT_TRUE(topo.edgesOf(v).empty());
        EXPECT_TRUE(topo.facesOf(v).empty());
    }
}

TEST(Topology, NoFaces) {
    const Topology topo = buildTopology({}, 4);
    EXPECT_EQ(topo.edgeCount(), 0u);
    EXPECT_EQ(topo.vertexNeighborAdr, std::vector<Index>(5, 0));
    EXPECT_EQ(topo.vertexFaceAdr, std::vector<Index>(5, 0));
    EXPECT_EQ(topo.faceNeighborAdr, std::vector<Index>(1, 0));
}

TEST(Topology, LargerMeshesMatchTheReference) {
    for (const TriMesh& mesh : {makeTorus1(), makeUvSphere(1.0, 16, 9), makeHeart(20.0, 12, 8)}) {
        SCOPED_TRACE(mesh.name);
        expectMatchesReference(mesh.faces, mesh.vertices.size());
    }
}

TEST(Topology, FaceOrderDoesNotChangeTheEdges) {
    TriMesh mesh = makeIcoSphere(1.0, 2);
    const Topology a = buildTopology(mesh.faces, mesh.vertices.size());
    std::reverse(mesh.faces.begin(), mesh.faces.end());
    for (Face& f : mesh.faces) std::rotate(f.begin(), f.begin() + 1, f.end());
    const Topology b = buildTopology(mesh.faces, mesh.vertices.size());
    EXPECT_EQ(a.edgeA, b.edgeA);
    EXPECT_EQ(a.edgeB, b.edgeB);
    EXPECT_EQ(a.edgeFaceCount, b.edgeFaceCount);
    EXPECT_EQ(a.vertexNeighbors, b.vertexNeighbors);
    EXPECT_EQ(a.vertexEdges, b.vertexEdges);
}

// Spring count = unique edge count: an edge shared by two faces is ONE spring.
TEST(Topology, SpringCountEqualsUniqueEdgeCount) {
    EXPECT_EQ(buildPartModel(makeTorus1())->springCount(), 1728u);
    EXPECT_EQ(buildPartModel(cube())->springCount(), 18u);
    EXPECT_EQ(buildPartModel(makeTorus2())->springCount(), 4698u);
    EXPECT_EQ(buildPartModel(makeHeart())->springCount(), 22041u);
    const TriMesh ico = makeIcoSphere(1.0, 3);
    EXPECT_EQ(buildPartModel(ico)->springCount(), bruteForce(ico.faces, ico.vertices.size()).edges.size());
}

}  // namespace
}  // namespace flexfit

TEST(Topology, AFaceNamingAMissingVertexIsAnError) {
    // validateMesh guards the readers; buildTopology is public too, and must not write past
    // its arrays when given a face beyond the vertex count.
    const std::vector<Face> faces = {{0, 1, 2}, {0, 1, 7}};
    try {
        (void)buildTopology(faces, 3);
        ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("face 1 names vertex 7 of 3"), std::string::npos) << e.what();
    }
}
