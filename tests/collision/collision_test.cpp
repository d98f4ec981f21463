// The narrow phase against brute force over every face pair, for random and perturbed meshes
// in random poses, both volumes and both exact tests; frame invariance; refit against rebuild.
#include "collision/pair_query.hpp"
#include "collision/triangle_queries.hpp"
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <random>
#include <set>

using namespace flexfit;

namespace {

TriMesh perturbed(TriMesh mesh, double amount, std::mt19937& rng) {
    std::uniform_real_distribution<double> u(-amount, amount);
    for (Vec3& v : mesh.vertices) v += Vec3(u(rng), u(rng), u(rng));
    return mesh;
}

Pose randomPose(std::mt19937& rng, double spread) {
    std::uniform_real_distribution<double> u(-1, 1);
    Pose p;
    p.rotation = Eigen::Quaterniond(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized());
    p.translation = Vec3(u(rng), u(rng), u(rng)) * spread;
    return p;
}

using FacePairs = std::set<std::pair<Index, Index>>;

struct BruteForce {
    FacePairs candidates, contacts;
};

BruteForce bruteForce(const Part& a, const Part& b, BoundingVolumeKind ka, BoundingVolumeKind kb, ExactTest test) {
    // Box leaves bound the face sphere for the sphere test, the triangle otherwise.
    auto box = [test](std::span<const Vec3> p, const Face& f) {
        return test == ExactTest::SphereTriangle ? faceSphereBox(p, f) : faceBox(p, f);
    };
    const Eigen::Matrix3d ra = a.pose().rotation.toRotationMatrix(), rb = b.pose().rotation.toRotationMatrix();
    const RelativePose bInA(ra.transpose() * rb, ra.transpose() * (b.pose().translation - a.pose().translation));
    const auto& pa = a.state().positions;
    const auto& pb = b.state().positions;
    BruteForce out;
    for (Index fa = 0; fa < a.model().faceCount(); ++fa)
        for (Index fb = 0; fb < b.model().faceCount(); ++fb) {
            const Face& x = a.model().mesh.faces[fa];
            const Face& y = b.model().mesh.faces[fb];
            bool leaves = false;
            if (ka == BoundingVolumeKind::Sphere && kb == BoundingVolumeKind::Sphere)
                leaves = overlap(faceSphere(pa, x), faceSphere(pb, y), bInA);
            else if (ka == BoundingVolumeKind::Aabb && kb == BoundingVolumeKind::Aabb)
                leaves = overlap(box(pa, x), box(pb, y), bInA);
            else if (ka == BoundingVolumeKind::Sphere)
                leaves = overlap(faceSphere(pa, x), box(pb, y), bInA);
            else
                leaves = overlap(box(pa, x), faceSphere(pb, y), bInA);
            if (leaves) out.candidates.insert({fa, fb});
            const Triangle ty{bInA.apply(pb[y[0]]), bInA.apply(pb[y[1]]), bInA.apply(pb[y[2]])};
            const bool hit = test == ExactTest::SphereTriangle
                                 ? sphereTriangleContact(faceSphere(pa, x).centre, faceSphere(pa, x).radius, ty).has_value()
                                 : intersectTriangles({pa[x[0]], pa[x[1]], pa[x[2]]}, ty).has_value();
            if (hit) out.contacts.insert({fa, fb});
        }
    return out;
}

FacePairs contactPairs(const std::vector<Contact>& contacts) {
    FacePairs out;
    for (const Contact& c : contacts) out.insert({c.faceA, c.faceB});
    return out;
}

// The pruned triangle query (A's leaves boxes) against brute force's contacts, with B's leaves
// spheres and boxes; what each query found.
struct PrunedQuery {
    bool contacts = false;
    std::size_t exactTests = 0, candidates = 0;  // leaf pairs the query tested, and that overlap
};
std::vector<PrunedQuery> expectPrunedQueryFindsBruteForcesContacts(const Part& a, const Part& b, int trial) {
    std::vector<PrunedQuery> out;
    for (BoundingVolumeKind kb : {BoundingVolumeKind::Sphere, BoundingVolumeKind::Aabb}) {
        const PartCollider ca(a, BoundingVolumeKind::Aabb), cb(b, kb);
        std::vector<Contact> contacts;
        QueryStats stats;
        queryPair(0, a, ca, 1, b, cb, ExactTest::TriangleTriangle, contacts, stats);
        const BruteForce reference = bruteForce(a, b, BoundingVolumeKind::Aabb, kb, ExactTest::TriangleTriangle);
        EXPECT_EQ(contactPairs(contacts), reference.contacts) << "trial " << trial << " " << toString(kb);
        out.push_back({!contacts.empty(), stats.exactTests, reference.candidates.size()});
    }
    return out;
}

}  // namespace

