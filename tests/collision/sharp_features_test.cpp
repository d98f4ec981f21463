// The point shell's sharp features (sharp_features.cpp): which faces of a rigid part count as
// sharp at a deformable part's scale, against the geometry of a box and of spheres; that a
// blade passing between a coarse part's masses, unseen by the point shell, is found through
// them (against brute force over the face pairs); that smooth surface hides no deeper than the
// stated bound; and the collision world's automatic choice of query.
#include "flexfit/flexfit.hpp"
#include "same_contacts.hpp"
#include "collision/triangle_queries.hpp"
#include "test_bodies.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
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

using flexfit::testing::pairsOf;

}  // namespace

TEST(SharpFeatures, ABoxIsSharpAtItsEdgesOnly) {
    // A finely divided cube at a scale below its cells: exactly the faces touching a vertex on
    // one of its edges (two coordinates at +-1) are sharp. At a scale whose disc reaches past a cell the
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
    const SharpFeatures wide = findSharpFeatures(fine, 0.25);  // its disc (0.31) reaches past a cell (0.25)
    EXPECT_GT(wide.faces.size(), narrow.faces.size());
    for (Index f : narrow.faces) EXPECT_TRUE(std::binary_search(wide.faces.begin(), wide.faces.end(), f));

    Part coarse(buildPartModel(makeBox(Vec3(1, 1, 1), 1)), rigidPart());
    EXPECT_EQ(findSharpFeatures(coarse, 0.01).faces.size(), coarse.model().faceCount());
}

