// The divergence check at the end of a world step (divergence_check.hpp).
#include "divergence_check.hpp"

#include "dynamics/divergence.hpp"

#include <sstream>

namespace flexfit::detail {
namespace {

template <class Vector>
void checkRigid(BodyId id, double time, const char* what, const Vector& value) {
    if (value.allFinite()) return;
    std::ostringstream text;
    text << "the " << what << " of the rigid body is not finite (";
    for (Eigen::Index i = 0; i < value.size(); ++i) text << (i ? ", " : "") << value[i];
    text << "); likely cause: a force or torque beyond what the model can take";
    throw DivergenceError(id, time, text.str());
}

}  // namespace

void checkFinite(const StepContext& step, const Bodies& bodies, std::span<const std::uint8_t> zonesChecked) {
    // Masses first: a diverging part pushes non-finite reactions onto the bodies it touches.
    for (BodyId id = 0; id < bodies.size(); ++id) {
        const Part& part = *bodies.parts[id];
        if (part.movingMasses().empty() || (id < zonesChecked.size() && zonesChecked[id])) continue;
        SimulationSettings used = part.settings().simulation;  // as the zone dynamics stepped it
        used.timeStep = step.timeStep;
        checkRegionFinite(part.model(), used, part.state(), part.region(), id, step.time);
    }
    for (BodyId id = 0; id < bodies.size(); ++id) {
        const RigidBody& body = bodies.rigid[id];
        if (body.motion == MotionType::Static) continue;  // never moves, takes no load (added finite)
        const Pose& pose = bodies.parts[id]->pose();
        // Causes before effects: loads, then velocities, then the pose they moved.
        checkRigid(id, step.time, "accumulated force", body.force);
        checkRigid(id, step.time, "accumulated torque", body.torque);
        checkRigid(id, step.time, "linear velocity", body.linearVelocity);
        checkRigid(id, step.time, "angular velocity", body.angularVelocity);
        checkRigid(id, step.time, "position", pose.translation);
        checkRigid(id, step.time, "orientation (quaternion x, y, z, w)", pose.rotation.coeffs());
    }
}

}  // namespace flexfit::detail
