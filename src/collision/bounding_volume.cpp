#include "flexfit/bounding_volume.hpp"
#include "flexfit/bvh.hpp"

namespace flexfit {


Sphere Sphere::around(std::span<const Vec3> points) {
    Eigen::AlignedBox3d box;
    for (const Vec3& p : points) box.extend(p);
    Sphere s{box.center(), 0.0};
    for (const Vec3& p : points) s.radius = std::max(s.radius, (p - s.centre).norm());
    return s;
}

Sphere Sphere::merge(const Sphere& a, const Sphere& b) {
    const Vec3 d = b.centre - a.centre;
    const double distance = d.norm();
    if (distance + b.radius <= a.radius) return a;
    if (distance + a.radius <= b.radius) return b;
    const double radius = 0.5 * (distance + a.radius + b.radius);
    // Grow a little so round-off never leaves a child poking out.
    return {a.centre + ((radius - a.radius) / distance) * d, radius * (1.0 + 1e-12)};
}

Aabb Aabb::around(std::span<const Vec3> points) {
    Aabb box;
    for (const Vec3& p : points) {
        box.min = box.min.cwiseMin(p);
        box.max = box.max.cwiseMax(p);
    }
    return box;
}

RelativePose::RelativePose(const Eigen::Matrix3d& r, const Vec3& t) : rotation(r), translation(t) {
    absRotation = r.cwiseAbs().array() + 1e-12;
    pureTranslation = r == Eigen::Matrix3d::Identity();
}

bool overlap(const Sphere& a, const Sphere& b, const RelativePose& bInA) {
    const double reach = a.radius + b.radius;
    return (bInA.apply(b.centre) - a.centre).squaredNorm() <= reach * reach;
}

// Separating-axis test of two oriented boxes on their face axes (bounding_volume.hpp): A's box
// axis-aligned in frame A, B's in frame B.
bool overlapRotated(const Aabb& a, const Aabb& b, const RelativePose& bInA) {
    const Vec3 ea = a.halfExtents(), eb = b.halfExtents();
    const Eigen::Matrix3d& r = bInA.rotation;
    const Eigen::Matrix3d& ar = bInA.absRotation;
    const Vec3 t = bInA.apply(b.centre()) - a.centre();  // in A's frame
    for (int i = 0; i < 3; ++i)  // A's axes
        if (std::abs(t[i]) > ea[i] + ar.row(i).dot(eb)) return false;
    for (int j = 0; j < 3; ++j)  // B's axes
        if (std::abs(t.dot(r.col(j))) > ea.dot(ar.col(j)) + eb[j]) return false;
    return true;
}

bool overlap(const Sphere& a, const Aabb& b, const RelativePose& bInA) {
    // The sphere's centre in B's frame, against B's box.
    const Vec3 c = bInA.rotation.transpose() * (a.centre - bInA.translation);
    const Vec3 closest = c.cwiseMax(b.min).cwiseMin(b.max);
    return (closest - c).squaredNorm() <= a.radius * a.radius;
}

bool overlap(const Aabb& a, const Sphere& b, const RelativePose& bInA) {
    const Vec3 c = bInA.apply(b.centre);
    const Vec3 closest = c.cwiseMax(a.min).cwiseMin(a.max);
    return (closest - c).squaredNorm() <= b.radius * b.radius;
}

}  // namespace flexfit

namespace flexfit {

Sphere encloseAll(std::span<const Sphere> volumes, std::span<const Index> which) {
    // The thesis's construction over the children's extents: centre at the midpoint of their
    // bounding box, radius to the farthest child surface.
    Eigen::AlignedBox3d box;
    for (Index i : which) {
        box.extend(volumes[i].centre - Vec3::Constant(volumes[i].radius));
        box.extend(volumes[i].centre + Vec3::Constant(volumes[i].radius));
    }
    Sphere s{box.center(), 0.0};
    for (Index i : which) s.radius = std::max(s.radius, (volumes[i].centre - s.centre).norm() + volumes[i].radius);
    s.radius *= 1.0 + 1e-12;
    return s;
}

Aabb encloseAll(std::span<const Aabb> volumes, std::span<const Index> which) {
    Aabb box;
    for (Index i : which) box = Aabb::merge(box, volumes[i]);
    return box;
}

}  // namespace flexfit
