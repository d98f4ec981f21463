// The rigid motion stage (rigid_motion.hpp).
#include "rigid_motion.hpp"

#include <algorithm>
#include <cmath>
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
        if (bodies.rigid[id].motion == MotionType::Dynamic) s.moving.push_back(id);
}

// A kinematic body is stopped by static and kinematic rigid parts; a dynamic one by every
// rigid part. Parts that deform never stop a body: they yield (contact_response).
bool stops(const Bodies& bodies, BodyId mover, BodyId other) {
    if (bodies.parts[other]->deforms()) return false;
    return bodies.rigid[mover].motion == MotionType::Dynamic || bodies.rigid[other].motion != MotionType::Dynamic;
}

double deepestStop(BodyId id, std::span<const Contact> contacts, const Bodies& bodies) {
    double deepest = 0.0;
    for (const Contact& c : contacts)
        if (stops(bodies, id, c.partA == id ? c.partB : c.partA)) deepest = std::max(deepest, c.depth);
    return deepest;
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

// 1. The dynamic bodies' rigid contacts into the solver, each pair once; every moving body's
// deepest stopping contact.
void gatherContacts(Bodies& bodies, CollisionWorld& collision, RigidMotionScratch& s, StepProfiler& profiler) {
    s.solver.contacts.clear();
    updateInverseInertia(bodies, s.solver);
    s.startDepth.assign(bodies.size(), 0.0);
    for (BodyId id : s.moving) {
        const std::span<const Contact> contacts = rigidContactsOf(id, bodies, collision, s, profiler);
        s.startDepth[id] = deepestStop(id, contacts, bodies);
        if (bodies.rigid[id].motion != MotionType::Dynamic) continue;
        // A pair of dynamic bodies is added by the lower id's query.
        s.unseen.clear();
        for (const Contact& c : contacts) {
            const BodyId other = c.partA == id ? c.partB : c.partA;
            if (other > id || bodies.rigid[other].motion != MotionType::Dynamic) s.unseen.push_back(c);
        }
        addContacts(s.unseen, bodies, s.solver);
    }
}

// The body's last query stays usable while nothing moves; not for a deforming body, whose
// shape changes between steps.
void keepCache(BodyId id, const Bodies& bodies, RigidMotionScratch& s) {
    if (bodies.parts[id]->deforms()) return;
    s.cachedBody = id;
    s.cacheEpoch = bodies.poseEpoch;
}

// 3. Moves the body along its velocities for dt, or as far as it goes without getting deeper
// than `allowed` into a part that stops it. The move is tried in pieces no longer than the
// travel bound (more than one only when max_substeps capped the sub-steps), then bisected in
// the piece that goes too deep. Returns false when the move was cut short.
bool advanceConservatively(BodyId id, double dt, double allowed, double bound, const StepContext& step, Bodies& bodies,
                           CollisionWorld& collision, RigidMotionScratch& s, StepProfiler& profiler) {
    Part& part = *bodies.parts[id];
    const RigidBody& body = bodies.rigid[id];
    const double pieces = std::ceil(travelOver(dt, body) / bound);
    if (!(pieces <= kMaxPieces))  // NaN too
        throw DivergenceError(id, step.time,
                              "moves " + std::to_string(travelOver(step.timeStep, body)) + " units in one step, more than max_substeps x " +
                                  std::to_string(kMaxPieces) + " travel bounds of " + std::to_string(bound) +
                                  "; likely cause: a force or speed beyond what the world can follow (raise max_substeps or lower the time step)");
    const Pose start = part.pose();
    s.cachedBody.reset();
    auto fits = [&](double fraction) {
        part.setPose(advancedPose(start, fraction * dt, body));
        const std::span<const Contact> contacts = rigidContactsOf(id, bodies, collision, s, profiler);
        if (deepestStop(id, contacts, bodies) > allowed) return false;
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
    part.setPose(reached > 0.0 ? advancedPose(start, reached * dt, body) : start);
    if (reached > 0.0) keepCache(id, bodies, s);
    return false;
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

int substepCount(double h, const WorldSettings& settings, const Bodies& bodies, const RigidMotionScratch& s) {
    const double bound = settings.maxTravelFraction * bodies.minimumThickness();
    double travel = 0.0;
    for (BodyId id : s.moving) travel = std::max(travel, travelOver(h, bodies.rigid[id]));
    return int(std::clamp(std::ceil(travel / bound), 1.0, double(settings.maxSubsteps)));  // NaN: 1
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
    for (BodyId id : s.moving)
        if (bodies.rigid[id].motion == MotionType::Dynamic) integrateVelocity(step, *bodies.parts[id], bodies.rigid[id]);
    s.stepStart.resize(bodies.size());
    for (BodyId id : s.moving) s.stepStart[id] = bodies.parts[id]->pose();
    const int substeps = substepCount(h, settings, bodies, s);
    const double dt = h / substeps;
    const double slop = settings.contactSlop * bodies.minimumThickness();
    const double bound = settings.maxTravelFraction * bodies.minimumThickness();
    // Depth is taken out at up to one slop per step: conservative advancement keeps it below
    // the slop, so the separation only corrects drift.
    const Separation separation{kSeparationShare / dt, kLinearSlopShare * slop, slop / h};
    s.stopped.assign(bodies.size(), 0);
    // The last mover's contacts stay valid into this step unless something moved it or a part
    // it may touch since: a body at rest costs one query per step.
    if (s.cacheEpoch != bodies.poseEpoch) s.cachedBody.reset();
    for (int sub = 0; sub < substeps; ++sub) {
        gatherContacts(bodies, collision, s, profiler);
        profiler.enter(Stage::ContactSolver);
        solveVelocities(settings.contactIterations, separation, bodies, s.solver);
        profiler.enter(Stage::RigidMotion);
        for (BodyId id : s.moving) {
            const bool reached = advanceConservatively(id, dt, std::max(slop, s.startDepth[id]), bound, step, bodies, collision, s, profiler);
            if (!reached) {
                s.stopped[id] = 1;
                ++profile.cutMoves;
            }
        }
        profiler.enter(Stage::ContactSolver);
        refreshLeverArms(bodies, s.solver);
        solveVelocities(settings.contactIterations, Separation{}, bodies, s.solver);
        applyRestitution(settings.contactIterations, 2.0 * step.gravity.norm() * h + 1e-9, bodies, s.solver);
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
            if (target.translation != now.translation || target.rotation.coeffs() != now.rotation.coeffs()) s.cachedBody.reset();
            bodies.parts[id]->setPose(target);
        }
        bodies.kinematicTargets[id].reset();
        RigidBody& body = bodies.rigid[id];
        const Pose& start = s.stepStart[id];
        const Pose& end = bodies.parts[id]->pose();
        Eigen::Quaterniond rotation = end.rotation * start.rotation.conjugate();
        if (rotation.w() < 0.0) rotation.coeffs() *= -1.0;  // the short way round
        const Eigen::AngleAxisd turn(rotation);
        body.linearVelocity = (end.apply(body.centreOfMass) - start.apply(body.centreOfMass)) / h;
        body.angularVelocity = turn.axis() * (turn.angle() / h);
    }
    profile.substeps += std::uint64_t(substeps);
    profile.rigidQueries += s.queries;
    s.queries = 0;
}

}  // namespace flexfit::detail
