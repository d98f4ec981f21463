// The operator stage (operator_input.hpp): the spring-damper coupling of the grabbed body and
// the kinematic targets.
#include "operator_input.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <string>

namespace flexfit::detail {
namespace {

const std::string kSource = "world";

CouplingGains couplingGains(const RigidBody& body, const GrabSettings& g, double h) {
    const double omega = std::min(2.0 * M_PI * g.frequency, 0.4 / h);
    const double smallestInertia = 1.0 / Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(body.inverseInertia).eigenvalues().maxCoeff();
    CouplingGains c;
    c.k = g.stiffness > 0.0 ? g.stiffness : body.mass * omega * omega;
    c.b = g.damping >= 0.0 ? g.damping : 2.0 * std::sqrt(c.k * body.mass);
    c.kr = g.angularStiffness > 0.0 ? g.angularStiffness : smallestInertia * omega * omega;
    c.br = g.angularDamping >= 0.0 ? g.angularDamping : 2.0 * std::sqrt(c.kr * smallestInertia);
    // Explicit coupling: stable while h sqrt(k/m) and h b/m stay below 1 (with margin to 2).
    const bool stable = h * std::sqrt(c.k / body.mass) <= 1.0 && h * c.b / body.mass <= 1.0 &&
                        h * std::sqrt(c.kr / smallestInertia) <= 1.0 && h * c.br / smallestInertia <= 1.0;
    if (!stable)
        throw InputError(kSource, 0, "grab coupling too stiff or too damped for the time step (need h*sqrt(k/m) <= 1 and h*b/m <= 1)");
    return c;
}

// The spring-damper between the operator's target and the grabbed body, for this step.
void applyCoupling(double h, OperatorState& op, Bodies& bodies) {
    if (!op.grabbed) return;
    const BodyId id = *op.grabbed;
    RigidBody& body = bodies.rigid[id];
    if (body.motion == MotionType::Kinematic) {
        bodies.kinematicTargets[id] = op.target;
        op.coupling = Coupling{true, id, Vec3::Zero(), Vec3::Zero()};
        return;
    }
    const Pose& pose = bodies.parts[id]->pose();
    const Vec3 targetCentre = op.target.apply(body.centreOfMass);
    const Vec3 targetVelocity = (targetCentre - op.previousTarget.apply(body.centreOfMass)) / h;
    const Eigen::AngleAxisd error = shortestTurn(op.target.rotation * pose.rotation.conjugate());
    const Eigen::AngleAxisd targetTurn = shortestTurn(op.target.rotation * op.previousTarget.rotation.conjugate());
    const Vec3 targetSpin = targetTurn.axis() * (targetTurn.angle() / h);
    const CouplingGains& g = op.gains;
    op.coupling.force = g.k * (targetCentre - bodies.centreOfMass(id)) + g.b * (targetVelocity - body.linearVelocity);
    op.coupling.torque = g.kr * error.angle() * error.axis() + g.br * (targetSpin - body.angularVelocity);
    body.force += op.coupling.force;
    body.torque += op.coupling.torque;
    op.previousTarget = op.target;
}

// Kinematic bodies take the velocity that reaches their target in this step; the rigid motion
// stage moves them there in sub-steps (rigid_motion.hpp). One without a target stands still.
void aimKinematicBodies(double h, Bodies& bodies) {
    for (BodyId id = 0; id < bodies.size(); ++id) {
        RigidBody& body = bodies.rigid[id];
        if (body.motion != MotionType::Kinematic) continue;
        if (!bodies.kinematicTargets[id]) {
            body.linearVelocity.setZero();
            body.angularVelocity.setZero();
            continue;
        }
        const Pose& target = *bodies.kinematicTargets[id];
        const Eigen::AngleAxisd turn = shortestTurn(target.rotation * bodies.parts[id]->pose().rotation.conjugate());
        body.linearVelocity = (target.apply(body.centreOfMass) - bodies.centreOfMass(id)) / h;
        body.angularVelocity = turn.axis() * (turn.angle() / h);
    }
}

}  // namespace

void grab(BodyId id, const GrabSettings& settings, double timeStep, const Bodies& bodies, OperatorState& op) {
    if (id >= bodies.size()) throw InputError(kSource, 0, "grab: no body " + std::to_string(id));
    const RigidBody& body = bodies.rigid[id];
    if (body.motion == MotionType::Static) throw InputError(kSource, 0, "grab: body " + std::to_string(id) + " is static");
    if (!(settings.frequency > 0.0) || !std::isfinite(settings.frequency) || !(settings.stiffness >= 0.0) ||
        !(settings.angularStiffness >= 0.0) || !std::isfinite(settings.damping) || !std::isfinite(settings.angularDamping))
        throw InputError(kSource, 0, "grab: coupling settings must be finite, frequency > 0 and stiffnesses >= 0");
    op.gains = body.motion == MotionType::Dynamic ? couplingGains(body, settings, timeStep) : CouplingGains{};
    op.grabbed = id;
    op.target = op.previousTarget = bodies.parts[id]->pose();
    op.coupling = Coupling{true, id, Vec3::Zero(), Vec3::Zero()};
}

void release(OperatorState& op) {
    op.grabbed.reset();
    op.coupling = Coupling{};
}

void operatorInput(const StepContext& step, OperatorState& op, Bodies& bodies) {
    applyCoupling(step.timeStep, op, bodies);
    aimKinematicBodies(step.timeStep, bodies);
}

}  // namespace flexfit::detail
