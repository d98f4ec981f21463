// Bounding volumes: the oriented-box test against a corner-projection implementation of its 6
// face axes (and, for what it leaves out, of all 15 separating axes), and the enclosing
// constructions against their members; the hierarchy's structure under both splits, and the
// surface-area split's trees against the centre split's by their area; a refit against a whole one.
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <random>

using namespace flexfit;

namespace {

std::array<Vec3, 8> corners(const Aabb& b) {
    std::array<Vec3, 8> c;
    for (int i = 0; i < 8; ++i) c[i] = Vec3(i & 1 ? b.max.x() : b.min.x(), i & 2 ? b.max.y() : b.min.y(), i & 4 ? b.max.z() : b.min.z());
    return c;
}

// Reference: project all 8 corners of both boxes on the boxes' 6 face axes and, with
// `crossAxes`, on the 9 cross products of their edges too.
bool referenceBoxesOverlap(const Aabb& a, const Aabb& b, const RelativePose& bInA, bool crossAxes) {
    const auto ca = corners(a);
    std::array<Vec3, 8> cb = corners(b);
    for (Vec3& c : cb) c = bInA.apply(c);
    std::vector<Vec3> axes{Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
    for (int j = 0; j < 3; ++j) axes.push_back(bInA.rotation.col(j));
    for (int i = 0; i < 3 && crossAxes; ++i)
        for (int j = 0; j < 3; ++j) axes.push_back(axes[std::size_t(i)].cross(bInA.rotation.col(j)));
    for (const Vec3& axis : axes) {
        if (axis.squaredNorm() < 1e-18) continue;
        double aMin = 1e300, aMax = -1e300, bMin = 1e300, bMax = -1e300;
        for (const Vec3& c : ca) aMin = std::min(aMin, c.dot(axis)), aMax = std::max(aMax, c.dot(axis));
        for (const Vec3& c : cb) bMin = std::min(bMin, c.dot(axis)), bMax = std::max(bMax, c.dot(axis));
        if (aMax < bMin || bMax < aMin) return false;
    }
    return true;
}

}  // namespace

TEST(BoundingVolume, OrientedBoxTestMatchesFaceAxisProjections) {
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(-1, 1), e(0.05, 1.0);
    int overlaps = 0, disagreements = 0, apartOnlyAcrossEdges = 0;
    for (int k = 0; k < 20000; ++k) {
        const Vec3 ca(u(rng), u(rng), u(rng)), cb(u(rng), u(rng), u(rng));
        const Vec3 ea(e(rng), e(rng), e(rng)), eb(e(rng), e(rng), e(rng));
        const Aabb a{ca - ea, ca + ea}, b{cb - eb, cb + eb};
        const Eigen::Matrix3d r = Eigen::Quaterniond(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized()).toRotationMatrix();
        const RelativePose pose(r, Vec3(u(rng), u(rng), u(rng)) * 2.0);
        const bool reference = referenceBoxesOverlap(a, b, pose, false);
        // The tested version pads for round-off (|R| + 1e-12): it may only err towards overlap.
        if (overlap(a, b, pose) != reference) {
            ++disagreements;
            EXPECT_TRUE(overlap(a, b, pose));
        }
        overlaps += reference;
        // What the face axes leave out: boxes apart only along an edge-edge axis, which it
        // reports overlapping (conservative; that the 15-axis reference's overlaps are among
        // its own follows from the comparison above).
        apartOnlyAcrossEdges += reference && !referenceBoxesOverlap(a, b, pose, true);
    }
    EXPECT_GT(overlaps, 2000);
    EXPECT_LT(disagreements, 5);
    // The sample holds such pairs, so agreeing with the face-axis reference above tells this
    // test from the 15-axis one.
    EXPECT_GT(apartOnlyAcrossEdges, 0);
}

TEST(BoundingVolume, MixedTestsAgreeWithSampling) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1);
    const Aabb box{{-0.5, -0.2, -0.3}, {0.4, 0.6, 0.2}};
    for (int k = 0; k < 2000; ++k) {
        const Sphere s{{u(rng) * 1.5, u(rng) * 1.5, u(rng) * 1.5}, 0.3};
        const Eigen::Matrix3d r = Eigen::Quaterniond(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized()).toRotationMatrix();
        const RelativePose boxInSphereFrame(r, Vec3(u(rng), u(rng), u(rng)) * 0.5);
        // Reference: distance from the sphere centre to the box by sampling the box densely.
        double best = 1e300;
        for (int i = 0; i <= 20; ++i)
            for (int j = 0; j <= 20; ++j)
                for (int l = 0; l <= 20; ++l) {
                    const Vec3 q = box.min + (box.max - box.min).cwiseProduct(Vec3(i, j, l) / 20.0);
                    best = std::min(best, (boxInSphereFrame.apply(q) - s.centre).norm());
                }
        const bool got = overlap(s, box, boxInSphereFrame);
        if (best < 0.28) {
            EXPECT_TRUE(got) << k;
        }
        if (best > 0.33) {
            EXPECT_FALSE(got) << k;
        }
    }
}

