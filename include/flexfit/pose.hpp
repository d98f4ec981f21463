// Rigid pose of a part: rotation + translation, the homogeneous transform T of thesis
// eq. 2.7-2.9.
//
// Stored as a unit quaternion and a vector, renormalised after every change, so the rotation
// stays orthonormal over millions of updates (a 4x4 matrix accumulated by products drifts).
// matrix() gives the 4x4 form for rendering and export.
#pragma once

#include "flexfit/core.hpp"

#include <string_view>

namespace flexfit {

struct Pose {
    Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
    Vec3 translation = Vec3::Zero();

    // Part frame -> world frame.
    Vec3 apply(const Vec3& p) const { return rotation * p + translation; }
    Vec3 rotate(const Vec3& v) const { return rotation * v; }
    // World frame -> part frame.
    Vec3 applyInverse(const Vec3& p) const { return rotation.conjugate() * (p - translation); }
    Vec3 rotateInverse(const Vec3& v) const { return rotation.conjugate() * v; }

    Eigen::Matrix4d matrix() const;
    // From a homogeneous matrix; its 3x3 block is re-orthonormalised. Throws InputError when
    // the matrix is not finite, its last row is not (0 0 0 1) or its block is not a rotation.
    static Pose fromMatrix(const Eigen::Matrix4d& m);
    // `after` applied after this pose: (after * this)(p) = after(this(p)).
    Pose then(const Pose& after) const;
};

// Throws InputError (`source`, "`what`: ...") unless the pose is one: a finite translation and a
// rotation quaternion of finite, non-zero squared norm (it is normalised where it is set; a
// quaternion of coefficients 1e200 would normalise to zeros, one of 1e-200 to NaN).
void checkPose(const Pose& pose, std::string_view source, std::string_view what);

// The same pose bit for bit (coefficient by coefficient; a NaN never is): what the rigid motion
// and the collision world's kept answers test before reusing what was found at a pose.
inline bool samePose(const Pose& a, const Pose& b) {
    return a.translation == b.translation && a.rotation.coeffs() == b.rotation.coeffs();
}

}  // namespace flexfit
