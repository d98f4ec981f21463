// Bounding volumes of the collision hierarchies, and their overlap tests across part frames.
//
// Sphere: the thesis's volume (eq. 4.1-4.2): cheapest test, rotation-invariant, loose on flat
// or elongated geometry. Aabb: axis-aligned in the part's own frame, so a rigid motion never
// refits it; against another part's box the test is the separating-axis test of two oriented
// boxes (Gottschalk et al., 15 axes), since each box is aligned only in its own frame.
#pragma once

#include "flexfit/names.hpp"
#include "flexfit/core.hpp"

#include <algorithm>
#include <cmath>
#include <span>

namespace flexfit {

enum class BoundingVolumeKind { Sphere, Aabb };
// Its names (names.hpp).
inline constexpr EnumName<BoundingVolumeKind> kBoundingVolumeKindNames[] = {
    {BoundingVolumeKind::Sphere, "sphere", "spheres"},
    {BoundingVolumeKind::Aabb, "aabb", "axis-aligned boxes"},
};
template <> inline constexpr std::span<const EnumName<BoundingVolumeKind>> kEnumNames<BoundingVolumeKind> = kBoundingVolumeKindNames;

struct Sphere {
    Vec3 centre = Vec3::Zero();
    double radius = 0.0;

    // The thesis's construction: centre at the midpoint of the points' bounding box, radius to
    // the farthest point.
    static Sphere around(std::span<const Vec3> points);
    // Smallest sphere enclosing two spheres.
    static Sphere merge(const Sphere& a, const Sphere& b);
    double size() const { return radius; }
};

struct Aabb {
    Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity());
    Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity());

    static Aabb around(std::span<const Vec3> points);
    static Aabb merge(const Aabb& a, const Aabb& b) { return {a.min.cwiseMin(b.min), a.max.cwiseMax(b.max)}; }
    Vec3 centre() const { return 0.5 * (min + max); }
    Vec3 halfExtents() const { return 0.5 * (max - min); }
    double size() const { return (max - min).norm(); }
};

// The pose of frame B seen from frame A: x_A = rotation * x_B + translation. absRotation holds
// |rotation| + epsilon for the box tests (guards parallel axes against round-off).
struct RelativePose {
    Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
    Eigen::Matrix3d absRotation = Eigen::Matrix3d::Identity();
    Vec3 translation = Vec3::Zero();
    bool pureTranslation = true;  // rotation is exactly the identity: boxes stay axis-aligned

    RelativePose() = default;
    RelativePose(const Eigen::Matrix3d& r, const Vec3& t);
    Vec3 apply(const Vec3& pB) const { return rotation * pB + translation; }
};

// Overlap of a volume in frame A with a volume in frame B (touching counts as overlap).
bool overlap(const Sphere& a, const Sphere& b, const RelativePose& bInA);
// The oriented-box case: the separating-axis test on A's and B's face axes, not the 9 cross
// products of their edges ("SAT lite", van den Bergen, J. Graphics Tools 2(4), 1997). Those
// rarely separate boxes in a traversal, and they were most of its cost: a rigid ball coming to
// rest on the rigid mouth took its coherent list 24 % faster without them (and without the
// bounding-sphere pre-test, which the face axes reject as cheaply), though it visits more node
// pairs. It errs only towards overlap: a traversal may descend further, never miss a leaf pair.
bool overlapRotated(const Aabb& a, const Aabb& b, const RelativePose& bInA);
// Inline: the traversals call it per node pair, and parts not turned against each other (a
// tool moved without rotation, parts at rest) need only the plain box test; turned boxes go
// to overlapRotated.
inline bool overlap(const Aabb& a, const Aabb& b, const RelativePose& bInA) {
    if (!bInA.pureTranslation) return overlapRotated(a, b, bInA);
    const Vec3 bMin = b.min + bInA.translation, bMax = b.max + bInA.translation;
    return (a.min.array() <= bMax.array()).all() && (bMin.array() <= a.max.array()).all();
}
bool overlap(const Sphere& a, const Aabb& b, const RelativePose& bInA);
bool overlap(const Aabb& a, const Sphere& b, const RelativePose& bInA);

}  // namespace flexfit
