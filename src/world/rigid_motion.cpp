// The rigid motion stage (rigid_motion.hpp).
#include "rigid_motion.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>

namespace flexfit::detail {
namespace {

// Baumgarte rate of the solver's first pass: the share of a depth (beyond the linear slop)
// taken out per sub-step, and the linear slop as a share of the contact slop.
constexpr double kSeparationShare = 0.5;
constexpr double kLinearSlopShare = 0.25;
// Halvings of a sub-step's move when it would go too deep: the body stops within 1/64 of it.
constexpr int kBisections = 6;
// Pieces of one sub-step's move beyond which a body is taken to have diverged.
constexpr double kMaxPieces = 64.0;
// Passes over the bodies whose move was cut (settleAll).
constexpr int kSettlePasses = 8;

// Velocity first (semi-implicit Euler): the loads of the last step and gravity, then the
// loads are consumed. Returns the speed the loads gave in the step.
double integrateVelocity(const StepContext& step, const Part& part, RigidBody& body) {
    const double h = step.timeStep;
    const double loadSpeed = h * (step.gravity + body.inverseMass * body.force).norm();
    const Eigen::Matrix3d r = part.pose().rotation.toRotationMatrix();
    const Eigen::Matrix3d inverseInertia = r * body.inverseInertia * r.transpose();
    const Eigen::Matrix3d inertia = inverseInertia.inverse();
    body.linearVelocity += h * (step.gravity + body.inverseMass * body.force);
    body.angularVelocity += h * (inverseInertia * (body.torque - body.angularVelocity.cross(inertia * body.angularVelocity)));
    body.force.setZero();
    body.torque.setZero();
    return loadSpeed;
}

// The pose reached from `start` moving along the body's velocities for dt: its centre of mass
// in a line, its rotation about it.
Pose advancedPose(const Pose& start, double dt, const RigidBody& body) {
    const Vec3 com = start.apply(body.centreOfMass) + dt * body.linearVelocity;
    Pose pose = start;
    const double speed = body.angularVelocity.norm();
    if (speed > 0.0)
        pose.rotation = (Eigen::Quaterniond(Eigen::AngleAxisd(speed * dt, body.angularVelocity / speed)) * pose.rotation).normalized();
    pose.translation = com - pose.rotation * body.centreOfMass;
    return pose;
}

double travelOver(double h, const RigidBody& body) {
    return h * (body.linearVelocity.norm() + body.angularVelocity.norm() * body.boundingRadius);
}

// Kinematic bodies with a target this step, then dynamic ones, in id order.
void collectMovingBodies(const Bodies& bodies, RigidMotionScratch& s) {
    s.moving.clear();
    for (BodyId id = 0; id < bodies.size(); ++id)
        if (bodies.rigid[id].motion == MotionType::Kinematic && bodies.kinematicTargets[id]) s.moving.push_back(id);
    for (BodyId id = 0; id < bodies.size(); ++id)
        if (bodies.dynamic(id)) s.moving.push_back(id);
}

// A kinematic body is stopped by static and kinematic rigid parts; a dynamic one by the parts
// whose contacts with it the solver owns (contact_solver.hpp), so that a body held back is
// also one whose velocity the contact removes. Parts that deform never stop a body: they
// yield (contact_response).
bool stops(const Bodies& bodies, BodyId mover, BodyId other) {
    if (bodies.parts[other]->deforms()) return false;
    if (bodies.dynamic(mover)) return solvedByImpulses(bodies, mover, other);
    return !bodies.dynamic(other);
}

BodyId partnerOf(BodyId id, const Contact& c) { return c.partA == id ? c.partB : c.partA; }

// The deepest each pair may get in this sub-step: the contact slop, or the pair's depth at the
// sub-step's start when it was deeper (a pair pushed in by a third body only gets shallower).
double allowedDepth(BodyId id, BodyId other, double slop, const RigidMotionScratch& s) {
    for (std::size_t k = s.startOffset[id]; k < s.startOffset[id] + s.startCount[id]; ++k)
        if (s.startDepths[k].first == other) return std::max(slop, s.startDepths[k].second);
    return slop;
}

bool tooDeep(BodyId id, std::span<const Contact> contacts, double slop, const Bodies& bodies, const RigidMotionScratch& s) {
    for (const Contact& c : contacts) {
        const BodyId other = partnerOf(id, c);
        if (stops(bodies, id, other) && c.depth > allowedDepth(id, other, slop, s)) return true;
    }
    return false;
}

// Records each stopping pair's deepest contact at the sub-step's start.
void recordStartDepths(BodyId id, std::span<const Contact> contacts, const Bodies& bodies, RigidMotionScratch& s) {
    s.startOffset[id] = s.startDepths.size();
    for (const Contact& c : contacts) {
        const BodyId other = partnerOf(id, c);
        if (!stops(bodies, id, other)) continue;
        if (s.startDepths.size() > s.startOffset[id] && s.startDepths.back().first == other)  // contacts come by pair
            s.startDepths.back().second = std::max(s.startDepths.back().second, c.depth);
        else
            s.startDepths.emplace_back(other, c.depth);
    }
    s.startCount[id] = s.startDepths.size() - s.startOffset[id];
}

// The body's contacts with rigid parts at its current pose (its cached ones when nothing moved
// since they were found).
std::span<const Contact> rigidContactsOf(BodyId id, Bodies& bodies, CollisionWorld& collision, RigidMotionScratch& s,
                                         StepProfiler& profiler) {
    if (s.cachedBody == id) return s.cached;
    const Stage outer = profiler.running();
    profiler.enter(Stage::NarrowPhase);
    const std::vector<Contact>& contacts = collision.contactsOf(id, true);
    clearRefittedChanges(collision, bodies);
    profiler.enter(outer);
    ++s.queries;
    return contacts;
}

// The speed the loads and gravity give a body in a step: its own when it is dynamic (every
// dynamic body moves), gravity's for the others.
double loadSpeedOf(BodyId id, const Bodies& bodies, const RigidMotionScratch& s) {
    return bodies.dynamic(id) ? s.loadSpeed[id] : s.gravitySpeed;
}

// 1. The dynamic bodies' rigid contacts into the solver, each pair once, with their
// restitution threshold; every moving body's stopping pairs' depths.
void gatherContacts(Bodies& bodies, CollisionWorld& collision, RigidMotionScratch& s, StepProfiler& profiler) {
    keepImpulses(s.solver);
    s.solver.contacts.clear();
    updateInverseInertia(s.moving, bodies, s.solver);
    s.startDepths.clear();  // recordStartDepths sets each mover's offset and count
    for (BodyId id : s.moving) {
        const std::span<const Contact> contacts = rigidContactsOf(id, bodies, collision, s, profiler);
        recordStartDepths(id, contacts, bodies, s);
        if (!bodies.dynamic(id)) continue;
        // A pair of dynamic bodies is added by the lower id's query, when that query saw it
        // (queries skip deforming partners).
        s.unseen.clear();
        const bool seenByLower = !bodies.parts[id]->deforms();
        for (const Contact& c : contacts) {
            const BodyId other = partnerOf(id, c);
            if (other > id || !bodies.dynamic(other) || !seenByLower) s.unseen.push_back(c);
        }
        const std::size_t first = s.solver.contacts.size();
        addContacts(s.unseen, bodies, s.solver);
        // A point bounces only when it approaches faster than twice what the loads give in a
        // step: a resting contact under any load does not.
        for (std::size_t k = first; k < s.solver.contacts.size(); ++k) {
            SolverContact& c = s.solver.contacts[k];
            c.bounceThreshold = 2.0 * std::max(loadSpeedOf(c.a, bodies, s), loadSpeedOf(c.b, bodies, s)) + 1e-9;
        }
    }
}

// The body's last query stays usable while nothing moves; not for a deforming body, whose
// shape changes between steps.
void keepCache(BodyId id, const Bodies& bodies, RigidMotionScratch& s) {
    if (bodies.parts[id]->deforms()) return;
    s.cachedBody = id;
    s.cacheEpoch = bodies.poseEpoch;
}

// 3. Every moving body first goes to the end of its move; then each, in turn, checks its place
// against the others' (moved or already cut back) and, when a stopping pair is deeper than it
// may be, cuts its own move back: the move is tried in pieces no longer than the travel bound
// (more than one only when the sub-steps could not follow the body), then bisected in the piece
// that goes too deep. Bodies moving together therefore do not hold each other back. Returns
// false when the move was cut short.
bool settleMove(BodyId id, double dt, double slop, double bound, const StepContext& step, Bodies& bodies,
                CollisionWorld& collision, RigidMotionScratch& s, StepProfiler& profiler) {
    Part& part = *bodies.parts[id];
    const RigidBody& body = bodies.rigid[id];
    const double pieces = std::ceil(travelOver(dt, body) / bound);
    if (!(pieces <= kMaxPieces)) {  // NaN too
        const double travel = travelOver(step.timeStep, body);
        const std::string cause = "; likely cause: a force, speed or kinematic jump beyond what max_substeps sub-steps can follow";
        if (!std::isfinite(travel))  // a speed overflowed (an angular velocity of 1e300): no distance to quote
            throw DivergenceError(id, step.time, "its velocity or angular velocity is no longer finite (speed " +
                                                     std::to_string(body.linearVelocity.norm()) + ", angular speed " +
                                                     std::to_string(body.angularVelocity.norm()) + " rad/s)" + cause);
        // The bound is the world's, from the thinnest body: a thin body elsewhere can be the cause.
        std::ostringstream text;
        text << "moves " << travel << " units in one step, more than " << int(kMaxPieces) << " travel bounds of " << bound
             << " per sub-step (the max travel fraction of the thinnest body's thickness, " << bodies.minimumThickness();
        if (const std::optional<BodyId> thin = bodies.thinnestBody()) text << ": body " << *thin;
        text << ")" << cause << ", or a body thinner than the others need";
        throw DivergenceError(id, step.time, text.str());
    }
    const Pose start = s.subStart[id];
    s.cachedBody.reset();
    auto fits = [&](double fraction) {
        detail::setPoseUnchecked(part, advancedPose(start, fraction * dt, body));
        const std::span<const Contact> contacts = rigidContactsOf(id, bodies, collision, s, profiler);
        if (tooDeep(id, contacts, slop, bodies, s)) return false;
        s.cached.assign(contacts.begin(), contacts.end());  // the contacts at the pose reached
        return true;
    };
    const int count = std::max(1, int(pieces));
    double reached = 0.0, blocked = 1.0;
    for (int piece = 1; piece <= count; ++piece) {
        const double fraction = double(piece) / count;
        if (!fits(fraction)) {
            blocked = fraction;
            break;
        }
        reached = fraction;
    }
    if (reached == 1.0) {
        keepCache(id, bodies, s);
        return true;
    }
    for (int i = 0; i < kBisections; ++i) {
        const double middle = 0.5 * (reached + blocked);
        (fits(middle) ? reached : blocked) = middle;
    }
    detail::setPoseUnchecked(part, reached > 0.0 ? advancedPose(start, reached * dt, body) : start);
    if (reached > 0.0) keepCache(id, bodies, s);
    return false;
}

// 3 for every mover, then again for those cut short while a pass changes a pose: a body is
// checked against the others' moves as they stand, so a box under a falling one is held back
// by that one's whole move until it is cut back in turn. Without the passes, a stack stepped
// in steps longer than its gaps take to close (gravity's travel in a step beyond the slop)
// never closed them: each box stopped above the one below, the contacts stayed apart and the
// boxes' velocities grew by g h a step while they stood still. Returns the bodies cut short
// (the others reached their whole move).
const std::vector<BodyId>& settleAll(double dt, double slop, double bound, const StepContext& step, Bodies& bodies,
                                     CollisionWorld& collision, RigidMotionScratch& s, StepProfiler& profiler) {
    s.cut.assign(s.moving.begin(), s.moving.end());
    for (int pass = 0; pass < kSettlePasses && !s.cut.empty(); ++pass) {
        bool changed = false;
        std::size_t kept = 0;
        for (BodyId id : s.cut) {
            const Pose before = bodies.parts[id]->pose();
            const bool reached = settleMove(id, dt, slop, bound, step, bodies, collision, s, profiler);
            changed = changed || !samePose(before, bodies.parts[id]->pose());
            if (!reached) s.cut[kept++] = id;
        }
        s.cut.resize(kept);
        if (pass > 0 && !changed) break;  // the first pass is every mover's; the rest repeat while poses change
    }
    return s.cut;
}

// 5. A kinematic body's pushes on the deformable parts it meets mid-step.
void pressDeformableParts(BodyId id, Bodies& bodies, CollisionWorld& collision, ContactResponse& response, StepProfiler& profiler) {
    const Stage outer = profiler.running();
    profiler.enter(Stage::NarrowPhase);
    const std::vector<Contact>& contacts = collision.contactsOf(id, false);
    clearRefittedChanges(collision, bodies);
    profiler.enter(Stage::ContactResponse);
    pushDeformableMasses(contacts, bodies, response);
    profiler.enter(outer);
}

int substepCount(double h, double bound, const WorldSettings& settings, const Bodies& bodies, const RigidMotionScratch& s) {
    double travel = 0.0;
    for (BodyId id : s.moving) travel = std::max(travel, travelOver(h, bodies.rigid[id]));
    const double count = std::ceil(travel / bound);
    if (!(count >= 1.0)) return 1;  // NaN too (settleMove reports a diverged body)
    return int(std::min(count, double(settings.maxSubsteps)));
}

}  // namespace

const CollisionWorld::KnownContacts* knownContacts(RigidMotionScratch& s, const Bodies& bodies) {
    if (!s.cachedBody || s.cacheEpoch != bodies.poseEpoch) return nullptr;
    s.known = {*s.cachedBody, s.cached};
    return &s.known;
}

void moveRigidBodies(const StepContext& step, const WorldSettings& settings, Bodies& bodies, CollisionWorld& collision,
                     ContactResponse& response, RigidMotionScratch& s, StepProfiler& profiler, Profile& profile) {
    const double h = step.timeStep;
    collectMovingBodies(bodies, s);
    if (s.moving.empty()) return;
    s.gravitySpeed = h * step.gravity.norm();
    for (std::vector<std::size_t>* v : {&s.startOffset, &s.startCount}) v->resize(bodies.size());
    s.loadSpeed.resize(bodies.size());
    s.stepStart.resize(bodies.size());
    s.subStart.resize(bodies.size());
    s.stopped.resize(bodies.size());
    for (BodyId id : s.moving) {
        if (bodies.dynamic(id)) s.loadSpeed[id] = integrateVelocity(step, *bodies.parts[id], bodies.rigid[id]);
        s.stepStart[id] = bodies.parts[id]->pose();
        s.stopped[id] = 0;
    }
    const double thinnest = bodies.minimumThickness();
    const double slop = settings.contactSlop * thinnest;
    const double bound = settings.maxTravelFraction * thinnest;
    const int substeps = substepCount(h, bound, settings, bodies, s);
    const double dt = h / substeps;
    // Depth is taken out at up to one slop per step: conservative advancement keeps it below
    // the slop, so the separation only corrects drift.
    const Separation separation{kSeparationShare / dt, kLinearSlopShare * slop, slop / h};
    // The last mover's contacts stay valid into this step unless something moved it or a part
    // it may touch since: a body at rest costs one query per step.
    if (s.cacheEpoch != bodies.poseEpoch) s.cachedBody.reset();
    for (int sub = 0; sub < substeps; ++sub) {
        gatherContacts(bodies, collision, s, profiler);
        profiler.enter(Stage::ContactSolver);
        warmStart(bodies, s.solver);
        solveVelocities(settings.contactIterations, separation, bodies, s.solver);
        profiler.enter(Stage::RigidMotion);
        for (BodyId id : s.moving) {
            s.subStart[id] = bodies.parts[id]->pose();
            detail::setPoseUnchecked(*bodies.parts[id], advancedPose(s.subStart[id], dt, bodies.rigid[id]));
        }
        for (BodyId id : settleAll(dt, slop, bound, step, bodies, collision, s, profiler)) {
            s.stopped[id] = 1;
            ++profile.cutMoves;
        }
        profiler.enter(Stage::ContactSolver);
        refreshLeverArms(bodies, s.solver);
        solveVelocities(settings.contactIterations, Separation{}, bodies, s.solver);
        applyRestitution(settings.contactIterations, bodies, s.solver);
        profiler.enter(Stage::RigidMotion);
        if (sub + 1 < substeps)
            for (BodyId id : s.moving)
                if (bodies.rigid[id].motion == MotionType::Kinematic) pressDeformableParts(id, bodies, collision, response, profiler);
    }
    // Kinematic bodies end exactly at their targets unless a part stopped them; their velocity
    // is the move they made.
    for (BodyId id : s.moving) {
        if (bodies.rigid[id].motion != MotionType::Kinematic) continue;
        if (!s.stopped[id]) {
            const Pose& target = *bodies.kinematicTargets[id];
            const Pose& now = bodies.parts[id]->pose();
            if (!samePose(target, now)) s.cachedBody.reset();
            detail::setPoseUnchecked(*bodies.parts[id], target);
        }
        bodies.kinematicTargets[id].reset();
        RigidBody& body = bodies.rigid[id];
        const Pose& start = s.stepStart[id];
        const Pose& end = bodies.parts[id]->pose();
        const Eigen::AngleAxisd turn = shortestTurn(end.rotation * start.rotation.conjugate());
        body.linearVelocity = (end.apply(body.centreOfMass) - start.apply(body.centreOfMass)) / h;
        body.angularVelocity = turn.axis() * (turn.angle() / h);
    }
    profile.substeps += std::uint64_t(substeps);
    profile.rigidQueries += s.queries;
    s.queries = 0;
}

}  // namespace flexfit::detail