// The traversal's leaf groups (pair_query.hpp) change which volume tests run, never the result:
// the brute-force comparisons run with every node pair descended (1), small groups and one
// larger than the trees' lower levels.
class NarrowPhaseByLeafGroup : public ::testing::TestWithParam<std::size_t> {
protected:
    void SetUp() override {
#if defined(__SANITIZE_ADDRESS__)
        // Sanitizer builds run ~20x slower: they check the ungrouped and the default traversal
        // (every code path a group size takes); the Release run checks every size.
        if (GetParam() != 1 && GetParam() != detail::kDefaultLeafGroup) GTEST_SKIP() << "Release only: another group size";
#endif
    }
};
INSTANTIATE_TEST_SUITE_P(LeafGroups, NarrowPhaseByLeafGroup, ::testing::Values(1, 2, 4, 64));

TEST_P(NarrowPhaseByLeafGroup, PlanePruningKeepsEveryContact) {
    // Without a candidate list the query prunes by the rest planes of A's faces: the contacts
    // must still be exactly the brute force's, also where A's faces are deformed (not at rest).
    const detail::ScopedLeafGroup grouping(GetParam());
    std::mt19937 rng(11);
    int withContacts = 0;
    for (int trial = 0; trial < 16; ++trial) {
        const auto ma = buildPartModel(perturbed(makeIcoSphere(1.0, 2), 0.05, rng));
        const auto mb = buildPartModel(perturbed(makeTorus(1.0, 0.35, 16, 10), 0.03, rng));
        PartSettings soft;
        Part a(ma, soft), b(mb);
        if (trial % 2) {
            a.applyForce(0, Vec3(0.3, 0.2, -0.1));  // a zone around mass 0 deforms A's faces there
            a.step();
        }
        a.setPose(randomPose(rng, 0.6));
        b.setPose(randomPose(rng, 0.6));
        for (const PrunedQuery& q : expectPrunedQueryFindsBruteForcesContacts(a, b, trial)) withContacts += q.contacts;
    }
    EXPECT_GT(withContacts, 8);
}

TEST_P(NarrowPhaseByLeafGroup, PruningByBsFacePlanesKeepsEveryContact) {
    // A part of small faces (A) against one of large faces (B): the query prunes A's subtrees,
    // and rejects leaf pairs, by the planes of B's faces at rest. A is full-deformable, so none
    // of its faces is at rest and only B's planes prune; B is rigid, at rest, or deformed around
    // a mass (those faces not at rest). The contacts must be exactly the brute force's, and the
    // pruning must leave the exact test fewer leaf pairs than overlap (with the default leaf
    // groups or smaller).
    const detail::ScopedLeafGroup grouping(GetParam());
    std::mt19937 rng(12);
    int withContacts = 0, pruned = 0;
    for (int trial = 0; trial < 12; ++trial) {
        const auto ma = buildPartModel(perturbed(makeTorus(1.0, 0.35, 32, 16), 0.01, rng));
        const auto mb = buildPartModel(perturbed(makeIcoSphere(0.8, 1), 0.05, rng));
        PartSettings full, rigid;
        full.mode = PartMode::FullDeformable;
        rigid.mode = PartMode::Rigid;
        Part a(ma, full), b(mb, trial % 3 == 0 ? rigid : PartSettings{});
        a.applyForce(0, Vec3(0.3, 0.2, -0.1));
        a.step();
        if (trial % 3 == 2) {
            b.applyForce(0, Vec3(-0.2, 0.3, 0.1));  // a zone around mass 0: B's faces there move
            b.step();
        }
        a.setPose(randomPose(rng, 0.5));
        b.setPose(randomPose(rng, 0.5));
        for (const PrunedQuery& q : expectPrunedQueryFindsBruteForcesContacts(a, b, trial)) {
            withContacts += q.contacts;
            pruned += q.exactTests < q.candidates;
        }
    }
    EXPECT_GT(withContacts, 8);
    // Leaf groups larger than B's lower subtrees test their leaf pairs without pruning.
    if (GetParam() <= detail::kDefaultLeafGroup) {
        EXPECT_GT(pruned, 12);
    }
}

