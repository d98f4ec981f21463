// A second implementation as the reference: FCL (OBBRSS hierarchies, exhaustive contacts) must
// report exactly the triangle pairs Flexfit reports, on random meshes and poses.
#include "flexfit/flexfit.hpp"

#include <fcl/fcl.h>
#include <gtest/gtest.h>

#include <random>
#include <set>

using namespace flexfit;

namespace {

using Pairs = std::set<std::pair<Index, Index>>;

Pairs fclPairs(const PartModel& a, const Pose& pa, const PartModel& b, const Pose& pb) {
    auto model = [](const PartModel& m) {
        auto out = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
        std::vector<fcl::Vector3d> vertices(m.restPositions.begin(), m.restPositions.end());
        std::vector<fcl::Triangle> triangles;
        for (const Face& f : m.mesh.faces) triangles.emplace_back(f[0], f[1], f[2]);
        out->beginModel();
        out->addSubModel(vertices, triangles);
        out->endModel();
        return out;
    };
    auto transform = [](const Pose& p) {
        fcl::Transform3d t = fcl::Transform3d::Identity();
        t.linear() = p.rotation.toRotationMatrix();
        t.translation() = p.translation;
        return t;
    };
    fcl::CollisionObjectd oa(model(a), transform(pa)), ob(model(b), transform(pb));
    fcl::CollisionRequestd request(1000000, true);
    fcl::CollisionResultd result;
    fcl::collide(&oa, &ob, request, result);
    Pairs pairs;
    for (std::size_t i = 0; i < result.numContacts(); ++i) pairs.insert({Index(result.getContact(i).b1), Index(result.getContact(i).b2)});
    return pairs;
}

}  // namespace

TEST(FclAgreement, SameTrianglePairsOnRandomPoses) {
    std::mt19937 rng(30);
    std::uniform_real_distribution<double> u(-1, 1);
    const auto torus = buildPartModel(makeTorus1());
    const auto sphere = buildPartModel(makeIcoSphere(6.0, 3));
    int compared = 0;
    for (int trial = 0; trial < 30; ++trial) {
        const auto& mb = trial % 2 ? torus : sphere;
        Part a(torus), b(mb);
        Pose pb;
        pb.rotation = Eigen::Quaterniond(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized());
        pb.translation = Vec3(12.0 + 4.0 * u(rng), 3.0 * u(rng), 3.0 * u(rng));
        b.setPose(pb);
        for (BoundingVolumeKind kind : {BoundingVolumeKind::Sphere, BoundingVolumeKind::Aabb}) {
            const PartCollider ca(a, kind), cb(b, kind);
            std::vector<Contact> contacts;
            QueryStats stats;
            queryPair(0, a, ca, 1, b, cb, ExactTest::TriangleTriangle, contacts, stats);
            Pairs ours;
            for (const Contact& c : contacts) ours.insert({c.faceA, c.faceB});
            EXPECT_EQ(ours, fclPairs(*torus, a.pose(), *mb, pb)) << "trial " << trial;
            compared += !ours.empty();
        }
    }
    EXPECT_GT(compared, 20);
}
