#include "flexfit/pose.hpp"

#include <cmath>

#include <Eigen/SVD>

namespace flexfit {

Eigen::Matrix4d Pose::matrix() const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = rotation.toRotationMatrix();
    m.topRightCorner<3, 1>() = translation;
    return m;
}

Pose Pose::fromMatrix(const Eigen::Matrix4d& m) {
    const std::string source = "pose matrix";
    if (!m.allFinite()) throw InputError(source, 0, "the matrix has a NaN or infinite entry");
    if (!m.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1), 1e-9))
        throw InputError(source, 0, "the last row of a rigid transform must be (0 0 0 1)");
    // Nearest rotation (polar decomposition through the SVD).
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m.topLeftCorner<3, 3>(), Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
    if (r.determinant() < 0.0 || !(svd.singularValues() - Eigen::Vector3d::Ones()).isZero(1e-6))
        throw InputError(source, 0, "the 3x3 block is not a rotation (scale, shear or reflection)");
    Pose pose;
    pose.rotation = Eigen::Quaterniond(r).normalized();
    pose.translation = m.topRightCorner<3, 1>();
    return pose;
}

void checkPose(const Pose& pose, std::string_view source, std::string_view what) {
    const double norm2 = pose.rotation.squaredNorm();
    if (!pose.translation.allFinite() || !pose.rotation.coeffs().allFinite() || !(norm2 > 0.0) || !std::isfinite(norm2))
        throw InputError(std::string(source), 0, std::string(what) + ": the pose must be finite, with a rotation quaternion of finite non-zero norm");
}

Pose Pose::then(const Pose& after) const {
    Pose out;
    out.rotation = (after.rotation * rotation).normalized();
    out.translation = after.rotation * translation + after.translation;
    return out;
}

}  // namespace flexfit