TEST_P(NarrowPhaseByLeafGroup, TurnedPairsOfUnevenTreesFindBruteForcesContacts) {
    // A turned pair whose trees differ in size by far is traversed with the smaller tree boxed
    // again in the larger's frame (collision.cpp): a coarse ball (80 faces) and a fine torus
    // (1,024), each as A and as B, in random poses, rigid or deformed around a mass.
    const detail::ScopedLeafGroup grouping(GetParam());
    std::mt19937 rng(13);
    int withContacts = 0;
    for (int trial = 0; trial < 12; ++trial) {
        const auto ball = buildPartModel(perturbed(makeIcoSphere(0.8, 1), 0.05, rng));
        const auto torus = buildPartModel(perturbed(makeTorus(1.0, 0.35, 32, 16), 0.01, rng));
        PartSettings rigid;
        rigid.mode = PartMode::Rigid;
        Part small(ball, trial % 2 ? PartSettings{} : rigid), large(torus, trial % 3 ? PartSettings{} : rigid);
        if (trial % 2) {
            small.applyForce(0, Vec3(0.2, -0.1, 0.3));
            small.step();
        }
        small.setPose(randomPose(rng, 0.5));
        large.setPose(randomPose(rng, 0.5));
        for (const bool smallFirst : {true, false}) {
            const Part& a = smallFirst ? small : large;
            const Part& b = smallFirst ? large : small;
            for (const PrunedQuery& q : expectPrunedQueryFindsBruteForcesContacts(a, b, trial)) withContacts += q.contacts;
        }
    }
    EXPECT_GT(withContacts, 16);
}

TEST_P(NarrowPhaseByLeafGroup, FlushFacesTurnedAlikeKeepTheirContactsWhenTheSmallerTreeIsReboxed) {
    // Two rigid boxes turned by the same rotation, the large one's bottom face lying on the small
    // one's top: their faces touch exactly (depth 0), where the reboxed tree's leaves, turned and
    // rounded otherwise than the exact test's triangles, had come out an ulp apart (found by a
    // fuzzing of coherent against full queries: up to 34 contacts lost in one query).
    const detail::ScopedLeafGroup grouping(GetParam());
    PartSettings rigid;
    rigid.mode = PartMode::Rigid;
    Part small(buildPartModel(makeBox(Vec3(1, 1, 1), 1)), rigid), large(buildPartModel(makeBox(Vec3(1, 1, 1), 4)), rigid);
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    int withContacts = 0;
    for (int trial = 0; trial < 60; ++trial) {
        const Eigen::Quaterniond q = Eigen::Quaterniond::UnitRandom();
        const Vec3 offset(u(rng), 2.0, u(rng));
        for (const bool smallFirst : {true, false}) {
            Part& a = smallFirst ? small : large;
            Part& b = smallFirst ? large : small;
            a.setPose(Pose{q, Vec3::Zero()});
            b.setPose(Pose{q, q * (smallFirst ? offset : Vec3(-offset))});
            PartCollider ca(a, BoundingVolumeKind::Aabb), cb(b, BoundingVolumeKind::Aabb);
            std::vector<Contact> found;
            QueryStats stats;
            queryPair(0, a, ca, 1, b, cb, ExactTest::TriangleTriangle, found, stats);
            const FacePairs expected = bruteForce(a, b, BoundingVolumeKind::Aabb, BoundingVolumeKind::Aabb, ExactTest::TriangleTriangle).contacts;
            EXPECT_EQ(contactPairs(found), expected) << "trial " << trial << (smallFirst ? ", the small box as A" : ", the large box as A");
            withContacts += !expected.empty();
        }
    }
    EXPECT_GT(withContacts, 60);
}

