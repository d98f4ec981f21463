// The rigid motion stage (rigid_motion.hpp).
#include "rigid_motion.hpp"

#include <algorithm>
#include <cmath>

namespace flexfit::detail {
namespace {

// Velocity first (semi-implicit Euler): the loads of the last step and gravity, then the
// loads are consumed.
void integrateVelocity(const StepContext& step, const Part& part, RigidBody& body) {
    const double h = step.timeStep;
    const Eigen::Matrix3d r = part.pose().rotation.toRotationMatrix();
    const Eigen::Matrix3d inverseInertia = r * body.inverseInertia * r.transpose();
    const Eigen::Matrix3d inertia = inverseInertia.inverse();
    body.linearVelocity += h * (step.gravity + body.inverseMass * body.force);
    body.angularVelocity += h * (inverseInertia * (body.torque - body.angularVelocity.cross(inertia * body.angularVelocity)));
    body.force.setZero();
    body.torque.setZero();
}

// Moves the body along its velocities for dt: its centre of mass in a line, its rotation about it.
void advancePose(double dt, const RigidBody& body, Part& part) {
    const Vec3 com = part.pose().apply(body.centreOfMass) + dt * body.linearVelocity;
    Pose pose = part.pose();
    const double speed = body.angularVelocity.norm();
    if (speed > 0.0)
        pose.rotation = (Eigen::Quaterniond(Eigen::AngleAxisd(speed * dt, body.angularVelocity / speed)) * pose.rotation).normalized();
    pose.translation = com - pose.rotation * body.centreOfMass;
    part.setPose(pose);
}

// Up to contactIterations passes of query and projection, until nothing is left to push out
// (a nanometre per unit of thickness: another pass would find the same contacts).
void resolveRigidContacts(BodyId id, int iterations, Bodies& bodies, CollisionWorld& collision, ContactResponse& response,
                          StepProfiler& profiler) {
    for (int iteration = 0; iteration < iterations; ++iteration) {
        const Stage outer = profiler.running();
        profiler.enter(Stage::NarrowPhase);
        const std::vector<Contact>& contacts = collision.contactsOf(id, true);  // pairs with rigid parts
        clearRefittedChanges(collision, bodies);
        profiler.enter(Stage::ContactResponse);
        const double correction = projectRigidContacts(id, contacts, bodies, response);
        profiler.enter(outer);
        if (correction <= 1e-9 * bodies.rigid[id].thickness) return;  // no contact, or resting
    }
}

}  // namespace

void moveDynamicBodies(const StepContext& step, const WorldSettings& settings, Bodies& bodies, CollisionWorld& collision,
                       ContactResponse& response, StepProfiler& profiler, Profile& profile) {
    const double h = step.timeStep;
    const double bound = settings.maxTravelFraction * bodies.minimumThickness();
    for (BodyId id = 0; id < bodies.size(); ++id) {
        RigidBody& body = bodies.rigid[id];
        if (body.motion != MotionType::Dynamic) continue;
        Part& part = *bodies.parts[id];
        integrateVelocity(step, part, body);
        // The travel the velocity gives decides the sub-steps.
        const double travel = h * (body.linearVelocity.norm() + body.angularVelocity.norm() * body.boundingRadius);
        const int substeps = std::clamp(int(std::ceil(travel / bound)), 1, settings.maxSubsteps);
        for (int s = 0; s < substeps; ++s) {
            advancePose(h / substeps, body, part);
            resolveRigidContacts(id, settings.contactIterations, bodies, collision, response, profiler);
        }
        profile.substeps += std::uint64_t(substeps);
    }
}

}  // namespace flexfit::detail
