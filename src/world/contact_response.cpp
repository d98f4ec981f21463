// The contact response stage (contact_response.hpp).
#include "contact_response.hpp"

#include <algorithm>
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

// Each (body, contacted mass) once, in first-contact order (deterministic); then each body
// feels k_eff (rest - x) of its masses, for the next step.
void applyDeformableReactions(std::span<const Contact> contacts, Bodies& bodies, ContactResponse& r) {
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
    for (const ContactResponse::Reaction& reaction : r.reactions) {
        const Part& p = *bodies.parts[reaction.part];
        const Vec3 displacement = p.pose().rotate(p.state().positions[reaction.mass] - p.model().restPositions[reaction.mass]);
        bodies.rigid[reaction.body].force -= r.stiffness[reaction.part] * displacement;
    }
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

void respondToContacts(std::span<const Contact> contacts, Bodies& bodies, ContactResponse& response) {
    collectPushes(contacts, bodies, response);
    displacePushedMasses(bodies, response);
    applyDeformableReactions(contacts, bodies, response);
}

double projectRigidContacts(BodyId id, std::span<const Contact> contacts, Bodies& bodies, ContactResponse& r) {
    // This body's contacts with parts that do not deform: direction out of them, depth.
    r.projections.clear();
    for (const Contact& c : contacts) {
        const BodyId other = c.partA == id ? c.partB : c.partA;
        if (bodies.parts[other]->deforms()) continue;
        r.projections.emplace_back(c.partA == id ? c.normal : Vec3(-c.normal), c.depth);
    }
    if (r.projections.empty()) return -1.0;
    // Gauss-Seidel over the contacts: each takes what the correction so far leaves of its depth
    // along its normal. Symmetric contacts (a ball on a ring) cancel sideways and add up along
    // the common direction, instead of pushing the body from side to side.
    Vec3 correction = Vec3::Zero();
    for (int pass = 0; pass < 4; ++pass)
        for (const auto& [out, depth] : r.projections) {
            const double remaining = depth - correction.dot(out);
            if (remaining > 0.0) correction += remaining * out;
        }
    bodies.parts[id]->translate(correction);
    RigidBody& body = bodies.rigid[id];
    for (const auto& [out, depth] : r.projections) {
        const double into = body.linearVelocity.dot(out);
        if (into < 0.0) body.linearVelocity -= into * out;  // inelastic
    }
    return correction.norm();
}

}  // namespace flexfit::detail
