// Tests localityOrder: a permutation on any mesh (several components, a lone vertex, fans, a
// non-manifold fin and vertex, a vertex in 20,000 faces), and that it does what it is for: on shuffled generated
// meshes it puts most springs back in spring blocks (counted by buildSpringBlocks) and more
// than reverse Cuthill-McKee (tests/support) does; renumberVertices keeps every face's corners.
#include "flexfit/generators.hpp"
#include "model/spring_blocks.hpp"
#include "model/vertex_order.hpp"
#include "shuffled_mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace flexfit {
namespace {

std::vector<Index> orderOf(const TriMesh& mesh) {
    return detail::localityOrder(buildTopology(mesh.faces, mesh.vertices.size()), mesh.faces);
}

bool isPermutation(std::vector<Index> p) {
    std::sort(p.begin(), p.end());
    for (std::size_t i = 0; i < p.size(); ++i)
        if (p[i] != i) return false;
    return true;
}

// Share of the mesh's edges that buildSpringBlocks puts in blocks.
double blockedShare(const TriMesh& mesh) {
    const Topology t = buildTopology(mesh.faces, mesh.vertices.size());
    const std::vector<double> ones(t.edgeCount(), 1.0);
    const SpringBlocks blocks = buildSpringBlocks(t.edgeA, t.edgeB, ones, ones, ones, mesh.vertices.size());
    return double(blocks.blockedSprings()) / double(t.edgeCount());
}

TEST(LocalityOrder, IsAPermutationOnAnyMesh) {
    TriMesh twoParts = makeIcoSphere(1.0, 1);
    const TriMesh torus = makeTorus(3.0, 1.0, 8, 6);
    const Index base = Index(twoParts.vertices.size());
    twoParts.vertices.insert(twoParts.vertices.end(), torus.vertices.begin(), torus.vertices.end());
    for (Face f : torus.faces) twoParts.faces.push_back({f[0] + base, f[1] + base, f[2] + base});
    twoParts.vertices.push_back(Vec3(9, 9, 9));  // a vertex in no face

    TriMesh fan;  // an open fan and a fin: three faces on edge 0-1
    fan.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {1, 1, 0}};
    fan.faces = {{0, 1, 2}, {0, 3, 1}, {0, 1, 4}, {1, 5, 2}};

    TriMesh bowtie;  // two fans meeting at vertex 0 only (its one-ring is two cycles)
    bowtie.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {-1, 0, 0}, {-1, -1, 0}, {0, -1, 0}};
    bowtie.faces = {{0, 1, 2}, {0, 2, 3}, {0, 4, 5}, {0, 5, 6}};

    TriMesh cone;  // one apex in 20,000 faces (a fan-triangulated cap)
    const int sides = 20000;
    cone.vertices.push_back(Vec3(0, 1, 0));
    for (int i = 0; i < sides; ++i) cone.vertices.push_back(Vec3(std::cos(0.0003 * i), 0, std::sin(0.0003 * i)));
    for (int i = 0; i < sides; ++i) cone.faces.push_back({0, Index(1 + (i + 1) % sides), Index(1 + i)});

    for (const TriMesh* mesh : {&twoParts, &fan, &bowtie, &cone}) {
        const std::vector<Index> order = orderOf(*mesh);
        ASSERT_EQ(order.size(), mesh->vertices.size());
        EXPECT_TRUE(isPermutation(order));
    }
}

TEST(LocalityOrder, OrdersEachComponentWhole) {
    TriMesh twoSpheres = makeIcoSphere(1.0, 2);
    const std::size_t n = twoSpheres.vertices.size();
    for (std::size_t v = 0; v < n; ++v) twoSpheres.vertices.push_back(twoSpheres.vertices[v] + Vec3(5, 0, 0));
    const std::size_t faces = twoSpheres.faces.size();
    for (std::size_t f = 0; f < faces; ++f) {
        const Face g = twoSpheres.faces[f];
        twoSpheres.faces.push_back({g[0] + Index(n), g[1] + Index(n), g[2] + Index(n)});
    }
    const TriMesh shuffled = testing::shuffledVertices(twoSpheres, 5);
    const std::vector<Index> order = orderOf(shuffled);
    // Every vertex of one component comes before every vertex of the other.
    std::vector<int> componentAt(shuffled.vertices.size());
    for (std::size_t v = 0; v < shuffled.vertices.size(); ++v) componentAt[order[v]] = shuffled.vertices[v].x() > 2.5 ? 1 : 0;
    EXPECT_TRUE(std::is_sorted(componentAt.begin(), componentAt.end()) ||
                std::is_sorted(componentAt.rbegin(), componentAt.rend()));
}

TEST(LocalityOrder, PutsAShuffledMeshsSpringsBackInBlocks) {
    struct Case {
        TriMesh mesh;
        double atLeast;
    };
    const Case cases[] = {{makeHeart(), 0.85}, {makeTorus2(), 0.75}, {makeTorus1(), 0.6}};
    for (const Case& c : cases) {
        const TriMesh shuffled = testing::shuffledVertices(c.mesh, 3);
        ASSERT_LT(blockedShare(shuffled), 0.05) << c.mesh.name;
        const TriMesh ordered = detail::renumberVertices(shuffled, orderOf(shuffled));
        const double share = blockedShare(ordered);
        EXPECT_GE(share, c.atLeast) << c.mesh.name;
        EXPECT_GT(share, blockedShare(testing::breadthFirstVertices(shuffled))) << c.mesh.name << ": reverse Cuthill-McKee";
    }
}

TEST(LocalityOrder, RenumberingKeepsEveryFacesCorners) {
    const TriMesh mesh = testing::shuffledVertices(makeTorus(3.0, 1.0, 12, 9), 1);
    const std::vector<Index> order = orderOf(mesh);
    const TriMesh renumbered = detail::renumberVertices(mesh, order);
    ASSERT_EQ(renumbered.faces.size(), mesh.faces.size());
    for (std::size_t f = 0; f < mesh.faces.size(); ++f)
        for (int c = 0; c < 3; ++c) {
            const Index v = mesh.faces[f][std::size_t(c)];
            EXPECT_EQ(renumbered.faces[f][std::size_t(c)], order[v]);
            EXPECT_EQ(renumbered.vertices[order[v]], mesh.vertices[v]);
        }
}

}  // namespace
}  // namespace flexfit