TEST(SharpFeatures, ASphereIsSmoothWhenLargeAgainstTheScale) {
    // A true sphere of radius k rho stands within rho tan(theta) behind a point over the disc of
    // radius rho cos(theta) / cos(2 theta) when k >= 2.25 (theta = 20 degrees): a finely
    // faceted ball is smooth a little above that and sharp everywhere below it (each face lies
    // within 20 degrees of its corners' normals, so only the height over the disc tells).
    Part ball(buildPartModel(makeIcoSphere(10.0, 4)), rigidPart());
    const double t = std::tan(kSharpFeatureAngle), c = std::cos(kSharpFeatureAngle) / std::cos(2.0 * kSharpFeatureAngle);
    const double threshold = (c * c + t * t) / (2.0 * t);
    ASSERT_NEAR(threshold, 2.25, 0.01);
    EXPECT_TRUE(findSharpFeatures(ball, 10.0 / (1.12 * threshold)).empty());
    EXPECT_EQ(findSharpFeatures(ball, 10.0 / (0.93 * threshold)).faces.size(), ball.model().faceCount());
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
// scale. Whenever neither reports a contact, the part (crossing the top) reaches at most
// sharpFeatureBound(rho) below the top, plus the field's rounding (sqrt(3) cells). Returns the
// crossings unseen and seen.
std::pair<int, int> lowerIntoSlab(const TriMesh& mesh, int trials, unsigned seed) {
    const auto model = buildPartModel(mesh);
    const SignedDistanceField field(model->mesh, model->topology);
    Part tool(model, rigidPart());
    Part slab(buildPartModel(makeBox(Vec3(6.0, 1.0, 6.0), 3)));
    PartCollider toolCollider(tool, BoundingVolumeKind::Aabb), slabCollider(slab, BoundingVolumeKind::Aabb);
    slabCollider.buildRestPointTree(slab);
    const double rho = restResolution(slab);
    const SharpFeatures features = findSharpFeatures(tool, rho);
    const double bound = sharpFeatureBound(rho) + std::sqrt(3.0) * field.cellSize();
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

// Sanitizer builds run ~30x slower: a third of the trials there, on the tools of at most
// kMaxToolFaces faces (the larger tools' distance fields took most of the test's 99 s there):
// the lens, the faceted balls of levels 1 and 2, the UV ball and both boxes. The lens is then
// the only tool with smooth vertices, so the unseen crossings and the bound are checked on it
// alone; the Release run makes every trial on every tool, the smooth balls and the needle too.
#if defined(__SANITIZE_ADDRESS__)
constexpr int kTrialsPerTool = 20;
constexpr std::size_t kMaxToolFaces = 1000;
#else
constexpr int kTrialsPerTool = 60;
constexpr std::size_t kMaxToolFaces = std::numeric_limits<std::size_t>::max();
#endif

TEST(SharpFeatures, NoCrossingDeeperThanTheBoundGoesUnseen) {
    // Smooth balls (no sharp faces at the slab's scale), faceted ones near and below the
    // threshold (some or all faces sharp), a smooth needle (sharp at that scale: it turns
    // over the disc), a faceted lens whose cap corners are smooth (pressed at random tilts
    // to their normals), a blade and a needle-thin box (all sharp): some shallow crossings go
    // unseen (the bound is not empty), none deeper than it.
    int unseen = 0, seen = 0;
    TriMesh needle = makeUvSphere(0.08, 16, 96);  // smooth, 0.16 wide, 2.4 long; its tip turns < 20 degrees a ring
    needle.name = "needle";
    for (Vec3& p : needle.vertices) p.y() *= 15.0;
    TriMesh lens = makeIcoSphere(10.0, 2);  // flat faceted caps: corners smooth at the scale, pressed tilted
    lens.name = "lens";
    for (Vec3& p : lens.vertices) p.y() *= 0.2;
    const TriMesh tools[] = {needle, lens, makeIcoSphere(10.0, 4), makeIcoSphere(6.0, 3), makeIcoSphere(4.0, 2), makeIcoSphere(3.0, 1),
                             makeUvSphere(2.0, 12, 6), makeBox(Vec3(1.5, 0.6, 0.02), 1), makeBox(Vec3(2.0, 0.03, 0.03), 4)};
    unsigned seed = 11;
    for (const TriMesh& mesh : tools) {
        const unsigned toolSeed = seed++;  // each tool's seed whichever tools run
        if (mesh.faces.size() > kMaxToolFaces) continue;
        const auto [u, s] = lowerIntoSlab(mesh, kTrialsPerTool, toolSeed);
        unseen += u;
        seen += s;
    }
    EXPECT_GT(unseen, 0);
    EXPECT_GT(seen, 0);
    Part smooth(buildPartModel(makeIcoSphere(10.0, 4)), rigidPart());
    EXPECT_TRUE(findSharpFeatures(smooth, restResolution(Part(buildPartModel(makeBox(Vec3(6.0, 1.0, 6.0), 3))))).empty());
}

namespace {

// A thin rigid blade standing in a coarse deformable slab, in a collision world under the point
// shell.
struct BladeInSlab {
    Part blade{buildPartModel(makeBox(Vec3(1.0, 0.5, 0.01), 1)), rigidPart()};
    Part slab{buildPartModel(makeBox(Vec3(3.0, 0.5, 3.0), 1))};
    CollisionWorld world{[] {
        CollisionSettings settings;
        settings.rigidDeformable = RigidDeformableQuery::PointShell;
        return settings;
    }()};
    BladeInSlab() {
        blade.setPose(at(Vec3(0.2, 0.7, 0.1)));
        world.add(0, blade);
        world.add(1, slab);
    }
};

}  // namespace

TEST(SharpFeatures, TheCollisionWorldFindsTheBladeUnderThePointShell) {
    BladeInSlab scene;
    Part& blade = scene.blade;
    const Part& slab = scene.slab;
    CollisionWorld& world = scene.world;
    const std::vector<Contact> contacts = world.findContacts();
    ASSERT_FALSE(contacts.empty());
    for (const Contact& c : contacts) EXPECT_EQ(c.massB, kNoMass);  // through the blade's faces
    const std::vector<Index> all = [&] {
        std::vector<Index> f(blade.model().faceCount());
        for (Index i = 0; i < f.size(); ++i) f[i] = i;
        return f;
    }();
    EXPECT_EQ(pairsOf(contacts), bruteForcePairs(blade, all, slab));
    // The sharp faces' query is counted as a face query, traversed each time.
    EXPECT_EQ(world.faceQueries(), 1u);
    EXPECT_EQ(world.faceTraversals(), 1u);
    world.findContacts();
    EXPECT_EQ(world.faceQueries(), 2u);
    EXPECT_EQ(world.faceTraversals(), 2u);
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

TEST(SharpFeatures, AFaceOverTheDiscLeadsOnToItsFarCorners) {
    // A small flat fan around v, then one long flat face (v's neighbour h to two corners 3 away)
    // and, hanging from that face's far edge 0.72 from v, a vertical wall: a fold within the
    // disc that only the long face's far corners lead to. The fan's faces are sharp.
    TriMesh mesh;
    mesh.name = "fan and wall";
    mesh.vertices.push_back(Vec3::Zero());  // v
    for (int k = 0; k < 6; ++k) {
        const double a = (30.0 + 60.0 * k) * M_PI / 180.0;
        mesh.vertices.push_back(Vec3(0.05 * std::cos(a), 0.0, 0.05 * std::sin(a)));
    }
    for (Index k = 0; k < 6; ++k) mesh.faces.push_back({0, 1 + (k + 1) % 6, 1 + k});  // normal +y
    const Index h = 2;                                                                  // at 90 degrees: (0, 0, 0.05)
    const Index a = Index(mesh.vertices.size()), b = a + 1, c = a + 2;
    mesh.vertices.push_back(Vec3(-3.0, 0.0, 0.72));
    mesh.vertices.push_back(Vec3(3.0, 0.0, 0.72));
    mesh.vertices.push_back(Vec3(0.0, -1.5, 0.74));
    mesh.faces.push_back({h, a, b});
    mesh.faces.push_back({a, c, b});
    Part part(buildPartModel(mesh), rigidPart());
    const double rho = 0.6;  // disc radius 0.74: the wall's corners lie far outside it
    ASSERT_GT((mesh.vertices[a] - mesh.vertices[0]).norm(), 4.0 * rho);
    const SharpFeatures features = findSharpFeatures(part, rho);
    for (Index f = 0; f < 6; ++f) EXPECT_TRUE(std::binary_search(features.faces.begin(), features.faces.end(), f)) << "fan face " << f;
    // Without the wall the same fan is smooth.
    mesh.faces.pop_back();
    mesh.vertices.pop_back();
    const SharpFeatures flat = findSharpFeatures(Part(buildPartModel(mesh), rigidPart()), rho);
    for (Index f = 0; f < 6; ++f) EXPECT_FALSE(std::binary_search(flat.faces.begin(), flat.faces.end(), f)) << "fan face " << f;
}

namespace {

// The contacts of a ball (rigid, level-2, radius 6) on torus2 (deformable, finer) under Auto,
// with the parts added in `order`, and optionally a coarse deformable slab far away.
std::vector<Contact> ballOnTorus2(bool torusFirst, bool withCoarseSlab) {
    CollisionSettings settings;
    Part ball(buildPartModel(makeIcoSphere(6.0, 2)), rigidPart());
    ball.setPose(at(Vec3(12.0, 8.0, 0.0)));
    Part torus(buildPartModel(makeTorus2()));
    Part slab(buildPartModel(makeBox(Vec3(8.0, 1.0, 8.0), 1)));  // mean edge above the ball's
    slab.setPose(at(Vec3(0.0, -50.0, 0.0)));
    CollisionWorld world(settings);
    BodyId next = 0;
    if (torusFirst) world.add(next++, torus);
    world.add(next++, ball);
    if (!torusFirst) world.add(next++, torus);
    if (withCoarseSlab) world.add(next++, slab);
    std::vector<Contact> contacts = world.findContacts();
    for (Contact& c : contacts) c.partA = c.partB = 0;  // the ids differ with the order
    return contacts;
}

}  // namespace

TEST(SharpFeatures, AutoChoosesWhicheverPartComesFirst) {
    // The torus added before the ball gets the same point-shell contacts as after it.
    const std::vector<Contact> after = ballOnTorus2(false, false);
    ASSERT_FALSE(after.empty());
    for (const Contact& c : after) EXPECT_NE(c.massB, kNoMass);
    const std::vector<Contact> before = ballOnTorus2(true, false);
    ASSERT_EQ(before.size(), after.size());
    for (std::size_t i = 0; i < after.size(); ++i) {
        EXPECT_EQ(before[i].massB, after[i].massB);
        EXPECT_EQ(before[i].depth, after[i].depth);
    }
}

TEST(SharpFeatures, ACoarserDeformablePartLeavesTheBallsScaleAlone) {
    // A slab coarser than the ball is served by faces, so the ball's features stay at the
    // torus's scale (none): its contacts with the torus are still the point shell's alone. At
    // the slab's scale the ball would be sharp all over.
    Part slab(buildPartModel(makeBox(Vec3(8.0, 1.0, 8.0), 1)));
    Part ball(buildPartModel(makeIcoSphere(6.0, 2)), rigidPart());
    ASSERT_EQ(findSharpFeatures(ball, restResolution(slab)).faces.size(), ball.model().faceCount());
    const std::vector<Contact> alone = ballOnTorus2(false, false), withSlab = ballOnTorus2(false, true);
    ASSERT_EQ(withSlab.size(), alone.size());
    for (std::size_t i = 0; i < alone.size(); ++i) {
        EXPECT_NE(withSlab[i].massB, kNoMass);
        EXPECT_EQ(withSlab[i].massB, alone[i].massB);
        EXPECT_EQ(withSlab[i].depth, alone[i].depth);
    }
}

TEST(SharpFeatures, ChangingTheExactTestKeepsTheSharpFaces) {
    // The blade under the point shell: switched to sphere-triangle its faces still meet the
    // slab (through the face spheres, a superset of the triangles' pairs), and switched back
    // the contacts are those of the start.
    BladeInSlab scene;
    CollisionWorld& world = scene.world;
    const std::vector<Contact> start = world.findContacts();
    ASSERT_FALSE(start.empty());
    world.setExactTest(ExactTest::SphereTriangle);
    const std::vector<Contact> spheres = world.findContacts();
    const auto spherePairs = pairsOf(spheres);
    for (const Contact& c : spheres) EXPECT_EQ(c.massB, kNoMass);
    for (const auto& pair : pairsOf(start)) EXPECT_TRUE(spherePairs.count(pair)) << pair.first << "," << pair.second;
    world.setExactTest(ExactTest::TriangleTriangle);
    const std::vector<Contact> back = world.findContacts();
    EXPECT_EQ(pairsOf(back), pairsOf(start));
    ASSERT_EQ(back.size(), start.size());
    for (std::size_t i = 0; i < back.size(); ++i) EXPECT_EQ(back[i].depth, start[i].depth);
}
