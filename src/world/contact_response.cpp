// The contact response stage (contact_response.hpp).
#include "contact_response.hpp"

#include "contact_solver.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace flexfit::detail {
namespace {


// Zones at the contacted faces and each mass's deepest push, in first-contact order.
void collectPushes(std::span<const Contact> contacts, Bodies& bodies, ContactResponse& r) {
    r.pushed.growTo(bodies.massCount());
    r.pushed.clear();
    r.pushes.clear();
    // Pushes the face's masses, or only `mass` when the contact has one (point shell).
    auto pushFace = [&](BodyId id, Index face, Index mass, const Vec3& displacement) {
        Part& part = *bodies.parts[id];
        part.touchFace(face);
        for (Index m : pressedMasses(part.model().mesh.faces[face], mass)) {
            const Index key = bodies.worldMass(id, m);
            if (r.pushed.insert(key))
                r.pushes.push_back({id, m, displacement});
            else if (Vec3& deepest = r.pushes[r.pushed.slotOf(key)].displacement; displacement.squaredNorm() > deepest.squaredNorm())
                deepest = displacement;
        }
    };
    for (const Contact& c : contacts) {
        const bool da = bodies.parts[c.partA]->deforms(), db = bodies.parts[c.partB]->deforms();
        if (!da && !db) continue;
        const double ka = r.stiffness[c.partA], kb = r.stiffness[c.partB];
        const double shareA = da && db ? (ka + kb > 0 ? kb / (ka + kb) : 0.5) : (da ? 1.0 : 0.0);
        if (shareA > 0.0) pushFace(c.partA, c.faceA, kNoMass, (c.depth * shareA) * c.normal);
        if (shareA < 1.0) pushFace(c.partB, c.faceB, c.massB, (-c.depth * (1.0 - shareA)) * c.normal);
    }
}

void displacePushedMasses(Bodies& bodies, const ContactResponse& r) {
    for (const ContactResponse::Push& p : r.pushes) bodies.parts[p.body]->displaceMass(p.mass, p.displacement);
}

// Velocity of the material point at world position x of a body: its rigid motion, plus the
// mass's own velocity when the point is a moving mass of a deforming part.
Vec3 pointVelocity(const Bodies& bodies, BodyId id, const Vec3& x) {
    const RigidBody& b = bodies.rigid[id];
    return b.linearVelocity + b.angularVelocity.cross(x - bodies.centreOfMass(id));
}

// Each reaction: the spring force k_eff (rest - x) of the mass, damped along it by the body's
// approach, never pulling; Coulomb friction against the body's sliding over the mass, which
// feels the opposite; the body gets the force and its torque.
void applyReactionForces(const StepContext& step, double dampingRatio, Bodies& bodies, ContactResponse& r) {
    for (RigidBody& b : bodies.rigid) b.deformableContactForce.setZero();
    r.reactionCount.assign(bodies.size(), 0u);
    for (const ContactResponse::Reaction& reaction : r.reactions) ++r.reactionCount[reaction.body];
    for (const ContactResponse::Reaction& reaction : r.reactions) {
        Part& p = *bodies.parts[reaction.part];
        const Vec3 displacement = p.pose().rotate(p.state().positions[reaction.mass] - p.model().restPositions[reaction.mass]);
        const double length = displacement.norm();
        if (!(length > 0.0)) continue;
        RigidBody& body = bodies.rigid[reaction.body];
        const double k = r.stiffness[reaction.part];
        const double share = body.mass / double(r.reactionCount[reaction.body]);  // of the body's mass, per mass pressed
        const double damping = std::min(2.0 * dampingRatio * std::sqrt(k * share), share / step.timeStep);
        const Vec3 normal = -displacement / length;  // the way the mass pushes the body
        const Vec3 x = p.worldPosition(reaction.mass);
        // The body's motion over the part's surface, taken as it moves rigidly: a pushed mass's
        // own velocity is what the restoration gives it, not the surface's resistance.
        const Vec3 relative = pointVelocity(bodies, reaction.body, x) - pointVelocity(bodies, reaction.part, x);
        const double normalSpeed = relative.dot(normal);
        const double pressing = std::max(k * length - damping * normalSpeed, 0.0);
        const Vec3 sliding = relative - normalSpeed * normal;
        const double slidingSpeed = sliding.norm();
        Vec3 friction = Vec3::Zero();
        if (slidingSpeed > 0.0) {
            const RigidBody& other = bodies.rigid[reaction.part];
            const double stopping = share * slidingSpeed / step.timeStep;  // stops the sliding in one step
            const double limit = combinedFriction(body.staticFriction, other.staticFriction) * pressing;
            const double magnitude = stopping <= limit ? stopping : combinedFriction(body.kineticFriction, other.kineticFriction) * pressing;
            friction = -(magnitude / slidingSpeed) * sliding;
            if (magnitude > 0.0) p.applyForce(reaction.mass, -friction);
        }
        const Vec3 force = pressing * normal + friction;
        body.force += force;
        body.torque += (x - bodies.centreOfMass(reaction.body)).cross(force);
        body.deformableContactForce += force;
    }
}

// Each (body, contacted mass) once, in first-contact order (deterministic); then each body
// feels its masses' reactions, for the next step.
void applyDeformableReactions(const StepContext& step, double dampingRatio, std::span<const Contact> contacts, Bodies& bodies,
                              ContactResponse& r) {
    r.reacting.growTo(bodies.massCount());
    r.reactionOwner.resize(bodies.massCount(), 0u);
    r.reacting.clear();
    r.reactions.clear();
    for (const Contact& c : contacts)
        for (const auto& [body, part, face, mass] :
             {std::tuple{c.partA, c.partB, c.faceB, c.massB}, std::tuple{c.partB, c.partA, c.faceA, kNoMass}}) {
            if (bodies.rigid[body].motion != MotionType::Dynamic || !bodies.parts[part]->deforms()) continue;
            // Contacts come grouped by pair, so a mass pressed by two bodies counts once for each.
            for (Index m : pressedMasses(bodies.parts[part]->model().mesh.faces[face], mass)) {
                const Index key = bodies.worldMass(part, m);
                if (r.reacting.insert(key) || r.reactionOwner[key] != body) {
                    r.reactionOwner[key] = body;
                    r.reactions.push_back({body, part, m});
                }
            }
        }
    applyReactionForces(step, dampingRatio, bodies, r);
}

}  // namespace

double effectiveContactStiffness(const Part& part, double timeStep) {
    const PartModel& m = part.model();
    const double springs = m.springCount() ? std::accumulate(m.stiffness.begin(), m.stiffness.end(), 0.0) / double(m.springCount()) : 0.0;
    const double meanMass = std::accumulate(m.mass.begin(), m.mass.end(), 0.0) / double(m.massCount());
    const RestorationSettings& r = part.settings().simulation.restoration;
    switch (r.method) {
        case RestorationMethod::AnchorSprings: return springs + r.anchorStiffness;
        case RestorationMethod::Constraint: return springs + r.constraintFraction * meanMass / (timeStep * timeStep);
        case RestorationMethod::None: break;
    }
    return springs;
}

void pushDeformableMasses(std::span<const Contact> contacts, Bodies& bodies, ContactResponse& response) {
    collectPushes(contacts, bodies, response);
    displacePushedMasses(bodies, response);
}

void respondToContacts(const StepContext& step, double dampingRatio, std::span<const Contact> contacts, Bodies& bodies,
                       ContactResponse& response) {
    pushDeformableMasses(contacts, bodies, response);
    applyDeformableReactions(step, dampingRatio, contacts, bodies, response);
}

}  // namespace flexfit::detail
