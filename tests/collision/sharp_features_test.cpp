// The point shell's sharp features (sharp_features.cpp): which faces of a rigid part count as
// sharp at a deformable part's scale, against the geometry of a box and of spheres; that a
// blade passing between a coarse part's masses, unseen by the point shell, is found through
// them (against brute force over the face pairs); that smooth surface hides no deeper than the
// stated bound; and the collision world's automatic choice of query.
#include "flexfit/flexfit.hpp"
#include "collision/triangle_queries.hpp"
#include "test_bodies.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

using namespace flexfit;
using flexfit::testing::at;
using flexfit::testing::rigidPart;

namespace {

// Face pairs (faceA, faceB) among A's listed faces and all of B's whose triangles intersect, by
// testing every pair.
std::set<std::pair<Index, Index>> bruteForcePairs(const Part& a, std::span<const Index> facesA, const Part& b) {
    const Eigen::Matrix3d ra = a.pose().rotation.toRotationMatrix();
    auto inA = [&](const Part& p, const Vec3& x) { return Vec3(ra.transpose() * (p.pose().apply(x) - a.pose().translation)); };
    std::set<std::pair<Index, Index>> out;
    for (Index fa : facesA) {
        const Face& f = a.model().mesh.faces[fa];
        const Triangle ta{a.state().positions[f[0]], a.state().positions[f[1]], a.state().positions[f[2]]};
        for (Index fb = 0; fb < b.model().faceCount(); ++fb) {
            const Face& g = b.model().mesh.faces[fb];
            const Triangle tb{inA(b, b.state().positions[g[0]]), inA(b, b.state().positions[g[1]]), inA(b, b.state().positions[g[2]])};
            if (intersectTriangles(ta, tb)) out.insert({fa, fb});
        }
    }
    return out;
}

std::set<std::pair<Index, Index>> pairsOf(const std::vector<Contact>& contacts) {
    std::set<std::pair<Index, Index>> out;
    for (const Contact& c : contacts) out.insert({c.faceA, c.faceB});
    return out;
}

}  // namespace

TEST(SharpFeatures, ABoxIsSharpAtItsEdgesOnly) {
    // A finely divided cube at a scale below its cells: exactly the faces touching a vertex on
    // one of its edges (two coordinates at +-1) are sharp. At a scale reaching past a cell the
    // band widens; at any scale a coarse cube is sharp everywhere.
    Part fine(buildPartModel(makeBox(Vec3(1, 1, 1), 8)), rigidPart());
    auto onEdge = [&](Index v) {
        const Vec3& p = fine.model().mesh.vertices[v];
        return (p.array().abs() > 1.0 - 1e-9).count() >= 2;
    };
    std::vector<Index> expected;
    for (Index f = 0; f < fine.model().faceCount(); ++f) {
        const Face& g = fine.model().mesh.faces[f];
        if (onEdge(g[0]) || onEdge(g[1]) || onEdge(g[2])) expected.push_back(f);
    }
    const SharpFeatures narrow = findSharpFeatures(fine, 0.1);
    EXPECT_EQ(narrow.faces, expected);
    EXPECT_LT(narrow.faces.size(), fine.model().faceCount());
    const SharpFeatures wide = findSharpFeatures(fine, 0.2);
    EXPECT_GT(wide.faces.size(), narrow.faces.size());
    for (Index f : narrow.faces) EXPECT_TRUE(std::binary_search(wide.faces.begin(), wide.faces.end(), f));

    Part coarse(buildPartModel(makeBox(Vec3(1, 1, 1), 1)), rigidPart());
    EXPECT_EQ(findSharpFeatures(coarse, 0.01).faces.size(), coarse.model().faceCount());
}

TEST(SharpFeatures, ASphereIsSmoothWhenLargeAgainstTheScale) {
    // The bound's sphere: smooth at radius >= 2.2 rho, sharp well below (each face lies within
    // 20 degrees of its corners' normals, so only the turn within the reach tells).
    Part ball(buildPartModel(makeIcoSphere(10.0, 4)), rigidPart());
    EXPECT_TRUE(findSharpFeatures(ball, 10.0 / 2.5).empty());
    Part coarse(buildPartModel(makeIcoSphere(10.0, 2)), rigidPart());  // 162 vertices: fewer than the probe's cap
    EXPECT_TRUE(findSharpFeatures(coarse, 10.0 / 3.0).empty());  // its facets turn ~10 degrees more
    EXPECT_EQ(findSharpFeatures(coarse, 10.0 / 1.2).faces.size(), coarse.model().faceCount());
    EXPECT_THROW(findSharpFeatures(ball, -1.0), std::invalid_argument);
    EXPECT_THROW(findSharpFeatures(ball, 1.0, ExactTest::TriangleTriangle, 0.0), std::invalid_argument);
}

