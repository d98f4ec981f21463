// Pose against Eigen's own transforms, and its orthonormality over long runs.
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace flexfit;

TEST(Pose, ApplyMatchesHomogeneousMatrix) {
    Pose pose;
    pose.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
    pose.translation = Vec3(4, -5, 6);
    const Vec3 p(0.3, 0.2, -1.1);
    const Eigen::Vector4d h = pose.matrix() * Eigen::Vector4d(p.x(), p.y(), p.z(), 1.0);
    EXPECT_LT((pose.apply(p) - h.head<3>()).norm(), 1e-12);
    EXPECT_LT((pose.applyInverse(pose.apply(p)) - p).norm(), 1e-12);
    const Pose back = Pose::fromMatrix(pose.matrix());
    EXPECT_LT((back.apply(p) - pose.apply(p)).norm(), 1e-12);
}

TEST(Pose, ComposesLikeMatrices) {
    Pose a, b;
    a.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Vec3::UnitZ()));
    a.translation = Vec3(1, 0, 0);
    b.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(-1.2, Vec3::UnitX()));
    b.translation = Vec3(0, 2, 0);
    EXPECT_TRUE(a.then(b).matrix().isApprox(b.matrix() * a.matrix(), 1e-12));
}

TEST(Pose, FromMatrixRejectsNonRigid) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m(0, 0) = 2.0;  // scale
    EXPECT_THROW(Pose::fromMatrix(m), InputError);
    m = Eigen::Matrix4d::Identity();
    m(2, 2) = -1.0;  // reflection
    EXPECT_THROW(Pose::fromMatrix(m), InputError);
    m = Eigen::Matrix4d::Identity();
    m(3, 0) = 1.0;  // projective row
    EXPECT_THROW(Pose::fromMatrix(m), InputError);
    m = Eigen::Matrix4d::Identity();
    m(1, 3) = std::nan("");
    EXPECT_THROW(Pose::fromMatrix(m), InputError);
}

// Sanitizer builds run ~30x slower: 200,000 updates there (the Release run makes the million).
#if defined(__SANITIZE_ADDRESS__)
constexpr int kRigidUpdates = 200000;
#else
constexpr int kRigidUpdates = 1000000;
#endif

TEST(Pose, MillionRigidUpdatesStayOrthonormal) {
    const auto model = buildPartModel(makeTorus1());
    Part part(model);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> angle(-0.05, 0.05), axis(-1, 1), step(-0.01, 0.01);
    for (int i = 0; i < kRigidUpdates; ++i) {
        part.rotate(Vec3(axis(rng), axis(rng), axis(rng)) + Vec3(1e-3, 0, 0), angle(rng));
        part.translate(Vec3(step(rng), step(rng), step(rng)));
    }
    const Eigen::Matrix3d r = part.pose().rotation.toRotationMatrix();
    EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-6);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-6);
}

TEST(Pose, CheckPoseRefusesWhatIsNoPose) {
    // A finite translation and a quaternion that normalises: accepted, whatever its length.
    checkPose(Pose{}, "test", "pose");
    checkPose(Pose{Eigen::Quaterniond(3.0, 0.0, 4.0, 0.0), Vec3(1e10, -2.0, 0.5)}, "test", "pose");
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    const Pose bad[] = {
        {Eigen::Quaterniond(0, 0, 0, 0), Vec3::Zero()},       // no rotation
        {Eigen::Quaterniond(1e200, 0, 0, 0), Vec3::Zero()},   // its squared norm overflows: normalises to zeros
        {Eigen::Quaterniond(1e-200, 0, 0, 0), Vec3::Zero()},  // underflows to 0: normalises to NaN
        {Eigen::Quaterniond(nan, 0, 0, 0), Vec3::Zero()},
        {Eigen::Quaterniond::Identity(), Vec3(0, inf, 0)},
        {Eigen::Quaterniond::Identity(), Vec3(nan, 0, 0)},
    };
    for (const Pose& p : bad) {
        try {
            checkPose(p, "test", "the test's pose");
            ADD_FAILURE() << p.rotation.coeffs().transpose() << " / " << p.translation.transpose() << " accepted";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("the test's pose"), std::string::npos) << e.what();
        }
    }
}
