// The contact response stage (contact_response.hpp).
#include "contact_response.hpp"

#include "contact_solver.hpp"
#include "core/lanes256.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <numeric>

namespace flexfit::detail {
namespace {

std::atomic<int> mergedResponseScopes{0};  // ScopedMergedResponse

// Whether every contact is one point-shell pair's, a rigid part's against a deformable one (a
// tool pressed into a part: the haptic case; checked contact by contact, a read of two ids each).
// Such a pair's contacts name each mass once (one sample a mass; ContactResponse and
// PointShellCoherent tests), so no mass needs merging: each contact is its mass's push and
// reaction, in order, as the general path would make them.
bool onePointShellPair(std::span<const Contact> contacts, const Bodies& bodies) {
    if (contacts.empty() || mergedResponseScopes.load(std::memory_order_relaxed) != 0) return false;
    const Contact& first = contacts.front();
    if (bodies.parts[first.partA]->deforms() || !bodies.parts[first.partB]->deforms()) return false;
    return std::all_of(contacts.begin(), contacts.end(), [&](const Contact& c) {
        return c.partA == first.partA && c.partB == first.partB && c.massB != kNoMass;
    });
}

// Zones at the contacted faces and each mass's deepest push, in first-contact order (`onePair`:
// onePointShellPair, so each contact is its mass's push).
void collectPushes(std::span<const Contact> contacts, bool onePair, Bodies& bodies, ContactResponse& r) {
    r.pushed.clear();
    r.pushBodies.clear();
    r.pushMasses.clear();
    r.pushDisplacements.clear();
    if (onePair) {
        const BodyId id = contacts.front().partB;
        Part& part = *bodies.parts[id];
        for (const Contact& c : contacts) {
            part.touchFace(c.faceB);
            r.pushBodies.push_back(id);
            r.pushMasses.push_back(c.massB);
            r.pushDisplacements.push_back((-c.depth) * c.normal);  // all of it on B: below's, shareA 0
        }
        return;
    }
    // Pushes the face's masses, or only `mass` when the contact has one (point shell).
    auto pushFace = [&](BodyId id, Index face, Index mass, const Vec3& displacement) {
        Part& part = *bodies.parts[id];
        part.touchFace(face);
        for (Index m : pressedMasses(part.model().mesh.faces[face], mass)) {
            const Index key = bodies.worldMass(id, m);
            if (r.pushed.insert(key)) {
                r.pushBodies.push_back(id);
                r.pushMasses.push_back(m);
                r.pushDisplacements.push_back(displacement);
            } else if (Vec3& deepest = r.pushDisplacements[r.pushed.slotOf(key)]; displacement.squaredNorm() > deepest.squaredNorm()) {
                deepest = displacement;
            }
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

// Each body's run of pushes at once (Part::displaceMasses), in order.
void displacePushedMasses(Bodies& bodies, ContactResponse& r) {
    const std::span<const Index> masses = r.pushMasses;
    const std::span<const Vec3> displacements = r.pushDisplacements;
    for (std::size_t begin = 0, end = 0; begin < masses.size(); begin = end) {
        const BodyId body = r.pushBodies[begin];
        for (end = begin + 1; end < masses.size() && r.pushBodies[end] == body;) ++end;
        detail::displaceMassesUnchecked(*bodies.parts[body], masses.subspan(begin, end - begin), displacements.subspan(begin, end - begin));
    }
}

// What every reaction between one pressing body and one deformable part shares.
struct PairTerms {
    Vec3 bodyCentre, bodyVelocity, bodySpin, partCentre, partVelocity, partSpin;
    double stiffness = 0.0, share = 0.0, damping = 0.0, staticFriction = 0.0, kineticFriction = 0.0;

    PairTerms(const Bodies& bodies, BodyId body, BodyId part, double stiffness_, std::uint32_t pressed, double dampingRatio, double h)
        : bodyCentre(bodies.centreOfMass(body)), bodyVelocity(bodies.rigid[body].linearVelocity),
          bodySpin(bodies.rigid[body].angularVelocity), partCentre(bodies.centreOfMass(part)),
          partVelocity(bodies.rigid[part].linearVelocity), partSpin(bodies.rigid[part].angularVelocity), stiffness(stiffness_) {
        share = bodies.rigid[body].mass / double(pressed);  // of the body's mass, per mass pressed
        damping = std::min(2.0 * dampingRatio * std::sqrt(stiffness * share), share / h);
        staticFriction = combinedFriction(bodies.rigid[body].staticFriction, bodies.rigid[part].staticFriction);
        kineticFriction = combinedFriction(bodies.rigid[body].kineticFriction, bodies.rigid[part].kineticFriction);
    }
    // The body's motion over the part's surface at x, the part taken as moving rigidly: a
    // pushed mass's own velocity is what the restoration gives it, not the surface's resistance.
    Vec3 relativeVelocity(const Vec3& x) const {
        return bodyVelocity + bodySpin.cross(x - bodyCentre) - partVelocity - partSpin.cross(x - partCentre);
    }
};

// Coulomb friction on the body against its sliding: the force that stops it in one step while
// within mu_s times the normal force, mu_k times it otherwise.
Vec3 frictionForce(const PairTerms& t, const Vec3& sliding, double pressing, double h) {
    const double speed = sliding.norm();
    if (!(speed > 0.0)) return Vec3::Zero();
    const double stopping = t.share * speed / h;
    const double magnitude = stopping <= t.staticFriction * pressing ? stopping : t.kineticFriction * pressing;
    return -(magnitude / speed) * sliding;
}

// One reaction: the spring force k_eff (rest - x) of the mass, damped along it by the body's
// approach, never pulling; Coulomb friction against the body's sliding over the surface, which
// the mass feels the opposite of; the body gets the force and its torque.
void applyReaction(const PairTerms& terms, Part& p, Index mass, double h, RigidBody& b) {
    const Vec3& local = p.state().positions[mass];
    const Vec3 displacement = p.pose().rotate(local - p.model().restPositions[mass]);
    const double length = displacement.norm();
    if (!(length > 0.0)) return;
    const Vec3 normal = -displacement / length;  // the way the mass pushes the body
    const Vec3 x = p.pose().apply(local);
    const Vec3 relative = terms.relativeVelocity(x);
    const double normalSpeed = relative.dot(normal);
    const double pressing = std::max(terms.stiffness * length - terms.damping * normalSpeed, 0.0);
    Vec3 force = pressing * normal;
    if (terms.staticFriction > 0.0) {
        const Vec3 friction = frictionForce(terms, relative - normalSpeed * normal, pressing, h);
        if (friction != Vec3::Zero()) p.applyForce(mass, -friction);
        force += friction;
    }
    b.force += force;
    b.torque += (x - terms.bodyCentre).cross(force);
    b.deformableContactForce += force;
}

#if defined(FLEXFIT_LANES256)
// applyReaction for a frictionless pair's reactions, 4 a vector: each lane's force and torque
// by the same operations in the same order (lanes256.hpp: the same bits), then added to the
// body one reaction at a time, in order. Returns how many it did (a multiple of 4).
FLEXFIT_AVX2_LANES std::size_t applyFrictionlessReactions256(const PairTerms& terms, const Part& p,
                                                           std::span<const ContactResponse::Reaction> reactions, RigidBody& b) {
    using namespace lanes;
    const QuaternionLanes q = broadcast(p.pose().rotation);
    const Lanes3 translation = broadcast(p.pose().translation);
    const Lanes3 bodyCentre = broadcast(terms.bodyCentre), bodyVelocity = broadcast(terms.bodyVelocity), bodySpin = broadcast(terms.bodySpin);
    const Lanes3 partCentre = broadcast(terms.partCentre), partVelocity = broadcast(terms.partVelocity), partSpin = broadcast(terms.partSpin);
    const __m256d stiffness = _mm256_set1_pd(terms.stiffness), damping = _mm256_set1_pd(terms.damping), zero = _mm256_setzero_pd();
    const std::size_t n = reactions.size() / 4 * 4;
    // The sums in registers, not through the body's memory (each += waited on the last one's
    // store); the same additions in the same order.
    Vec3 force = b.force, torque = b.torque, pressed = b.deformableContactForce;
    const Vec3Array &positions = p.state().positions, &restPositions = p.model().restPositions;
    for (std::size_t k = 0; k < n; k += 4) {
        const ContactResponse::Reaction* four = &reactions[k];
        const Lanes3 local = gather([&](int j) -> const Vec3& { return positions[four[j].mass]; });
        const Lanes3 rest = gather([&](int j) -> const Vec3& { return restPositions[four[j].mass]; });
        const Lanes3 displacement = rotate(q, sub(local, rest));
        const __m256d length = _mm256_sqrt_pd(dot(displacement, displacement));
        const int acts = _mm256_movemask_pd(_mm256_cmp_pd(length, zero, _CMP_GT_OQ));  // !(length > 0): no reaction
        const Lanes3 normal = divide(negate(displacement), length);
        const Lanes3 x = add(rotate(q, local), translation);
        const Lanes3 arm = sub(x, bodyCentre);
        const Lanes3 relative = sub(sub(add(bodyVelocity, cross(bodySpin, arm)), partVelocity), cross(partSpin, sub(x, partCentre)));
        __m256d pressing = _mm256_sub_pd(_mm256_mul_pd(stiffness, length), _mm256_mul_pd(damping, dot(relative, normal)));
        pressing = _mm256_blendv_pd(pressing, zero, _mm256_cmp_pd(pressing, zero, _CMP_LT_OQ));  // std::max(pressing, 0.0)
        const Lanes3 forceLanes = scale(pressing, normal);
        const Stored3 forces = store(forceLanes), torques = store(cross(arm, forceLanes));
        for (int j = 0; j < 4; ++j) {
            if (!(acts & (1 << j))) continue;
            force += forces[j];
            torque += torques[j];
            pressed += forces[j];
        }
    }
    b.force = force;
    b.torque = torque;
    b.deformableContactForce = pressed;
    return n;
}
#endif

// Each reaction (applyReaction), pair by pair (reactions come grouped by pair).
void applyReactionForces(const StepContext& step, double dampingRatio, Bodies& bodies, ContactResponse& r) {
    for (const ContactResponse::Reaction& reaction : r.reactions) r.reactionCount[reaction.body] = 0;
    for (const ContactResponse::Reaction& reaction : r.reactions) ++r.reactionCount[reaction.body];
    const double h = step.timeStep;
    const std::span<const ContactResponse::Reaction> all = r.reactions;
    for (std::size_t begin = 0, end = 0; begin < all.size(); begin = end) {
        const BodyId body = all[begin].body, partId = all[begin].part;
        for (end = begin + 1; end < all.size() && all[end].body == body && all[end].part == partId;) ++end;
        const PairTerms terms(bodies, body, partId, r.stiffness[partId], r.reactionCount[body], dampingRatio, h);
        Part& p = *bodies.parts[partId];
        RigidBody& b = bodies.rigid[body];
        std::size_t k = begin;
#if defined(FLEXFIT_LANES256)
        if (!(terms.staticFriction > 0.0) && lanesEnabled()) k += applyFrictionlessReactions256(terms, p, all.subspan(begin, end - begin), b);
#endif
        for (; k < end; ++k) applyReaction(terms, p, all[k].mass, h, b);
    }
}

// Which sides of a pair's contacts make reactions: side A (A presses B) when A is dynamic, B
// deforms and the contact solver did not answer the pair; side B the other way round.
struct ReactingSides {
    bool bodyA = false, bodyB = false;
    ReactingSides(const Bodies& bodies, BodyId a, BodyId b)
        : bodyA(reacts(bodies, a, b)), bodyB(reacts(bodies, b, a)) {}
    static bool reacts(const Bodies& bodies, BodyId body, BodyId part) {
        return bodies.dynamic(body) && bodies.parts[part]->deforms() && !solvedByImpulses(bodies, body, part);
    }
};

// Each (body, contacted mass) once, in first-contact order (deterministic; `onePair`: each
// contact is its mass's reaction); then each body feels its masses' reactions, for the next step.
void applyDeformableReactions(const StepContext& step, double dampingRatio, std::span<const Contact> contacts, bool onePair,
                              Bodies& bodies, ContactResponse& r) {
    r.reacting.clear();
    for (const ContactResponse::Reaction& reaction : r.reactions) bodies.rigid[reaction.body].deformableContactForce.setZero();  // last step's
    r.reactions.clear();
    // Contacts come grouped by pair, so a mass pressed by two bodies counts once for each.
    auto react = [&](BodyId body, BodyId part, Index face, Index mass) {
        for (Index m : pressedMasses(bodies.parts[part]->model().mesh.faces[face], mass)) {
            const Index key = bodies.worldMass(part, m);
            if (r.reacting.insert(key) || r.reactionOwner[key] != body) {
                r.reactionOwner[key] = body;
                r.reactions.push_back({body, part, m});
            }
        }
    };
    if (onePair) {
        const BodyId body = contacts.front().partA, part = contacts.front().partB;
        if (ReactingSides(bodies, body, part).bodyA)
            for (const Contact& c : contacts) r.reactions.push_back({body, part, c.massB});
        applyReactionForces(step, dampingRatio, bodies, r);
        return;
    }
    std::optional<ReactingSides> sides;
    BodyId a = 0, b = 0;
    for (const Contact& c : contacts) {
        if (!sides || c.partA != a || c.partB != b) {  // the pair's sides, once per run of its contacts
            a = c.partA;
            b = c.partB;
            sides.emplace(bodies, a, b);
        }
        if (sides->bodyA) react(a, b, c.faceB, c.massB);
        if (sides->bodyB) react(b, a, c.faceA, kNoMass);
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
        case RestorationMethod::Constraint:
            return springs + constraintFractionFor(r, timeStep) * meanMass / (timeStep * timeStep);
        case RestorationMethod::None: break;
    }
    return springs;
}

ScopedMergedResponse::ScopedMergedResponse() { mergedResponseScopes.fetch_add(1, std::memory_order_relaxed); }
ScopedMergedResponse::~ScopedMergedResponse() { mergedResponseScopes.fetch_sub(1, std::memory_order_relaxed); }

void sizeResponseScratch(const Bodies& bodies, ContactResponse& r) {
    const std::size_t masses = bodies.massCount();
    r.pushed.growTo(masses);
    r.pushed.reserve(masses);
    r.reacting.growTo(masses);
    r.reacting.reserve(masses);
    r.reactionOwner.resize(masses, 0u);
    r.reactionCount.resize(bodies.size(), 0u);
    // Each list holds a mass at most once (per body for the reactions): no step reallocates.
    r.pushBodies.reserve(masses);
    r.pushMasses.reserve(masses);
    r.pushDisplacements.reserve(masses);
    r.reactions.reserve(masses);
}

namespace {

void pushAndDisplace(std::span<const Contact> contacts, bool onePair, Bodies& bodies, ContactResponse& response) {
    sizeResponseScratch(bodies, response);  // once a response (a no-op once sized)
    collectPushes(contacts, onePair, bodies, response);
    displacePushedMasses(bodies, response);
}

}  // namespace

void pushDeformableMasses(std::span<const Contact> contacts, Bodies& bodies, ContactResponse& response) {
    pushAndDisplace(contacts, onePointShellPair(contacts, bodies), bodies, response);
}

void respondToContacts(const StepContext& step, double dampingRatio, std::span<const Contact> contacts, Bodies& bodies,
                       ContactResponse& response) {
    const bool onePair = onePointShellPair(contacts, bodies);  // once: pushing changes no part's mode
    pushAndDisplace(contacts, onePair, bodies, response);
    applyDeformableReactions(step, dampingRatio, contacts, onePair, bodies, response);
}

}  // namespace flexfit::detail
