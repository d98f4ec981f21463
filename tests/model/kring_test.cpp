// k-rings against an independent BFS over a dense adjacency matrix built from the faces.
#include "flexfit/flexfit.hpp"
#include "model/kring.hpp"

#include <gtest/gtest.h>

#include <map>
#include <queue>
#include <random>

using namespace flexfit;

namespace {

// Distances from the seeds by BFS on a dense V x V adjacency matrix (small meshes only).
std::vector<int> denseDistances(const TriMesh& mesh, const std::vector<Index>& seeds) {
    const std::size_t n = mesh.vertices.size();
    std::vector<std::vector<char>> adjacent(n, std::vector<char>(n, 0));
    for (const Face& f : mesh.faces)
        for (int e = 0; e < 3; ++e) adjacent[f[e]][f[(e + 1) % 3]] = adjacent[f[(e + 1) % 3]][f[e]] = 1;
    std::vector<int> distance(n, -1);
    std::queue<std::size_t> queue;
    for (Index s : seeds)
        if (distance[s] < 0) {
            distance[s] = 0;
            queue.push(s);
        }
    while (!queue.empty()) {
        const std::size_t u = queue.front();
        queue.pop();
        for (std::size_t w = 0; w < n; ++w)
            if (adjacent[u][w] && distance[w] < 0) {
                distance[w] = distance[u] + 1;
                queue.push(w);
            }
    }
    return distance;
}

}  // namespace

TEST(KRing, MatchesDenseBfsOnSmallMeshes) {
    std::mt19937 rng(3);
    for (const TriMesh& mesh : {makeTorus(3, 1, 9, 7), makeIcoSphere(1, 2), makeUvSphere(1, 10, 6)}) {
        const Topology topo = buildTopology(mesh.faces, mesh.vertices.size());
        KRingWalker walker(mesh.vertices.size());
        std::uniform_int_distribution<Index> pick(0, Index(mesh.vertices.size() - 1));
        for (int trial = 0; trial < 20; ++trial) {
            std::vector<Index> seeds{pick(rng)};
            if (trial % 3 == 0) seeds.push_back(pick(rng));
            const std::vector<int> reference = denseDistances(mesh, seeds);
            for (int rings = 0; rings <= 6; ++rings) {
                std::vector<RingMember> members;
                walker.collect(topo, seeds, rings, members);
                std::map<Index, int> got;
                for (const RingMember& m : members) {
                    EXPECT_TRUE(got.emplace(m.mass, m.depth).second) << "mass listed twice";
                }
                std::size_t expected = 0;
                for (std::size_t v = 0; v < reference.size(); ++v)
                    if (reference[v] >= 0 && reference[v] <= rings) {
                        ++expected;
                        ASSERT_TRUE(got.count(Index(v))) << "missing mass " << v << " rings " << rings;
                        EXPECT_EQ(got[Index(v)], reference[v]);
                    }
                EXPECT_EQ(members.size(), expected);
            }
        }
    }
}

TEST(KRing, SeedsFirstAndNoWorkBeyondTheRing) {
    const TriMesh mesh = makeHeart();
    const Topology topo = buildTopology(mesh.faces, mesh.vertices.size());
    KRingWalker walker(mesh.vertices.size());
    std::vector<RingMember> members;
    const std::vector<Index> seeds{100, 100, 101};
    walker.collect(topo, seeds, 0, members);
    ASSERT_EQ(members.size(), 2u);  // duplicates ignored
    EXPECT_EQ(members[0].mass, 100u);
    EXPECT_EQ(members[1].mass, 101u);
    // A query touches only what it returns: its cost does not depend on the mesh size.
    walker.collect(topo, std::vector<Index>{4000}, 2, members);
    EXPECT_EQ(walker.lastVisited(), members.size());
    EXPECT_LT(members.size(), 40u);
}