TEST_P(NarrowPhaseByLeafGroup, CandidatesAndContactsEqualBruteForce) {
    const detail::ScopedLeafGroup grouping(GetParam());
    std::mt19937 rng(10);
    const BoundingVolumeKind kinds[2] = {BoundingVolumeKind::Sphere, BoundingVolumeKind::Aabb};
    int withContacts = 0;
#if defined(__SANITIZE_ADDRESS__)
    constexpr int kTrials = 4;  // the brute force is ~20x slower there: the Release build runs 12
#else
    constexpr int kTrials = 12;
#endif
    for (int trial = 0; trial < kTrials; ++trial) {
        const auto ma = buildPartModel(perturbed(makeIcoSphere(1.0, 2), 0.05, rng));
        const auto mb = buildPartModel(perturbed(makeTorus(1.0, 0.35, 16, 10), 0.03, rng));
        Part a(ma), b(mb);
        a.setPose(randomPose(rng, 0.6));
        b.setPose(randomPose(rng, 0.6));
        for (BoundingVolumeKind ka : kinds)
            for (BoundingVolumeKind kb : kinds)
                for (ExactTest test : {ExactTest::SphereTriangle, ExactTest::TriangleTriangle}) {
                    const PartCollider ca(a, ka, test), cb(b, kb, test);
                    std::vector<Contact> contacts;
                    std::vector<std::pair<Index, Index>> candidates;
                    QueryStats stats;
                    queryPair(0, a, ca, 1, b, cb, test, contacts, stats, &candidates);
                    const BruteForce reference = bruteForce(a, b, ka, kb, test);
                    EXPECT_EQ(FacePairs(candidates.begin(), candidates.end()), reference.candidates)
                        << "trial " << trial << " " << toString(ka) << "/" << toString(kb);
                    EXPECT_EQ(candidates.size(), reference.candidates.size());  // each pair once
                    EXPECT_EQ(contactPairs(contacts), reference.contacts) << "trial " << trial << " " << toString(test);
                    withContacts += !contacts.empty();
                }
    }
    EXPECT_GT(withContacts, 20 * kTrials / 12);
}

TEST(NarrowPhase, SameContactsWhenBothPartsMoveTogether) {
    std::mt19937 rng(11);
    const auto ma = buildPartModel(makeTorus1()), mb = buildPartModel(makeTorus(10, 2.5, 20, 12));
    Part a(ma), b(mb);
    // A generic pose: no pair of faces sits within round-off of touching.
    b.setPose(Pose{Eigen::Quaterniond(Eigen::AngleAxisd(1.3, Vec3(0.3, 1.0, 0.2).normalized())), Vec3(23.3, 0.37, -0.21)});
    for (BoundingVolumeKind kind : {BoundingVolumeKind::Sphere, BoundingVolumeKind::Aabb}) {
        const PartCollider ca(a, kind), cb(b, kind);
        std::vector<Contact> before, after;
        QueryStats stats;
        queryPair(0, a, ca, 1, b, cb, ExactTest::TriangleTriangle, before, stats);
        ASSERT_FALSE(before.empty());
        const Pose move = randomPose(rng, 50.0);
        Part a2(ma), b2(mb);
        a2.setPose(a.pose().then(move));
        b2.setPose(b.pose().then(move));
        queryPair(0, a2, ca, 1, b2, cb, ExactTest::TriangleTriangle, after, stats);  // hierarchies untouched
        ASSERT_EQ(contactPairs(before), contactPairs(after));
        for (std::size_t i = 0; i < before.size(); ++i) {
            EXPECT_NEAR(before[i].depth, after[i].depth, 1e-9);
            EXPECT_LT((move.apply(before[i].point) - after[i].point).norm(), 1e-8);
            EXPECT_LT((move.rotate(before[i].normal) - after[i].normal).norm(), 1e-8);
        }
    }
}