TEST(BoundingVolume, EnclosuresContainTheirMembers) {
    std::mt19937 rng(6);
    std::uniform_real_distribution<double> u(-3, 3), r(0, 1);
    std::vector<Sphere> spheres;
    std::vector<Index> all;
    for (Index i = 0; i < 50; ++i) {
        spheres.push_back({{u(rng), u(rng), u(rng)}, r(rng)});
        all.push_back(i);
    }
    const Sphere outer = encloseAll(std::span<const Sphere>(spheres), all);
    for (const Sphere& s : spheres) EXPECT_LE((s.centre - outer.centre).norm() + s.radius, outer.radius * (1 + 1e-12));
    for (std::size_t i = 1; i < spheres.size(); ++i) {
        const Sphere m = Sphere::merge(spheres[i - 1], spheres[i]);
        for (const Sphere& s : {spheres[i - 1], spheres[i]}) EXPECT_LE((s.centre - m.centre).norm() + s.radius, m.radius * (1 + 1e-9));
    }
    const std::vector<Vec3> points{{0, 0, 0}, {4, 0, 0}, {0, 1, 0}};
    const Sphere thesis = Sphere::around(points);
    EXPECT_TRUE(thesis.centre.isApprox(Vec3(2, 0.5, 0)));  // midpoint of the box
    EXPECT_NEAR(thesis.radius, std::sqrt(4.0 + 0.25), 1e-12);  // to the farthest point
}

TEST(BoundingVolume, EachSubtreeIsTheNodeRangeItsLeavesAreIn) {
    // Brute force over parent links: leaf l is in node n's subtree when n is l or an ancestor.
    // Both ways of splitting; every node's volume encloses its children's, every item is in
    // exactly one leaf.
    using Split = Bvh<Aabb>::Split;
    for (Split how : {Split::Centre, Split::SurfaceArea}) {
        std::mt19937 rng(8);
        std::uniform_real_distribution<double> u(-3, 3);
        for (std::size_t count : {1u, 2u, 3u, 7u, 50u}) {
            std::vector<Aabb> leaves;
            for (std::size_t i = 0; i < count; ++i) {
                const Vec3 c(u(rng), u(rng), u(rng));
                leaves.push_back({c.array() - 0.1, c.array() + 0.1});
            }
            Bvh<Aabb> tree;
            tree.build(leaves, how);
            const auto& nodes = tree.nodes();
            ASSERT_EQ(nodes.size(), 2 * count - 1);
            std::vector<int> leafOfItem(count, 0);
            for (std::int32_t n = 0; n < std::int32_t(nodes.size()); ++n) {
                const auto& node = nodes[std::size_t(n)];
                if (node.isLeaf()) {
                    ++leafOfItem[node.item];
                    EXPECT_TRUE(node.volume.min == leaves[node.item].min && node.volume.max == leaves[node.item].max);
                } else {
                    for (std::int32_t child : {node.left, node.right}) {
                        EXPECT_EQ(tree.parent(std::size_t(child)), n);
                        const Aabb& c = nodes[std::size_t(child)].volume;
                        EXPECT_TRUE((node.volume.min.array() <= c.min.array()).all() && (c.max.array() <= node.volume.max.array()).all());
                    }
                }
                std::size_t below = 0;
                for (std::int32_t l = 0; l < std::int32_t(nodes.size()); ++l) {
                    bool inSubtree = false;
                    for (std::int32_t m = l; m >= 0 && !inSubtree; m = tree.parent(std::size_t(m))) inSubtree = m == n;
                    EXPECT_EQ(inSubtree, l >= n && l < tree.subtreeEnd(n)) << "node " << n << ", node " << l;
                    below += inSubtree && nodes[std::size_t(l)].isLeaf();
                }
                EXPECT_EQ(tree.itemCount(n), below) << "node " << n;
            }
            EXPECT_EQ(std::count(leafOfItem.begin(), leafOfItem.end(), 1), std::ptrdiff_t(count));
        }
    }
}

