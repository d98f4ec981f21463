#include "flexfit/assembly.hpp"

#include <algorithm>
#include <cmath>

namespace flexfit {

const char* toString(SnapTechnique technique) {
    switch (technique) {
        case SnapTechnique::CollisionSnap: return "collision snapping";
        case SnapTechnique::ProximitySnap: return "proximity snapping";
        case SnapTechnique::VectorSnap: return "improved snap-fitting";
        case SnapTechnique::ZoneSnap: return "zone snap-fitting";
    }
    return "?";
}

bool AssemblyArea::contains(const Vec3& pointInPart) const {
    const Vec3 p = frame.applyInverse(pointInPart);
    switch (shape) {
        case Shape::Box: return (p.cwiseAbs() - halfExtents).maxCoeff() <= 0.0;
        case Shape::Sphere: return p.norm() <= radius;
        case Shape::Cylinder: return std::abs(p.y()) <= halfHeight && std::hypot(p.x(), p.z()) <= radius;
    }
    return false;
}

Pose finalPose(const AssemblyRule& rule, const Pose& secondary) { return rule.finalRelativePose.then(secondary); }

bool snapConditionHolds(const AssemblyRule& rule, const Pose& primary, const Pose& secondary, bool touching) {
    switch (rule.technique) {
        case SnapTechnique::CollisionSnap: return touching;
        case SnapTechnique::ProximitySnap: {
            const Pose target = finalPose(rule, secondary);
            const double distance = (primary.translation - target.translation).norm();
            const double angle = primary.rotation.angularDistance(target.rotation);
            return distance <= rule.distanceTolerance && angle <= rule.angleTolerance;
        }
        case SnapTechnique::VectorSnap: {
            // Both vectors in the world: origins together and ends together (orientation matters).
            const Vec3 po = primary.apply(rule.primaryVector.origin), pe = primary.apply(rule.primaryVector.end);
            const Vec3 so = secondary.apply(rule.secondaryVector.origin), se = secondary.apply(rule.secondaryVector.end);
            return (po - so).norm() <= rule.vectorTolerance && (pe - se).norm() <= rule.vectorTolerance;
        }
        case SnapTechnique::ZoneSnap: {
            // The primary's vector in the secondary's frame, both ends inside the (convex) area.
            const Vec3 o = secondary.applyInverse(primary.apply(rule.primaryVector.origin));
            const Vec3 e = secondary.applyInverse(primary.apply(rule.primaryVector.end));
            return rule.area.contains(o) && rule.area.contains(e);
        }
    }
    return false;
}

Pose interpolate(const Pose& from, const Pose& to, double s) {
    s = std::clamp(s, 0.0, 1.0);
    Pose out;
    out.rotation = from.rotation.slerp(s, to.rotation).normalized();
    out.translation = (1.0 - s) * from.translation + s * to.translation;
    return out;
}

}  // namespace flexfit