TEST(NarrowPhase, RefitAfterDeformationEqualsRebuild) {
    std::mt19937 rng(12);
    const auto ma = buildPartModel(makeTorus1()), mb = buildPartModel(makeIcoSphere(3.0, 3));
    Part deformed(ma), probe(mb);
    probe.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(12.0, 0.5, 0.0)});
    for (BoundingVolumeKind kind : {BoundingVolumeKind::Sphere, BoundingVolumeKind::Aabb}) {
        Part part(ma);
        PartCollider refitted(part, kind);
        part.openZone(ZoneSeed::mass(0), 4);
        part.clearChangedMasses();
        for (int i = 0; i < 300; ++i) {
            part.applyForce(0, Vec3(-40.0, 5.0, 0.0));
            part.step();
        }
        const std::size_t before = refitted.refitNodeCount();
        refitted.refit(part, part.changedMasses());
        // Only the faces around the zone and their ancestors were recomputed.
        EXPECT_LT(refitted.refitNodeCount() - before, 600u);
        const PartCollider rebuilt(part, kind);
        const PartCollider probeCollider(probe, BoundingVolumeKind::Sphere);
        std::vector<Contact> x, y;
        std::vector<std::pair<Index, Index>> cx, cy;
        QueryStats stats;
        queryPair(0, part, refitted, 1, probe, probeCollider, ExactTest::TriangleTriangle, x, stats, &cx);
        queryPair(0, part, rebuilt, 1, probe, probeCollider, ExactTest::TriangleTriangle, y, stats, &cy);
        EXPECT_EQ(contactPairs(x), contactPairs(y));
        EXPECT_EQ(FacePairs(cx.begin(), cx.end()), FacePairs(cy.begin(), cy.end()));
        EXPECT_FALSE(x.empty()) << toString(kind);
    }
}

TEST(NarrowPhase, PointShellContactsEqualBruteForceOverEveryMass) {
    // A rigid ball against a deformable torus, at rest and with a deformed zone, in random
    // poses: the contacts are exactly the masses whose sampled distance is <= 0 (every mass
    // tested, no tree), and each depth is the exact penetration within the field's error.
    std::mt19937 rng(21);
    const auto ballModel = buildPartModel(makeIcoSphere(0.9, 2));
    const auto torusModel = buildPartModel(makeTorus(1.0, 0.35, 48, 16));
    const SignedDistanceField field(ballModel->mesh, ballModel->topology);
    const double error = std::sqrt(3.0) * field.cellSize();
    int withContacts = 0;
    for (int trial = 0; trial < 12; ++trial) {
        Part ball(ballModel, [] { PartSettings s; s.mode = PartMode::Rigid; return s; }());
        Part torus(torusModel);
        if (trial % 2) {
            torus.applyForce(0, Vec3(0.4, 0.3, -0.2));
            for (int i = 0; i < 30; ++i) torus.step();
        }
        ball.setPose(randomPose(rng, 0.4));
        torus.setPose(randomPose(rng, 0.4));
        PartCollider torusCollider(torus, BoundingVolumeKind::Aabb);
        torusCollider.buildRestPointTree(torus);
        std::vector<Contact> contacts;
        QueryStats stats;
        queryPointShell(0, ball, field, 1, torus, torusCollider.restPointTree(), contacts, stats);

        const Eigen::Matrix3d ra = ball.pose().rotation.toRotationMatrix();
        std::set<Index> expected, found;
        for (Index m = 0; m < torusModel->massCount(); ++m) {
            const Vec3 p = ra.transpose() * (torus.pose().apply(torus.state().positions[m]) - ball.pose().translation);
            if (field.inGrid(p) && field.sample(p).distance <= 0.0) expected.insert(m);
        }
        for (const Contact& c : contacts) {
            EXPECT_TRUE(found.insert(c.massB).second) << "mass " << c.massB << " twice";
            const Vec3 p = ra.transpose() * (c.point - ball.pose().translation);
            EXPECT_NEAR(c.depth, -field.query(p).distance, error);
            EXPECT_NEAR(c.normal.norm(), 1.0, 1e-9);
            const Face& f = torusModel->mesh.faces[c.faceB];
            EXPECT_TRUE(f[0] == c.massB || f[1] == c.massB || f[2] == c.massB);
        }
        EXPECT_EQ(found, expected) << "trial " << trial;
        EXPECT_LT(stats.exactTests, torusModel->massCount());  // the tree pruned
        withContacts += !contacts.empty();
    }
    EXPECT_GT(withContacts, 5);
}