namespace {

// The surface-area cost of a tree, computed from its nodes: the sum of its internal boxes'
// areas (the expected node tests of a random query, up to a constant).
double internalArea(const Bvh<Aabb>& tree) {
    double area = 0.0;
    for (const auto& node : tree.nodes()) {
        if (node.isLeaf()) continue;
        const Vec3 d = node.volume.max - node.volume.min;
        area += d.x() * d.y() + d.y() * d.z() + d.z() * d.x();
    }
    return area;
}

std::vector<Aabb> faceBoxes(const TriMesh& mesh) {
    std::vector<Aabb> boxes;
    for (const Face& f : mesh.faces) {
        const std::array<Vec3, 3> corners{mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]};
        boxes.push_back(Aabb::around(corners));
    }
    return boxes;
}

}  // namespace

// The surface-area split makes trees of less area than the centre split on the meshes the
// face hierarchies meet: a regular sphere, a torus, and a soup of long thin and small triangles
// (as CAD exports have); Wuson, a third-party part, when assimp-testmodels is installed.
TEST(BoundingVolume, SurfaceAreaSplitsMakeTreesOfLessArea) {
    std::vector<std::pair<std::string, std::vector<Aabb>>> cases{{"icosphere", faceBoxes(makeIcoSphere(1.0, 4))},
                                                                  {"torus", faceBoxes(makeTorus(10.0, 2.5, 152, 48))}};
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1), length(0.001, 1.0);
    std::vector<Aabb> soup;
    for (int i = 0; i < 3000; ++i) {
        const Vec3 c(u(rng), u(rng), u(rng)), direction = Vec3(u(rng), u(rng), u(rng)).normalized();
        const double l = length(rng) * length(rng);
        const std::array<Vec3, 3> corners{c, c + l * direction, c + 0.01 * l * Vec3(u(rng), u(rng), u(rng))};
        soup.push_back(Aabb::around(corners));
    }
    cases.emplace_back("soup", soup);
    const std::filesystem::path wuson = "/usr/share/assimp/models/OFF/Wuson.off";
    if (std::filesystem::exists(wuson)) cases.emplace_back("Wuson", faceBoxes(readMesh(wuson).mesh));
    for (const auto& [name, boxes] : cases) {
        Bvh<Aabb> centre, surface;
        centre.build(boxes, Bvh<Aabb>::Split::Centre);
        surface.build(boxes, Bvh<Aabb>::Split::SurfaceArea);
        EXPECT_LT(internalArea(surface), 0.97 * internalArea(centre)) << name;
    }
}

// A refit of some leaves gives every node the volume a whole bottom-up refit (refitAll) gives,
// bit for bit: few changed leaves (their ancestors merged deepest first) and many (a scan of
// every node), boxes and spheres, both splits.
template <class BV>
void expectRefitEqualsRefitAll(BV (*volumeAt)(const Vec3&, double)) {
    using Tree = Bvh<BV>;
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> u(-3, 3), r(0.01, 0.3);
    std::vector<BV> leaves;
    for (int i = 0; i < 500; ++i) leaves.push_back(volumeAt(Vec3(u(rng), u(rng), u(rng)), r(rng)));
    for (typename Tree::Split how : {Tree::Split::Centre, Tree::Split::SurfaceArea}) {
        for (std::size_t changed : {1u, 7u, 40u, 300u}) {
            Tree tree;
            tree.build(leaves, how);
            // Built nodes enclose their leaves directly (encloseAll); a sphere merged from its
            // children's differs, so both trees start from merged volumes.
            tree.refitAll([&](Index i) { return leaves[i]; });
            std::vector<BV> now = leaves;
            std::vector<Index> items;
            for (std::size_t k = 0; k < changed; ++k) {
                const auto item = Index(std::uniform_int_distribution<int>(0, 499)(rng));
                now[item] = volumeAt(Vec3(u(rng), u(rng), u(rng)), r(rng));
                items.push_back(item);
            }
            Tree whole = tree;
            tree.refit(items, [&](Index i) { return now[i]; });
            whole.refitAll([&](Index i) { return now[i]; });
            for (std::size_t n = 0; n < tree.nodes().size(); ++n)
                ASSERT_EQ(std::memcmp(&tree.nodes()[n].volume, &whole.nodes()[n].volume, sizeof(BV)), 0)
                    << "node " << n << ", " << changed << " leaves changed";
        }
    }
}

TEST(BoundingVolume, RefitGivesEveryNodeTheVolumeOfAWholeRefit) {
    expectRefitEqualsRefitAll<Aabb>([](const Vec3& c, double r) { return Aabb{c.array() - r, c.array() + r}; });
    expectRefitEqualsRefitAll<Sphere>([](const Vec3& c, double r) { return Sphere{c, r}; });
}
