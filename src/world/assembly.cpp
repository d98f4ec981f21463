#include "flexfit/assembly.hpp"

#include "assembly_stage.hpp"

#include <algorithm>
#include <cmath>

namespace flexfit {

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

// --- The stage (assembly_stage.hpp) ---

namespace flexfit::detail {
namespace {

bool touching(std::span<const Contact> contacts, BodyId a, BodyId b) {
    for (const Contact& c : contacts)
        if ((c.partA == a && c.partB == b) || (c.partA == b && c.partB == a)) return true;
    return false;
}

// The rule's condition holds: the snap starts, and the primary is the snap's from now on.
void startSnap(const StepContext& step, const Pose& target, RuleState& state, AssemblyState& assembly, Bodies& bodies,
               OperatorState& op) {
    const AssemblyRule& rule = state.rule;
    state.phase = RuleState::Phase::Snapping;
    state.start = step.time;
    state.from = bodies.parts[rule.primary]->pose();
    assembly.events.push_back({rule.name, rule.technique, step.time, state.from, target});
    if (op.grabbed == rule.primary) release(op);  // the snap takes the part from the operator
    RigidBody& body = bodies.rigid[rule.primary];
    body.motion = MotionType::Kinematic;  // the snap drives it from now on
    body.linearVelocity.setZero();
    body.angularVelocity.setZero();
}

}  // namespace

std::size_t addRule(const AssemblyRule& rule, std::size_t bodyCount, AssemblyState& assembly) {
    if (rule.primary >= bodyCount || rule.secondary >= bodyCount || rule.primary == rule.secondary)
        throw InputError("world", 0, "assembly rule '" + rule.name + "' needs two different existing bodies");
    requireNamedValue<InputError>(rule.technique, "world", "assembly rule '" + rule.name + "': technique");
    requireNamedValue<InputError>(rule.area.shape, "world", "assembly rule '" + rule.name + "': area shape");
    if (!(rule.snapDuration >= 0.0) || !std::isfinite(rule.snapDuration))
        throw InputError("world", 0, "assembly rule '" + rule.name + "': snap duration must be finite and >= 0");
    for (const AssemblyVector* v : {&rule.primaryVector, &rule.secondaryVector})
        if (!v->origin.allFinite() || !v->end.allFinite() || v->origin == v->end)
            throw InputError("world", 0, "assembly rule '" + rule.name + "': a vector's origin and end must be finite and differ (zero length has no direction)");
    const std::string what = "assembly rule '" + rule.name + "'";
    checkPose(rule.finalRelativePose, "world", what + ": final relative pose");
    checkPose(rule.area.frame, "world", what + ": area frame");
    for (const double tolerance : {rule.distanceTolerance, rule.angleTolerance, rule.vectorTolerance})
        if (!(tolerance >= 0.0) || !std::isfinite(tolerance))
            throw InputError("world", 0, "assembly rule '" + rule.name + "': its distance, angle and vector tolerances must be finite and >= 0");
    const AssemblyArea& area = rule.area;
    if (!area.halfExtents.allFinite() || !(area.halfExtents.minCoeff() >= 0.0) || !(area.radius >= 0.0) || !std::isfinite(area.radius) ||
        !(area.halfHeight >= 0.0) || !std::isfinite(area.halfHeight))
        throw InputError("world", 0, "assembly rule '" + rule.name + "': the area's half extents, radius and half height must be finite and >= 0");
    RuleState state;
    state.rule = rule;
    assembly.rules.push_back(state);
    return assembly.rules.size() - 1;
}

void assemble(const StepContext& step, std::span<const Contact> contacts, AssemblyState& assembly, Bodies& bodies,
              OperatorState& op) {
    for (RuleState& state : assembly.rules) {
        const AssemblyRule& rule = state.rule;
        Part& primary = *bodies.parts[rule.primary];
        const Pose& secondary = bodies.parts[rule.secondary]->pose();
        const Pose target = finalPose(rule, secondary);
        if (state.phase == RuleState::Phase::Waiting) {
            if (!snapConditionHolds(rule, primary.pose(), secondary, touching(contacts, rule.primary, rule.secondary))) continue;
            startSnap(step, target, state, assembly, bodies, op);
        }
        const double s = rule.snapDuration > 0.0 ? (step.time + step.timeStep - state.start) / rule.snapDuration : 1.0;
        detail::setPoseUnchecked(primary, interpolate(state.from, target, s));
        ++bodies.poseEpoch;
        if (s >= 1.0) state.phase = RuleState::Phase::Assembled;  // and stays attached
    }
}

}  // namespace flexfit::detail