TEST(SharpFeatures, ABladeBetweenTheMassesIsFoundThroughItsFaces) {
    // A thin rigid blade pressed edge first into the middle of a coarse deformable slab whose
    // top face has masses only at its corners: no mass is inside the blade, so the point shell
    // sees nothing; the blade's sharp faces meet the slab's top faces, as brute force finds.
    const auto bladeModel = buildPartModel(makeBox(Vec3(1.0, 0.5, 0.01), 1));
    const SignedDistanceField field(bladeModel->mesh, bladeModel->topology);
    Part blade(bladeModel, rigidPart());
    Part slab(buildPartModel(makeBox(Vec3(3.0, 0.5, 3.0), 1)));
    blade.setPose(Pose{Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Vec3::UnitY())), Vec3(0.2, 0.5 + 0.5 - 0.3, 0.1)});
    PartCollider bladeCollider(blade, BoundingVolumeKind::Aabb), slabCollider(slab, BoundingVolumeKind::Aabb);
    slabCollider.buildRestPointTree(slab);

    std::vector<Contact> shell;
    QueryStats stats;
    queryPointShell(0, blade, field, 1, slab, slabCollider.restPointTree(), shell, stats);
    EXPECT_TRUE(shell.empty());  // the hole

    const SharpFeatures features = findSharpFeatures(blade, restResolution(slab));
    ASSERT_EQ(features.faces.size(), blade.model().faceCount());
    std::vector<Contact> found;
    querySharpFeatures(0, blade, bladeCollider, features, 1, slab, slabCollider, ExactTest::TriangleTriangle, found, stats);
    const auto expected = bruteForcePairs(blade, features.faces, slab);
    ASSERT_FALSE(expected.empty());
    EXPECT_EQ(pairsOf(found), expected);
    for (std::size_t i = 1; i < found.size(); ++i)  // (faceA, faceB) order
        EXPECT_LE(std::pair(found[i - 1].faceA, found[i - 1].faceB), std::pair(found[i].faceA, found[i].faceB));
    for (const Contact& c : found) {
        EXPECT_EQ(c.massB, kNoMass);
        EXPECT_GT(c.depth, 0.0);
        EXPECT_NEAR(c.normal.norm(), 1.0, 1e-12);
    }
}

namespace {

// Lowers a rigid part into a coarse slab (top at y = 1, masses 4 apart) at random places,
// turns and depths, queried by the point shell and the part's sharp faces at the slab's
// scale. Whenever neither reports a contact, the part (crossing the top) reaches at most rho tan(20 degrees)
// below the top, plus the field's rounding (sqrt(3) cells). Returns the crossings unseen and
// seen.
std::pair<int, int> lowerIntoSlab(const TriMesh& mesh, int trials, unsigned seed) {
    const auto model = buildPartModel(mesh);
    const SignedDistanceField field(model->mesh, model->topology);
    Part tool(model, rigidPart());
    Part slab(buildPartModel(makeBox(Vec3(6.0, 1.0, 6.0), 3)));
    PartCollider toolCollider(tool, BoundingVolumeKind::Aabb), slabCollider(slab, BoundingVolumeKind::Aabb);
    slabCollider.buildRestPointTree(slab);
    const double rho = restResolution(slab);
    const SharpFeatures features = findSharpFeatures(tool, rho);
    const double bound = rho * std::tan(kSharpFeatureAngle) + std::sqrt(3.0) * field.cellSize();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> across(-3.0, 3.0), depth(0.0, 2.0), turn(-M_PI, M_PI);
    int unseen = 0, seen = 0;
    for (int trial = 0; trial < trials; ++trial) {
        const Vec3 axis = Vec3(across(rng), across(rng), across(rng)).normalized();
        const Eigen::Quaterniond spin(Eigen::AngleAxisd(turn(rng), axis));
        double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
        for (const Vec3& p : tool.model().mesh.vertices) {
            lowest = std::min(lowest, Vec3(spin * p).y());
            highest = std::max(highest, Vec3(spin * p).y());
        }
        // Its lowest vertex d below the top, and part of it above (a part swallowed whole
        // crosses no surface: no query can see it).
        const double x = across(rng), z = across(rng), d = std::min(depth(rng), 0.999 * (highest - lowest));
        tool.setPose(Pose{spin, Vec3(x, 1.0 - d - lowest, z)});
        std::vector<Contact> contacts;
        QueryStats stats;
        queryPointShell(0, tool, field, 1, slab, slabCollider.restPointTree(), contacts, stats);
        querySharpFeatures(0, tool, toolCollider, features, 1, slab, slabCollider, ExactTest::TriangleTriangle, contacts, stats);
        if (contacts.empty()) {
            EXPECT_LE(d, bound) << mesh.name << ", trial " << trial << ", " << features.faces.size() << " sharp faces";
            ++unseen;
        } else {
            ++seen;
        }
    }
    return {unseen, seen};
}

}  // namespace

TEST(SharpFeatures, NoCrossingDeeperThanTheBoundGoesUnseen) {
    // Smooth balls (no sharp faces at the slab's scale), faceted ones near and below the
    // threshold (some or all faces sharp), a smooth needle (sharp at that scale: it turns
    // within the reach), a blade and a needle-thin box (all sharp): some
    // shallow crossings go unseen (the bound is not empty), none deeper than it.
    int unseen = 0, seen = 0;
    TriMesh needle = makeUvSphere(0.08, 16, 96);  // smooth, 0.16 wide, 2.4 long; its tip turns < 20 degrees a ring
    needle.name = "needle";
    for (Vec3& p : needle.vertices) p.y() *= 15.0;
    const TriMesh tools[] = {needle, makeIcoSphere(10.0, 4), makeIcoSphere(6.0, 3), makeIcoSphere(4.0, 2), makeIcoSphere(3.0, 1),
                             makeUvSphere(2.0, 12, 6), makeBox(Vec3(1.5, 0.6, 0.02), 1), makeBox(Vec3(2.0, 0.03, 0.03), 4)};
    unsigned seed = 11;
    for (const TriMesh& mesh : tools) {
        const auto [u, s] = lowerIntoSlab(mesh, 60, seed++);
        unseen += u;
        seen += s;
    }
    EXPECT_GT(unseen, 0);
    EXPECT_GT(seen, 0);
    Part smooth(buildPartModel(makeIcoSphere(10.0, 4)), rigidPart());
    EXPECT_TRUE(findSharpFeatures(smooth, restResolution(Part(buildPartModel(makeBox(Vec3(6.0, 1.0, 6.0), 3))))).empty());
}

TEST(SharpFeatures, TheCollisionWorldFindsTheBladeUnderThePointShell) {
    CollisionSettings settings;
    settings.rigidDeformable = RigidDeformableQuery::PointShell;
    Part blade(buildPartModel(makeBox(Vec3(1.0, 0.5, 0.01), 1)), rigidPart());
    Part slab(buildPartModel(makeBox(Vec3(3.0, 0.5, 3.0), 1)));
    blade.setPose(at(Vec3(0.2, 0.7, 0.1)));
    CollisionWorld world(settings);
    world.add(0, blade);
    world.add(1, slab);
    const std::vector<Contact> contacts = world.findContacts();
    ASSERT_FALSE(contacts.empty());
    for (const Contact& c : contacts) EXPECT_EQ(c.massB, kNoMass);  // through the blade's faces
    const std::vector<Index> all = [&] {
        std::vector<Index> f(blade.model().faceCount());
        for (Index i = 0; i < f.size(); ++i) f[i] = i;
        return f;
    }();
    EXPECT_EQ(pairsOf(contacts), bruteForcePairs(blade, all, slab));
}

TEST(SharpFeatures, AutoChoosesThePointShellWhereTheDeformablePartIsFiner) {
    // A coarse ball on a fine torus: point-shell contacts (each names a mass). A fine ball on a
    // coarse torus: face contacts. The same fine ball under Faces: the same face contacts.
    // (Mean edges: the level-2 ball of radius 6 about 1.6, torus2 about 1.0; the level-4 ball
    // of radius 3 about 0.2, torus1 about 2.5. The coarse ball is smooth at torus2's scale.)
    auto contactsWith = [](RigidDeformableQuery query, double ballRadius, int ballLevel, const TriMesh& torusMesh) {
        CollisionSettings settings;
        settings.rigidDeformable = query;
        Part ball(buildPartModel(makeIcoSphere(ballRadius, ballLevel)), rigidPart());
        ball.setPose(at(Vec3(12.0, ballRadius + 2.0, 0.0)));
        Part torus(buildPartModel(torusMesh));
        CollisionWorld world(settings);
        world.add(0, ball);
        world.add(1, torus);
        return world.findContacts();
    };
    const std::vector<Contact> coarseBall = contactsWith(RigidDeformableQuery::Auto, 6.0, 2, makeTorus2());
    ASSERT_FALSE(coarseBall.empty());
    for (const Contact& c : coarseBall) EXPECT_NE(c.massB, kNoMass);
    const std::vector<Contact> fineBall = contactsWith(RigidDeformableQuery::Auto, 3.0, 4, makeTorus1());
    ASSERT_FALSE(fineBall.empty());
    for (const Contact& c : fineBall) EXPECT_EQ(c.massB, kNoMass);
    EXPECT_EQ(pairsOf(fineBall), pairsOf(contactsWith(RigidDeformableQuery::Faces, 3.0, 4, makeTorus1())));
}
