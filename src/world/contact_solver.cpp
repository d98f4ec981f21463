// The contact solver stage (contact_solver.hpp).
#include "contact_solver.hpp"

#include <algorithm>
#include <cmath>

namespace flexfit::detail {
namespace {

// Velocity of the body's material point at r from its centre of mass.
Vec3 pointVelocity(const RigidBody& body, const Vec3& r) { return body.linearVelocity + body.angularVelocity.cross(r); }

Vec3 relativeVelocity(const Bodies& bodies, const SolverContact& c) {
    return pointVelocity(bodies.rigid[c.a], c.ra) - pointVelocity(bodies.rigid[c.b], c.rb);
}

// Direction k of the point: its normal (0), tangent1 (1) or tangent2 (2).
inline const Vec3& directionOf(const SolverContact& c, int k) { return k == 0 ? c.normal : k == 1 ? c.tangent1 : c.tangent2; }

// The point's relative speed along direction k (prepareDirections), from the bodies'
// velocities: d . (v_a - v_b) + (r_a x d) . w_a - (r_b x d) . w_b.
inline double speedAlong(const SolverContact& c, int k, const Bodies& bodies) {
    const Vec3& d = directionOf(c, k);
    const RigidBody& a = bodies.rigid[c.a];
    const RigidBody& b = bodies.rigid[c.b];
    const SolverContact::Direction& along = c.along[k];
    return d.dot(a.linearVelocity - b.linearVelocity) + along.armA.dot(a.angularVelocity) - along.armB.dot(b.angularVelocity);
}

// Impulse `linear` (world) on a at the point and -linear on b, whose angular parts are
// `turnA` and `turnB` (sums of the directions' turns times their impulses).
inline void applyImpulse(const SolverContact& c, const Vec3& linear, const Vec3& turnA, const Vec3& turnB, Bodies& bodies) {
    if (c.dynamicA) {
        RigidBody& a = bodies.rigid[c.a];
        a.linearVelocity += c.inverseMassA * linear;
        a.angularVelocity += turnA;
    }
    if (c.dynamicB) {
        RigidBody& b = bodies.rigid[c.b];
        b.linearVelocity -= c.inverseMassB * linear;
        b.angularVelocity -= turnB;
    }
}

// An impulse `impulse` along direction k.
inline void applyAlong(const SolverContact& c, int k, double impulse, Bodies& bodies) {
    applyImpulse(c, impulse * directionOf(c, k), impulse * c.along[k].turnA, impulse * c.along[k].turnB, bodies);
}

// The inverse of the effective mass the pair opposes to an impulse along direction k.
double effectiveMass(const SolverContact& c, int k) {
    const SolverContact::Direction& d = c.along[k];
    const double inverse = c.inverseMassA + d.armA.dot(d.turnA) + c.inverseMassB + d.armB.dot(d.turnB);
    return inverse > 0.0 ? 1.0 / inverse : 0.0;
}

// The directions' arms and turns at the point's lever arms (SolverContact::Direction).
void prepareDirections(const Bodies& bodies, const ContactSolver& s, SolverContact& c) {
    c.dynamicA = bodies.dynamic(c.a);
    c.dynamicB = bodies.dynamic(c.b);
    c.inverseMassA = c.dynamicA ? bodies.rigid[c.a].inverseMass : 0.0;
    c.inverseMassB = c.dynamicB ? bodies.rigid[c.b].inverseMass : 0.0;
    for (int k = 0; k < 3; ++k) {
        SolverContact::Direction& d = c.along[k];
        d.armA = c.ra.cross(directionOf(c, k));
        d.armB = c.rb.cross(directionOf(c, k));
        d.turnA = c.dynamicA ? Vec3(s.inverseInertia[c.a] * d.armA) : Vec3::Zero();
        d.turnB = c.dynamicB ? Vec3(s.inverseInertia[c.b] * d.armB) : Vec3::Zero();
    }
}

// Two unit tangents completing the normal to an orthonormal frame.
void tangentsOf(const Vec3& n, Vec3& t1, Vec3& t2) {
    const Vec3 helper = std::abs(n.x()) < 0.57 ? Vec3::UnitX() : Vec3::UnitY();
    t1 = n.cross(helper).normalized();
    t2 = n.cross(t1);
}

// Coulomb: the impulse that stops the sliding while within the static cone, else the kinetic
// one against it.
void solveFriction(SolverContact& c, Bodies& bodies) {
    const double old1 = c.tangentImpulse1, old2 = c.tangentImpulse2;
    double new1 = old1 - c.tangentMass1 * speedAlong(c, 1, bodies);
    double new2 = old2 - c.tangentMass2 * speedAlong(c, 2, bodies);
    const double cone = c.staticFriction * c.normalImpulse;
    if (!wellInsideCone(new1, new2, cone)) {
        const double magnitude = std::hypot(new1, new2);
        if (magnitude > cone) {
            const double scale = magnitude > 0.0 ? c.kineticFriction * c.normalImpulse / magnitude : 0.0;
            new1 *= scale;
            new2 *= scale;
        }
    }
    c.tangentImpulse1 = new1;
    c.tangentImpulse2 = new2;
    const double change1 = new1 - old1, change2 = new2 - old2;
    applyImpulse(c, change1 * c.tangent1 + change2 * c.tangent2, change1 * c.along[1].turnA + change2 * c.along[2].turnA,
                 change1 * c.along[1].turnB + change2 * c.along[2].turnB, bodies);
}

void solveNormal(SolverContact& c, double targetSpeed, Bodies& bodies) {
    const double speed = speedAlong(c, 0, bodies);
    const double accumulated = std::max(c.normalImpulse - c.normalMass * (speed - targetSpeed), 0.0);
    const double change = accumulated - c.normalImpulse;
    c.normalImpulse = accumulated;
    applyAlong(c, 0, change, bodies);
}

}  // namespace

// Rigid contacts; and a dynamic deforming body's contacts with rigid parts (its rigid motion
// meets them as a rigid body's would; the response deforms it there).
bool solvedByImpulses(const Bodies& bodies, BodyId a, BodyId b) {
    const bool da = bodies.parts[a]->deforms(), db = bodies.parts[b]->deforms();
    if (!da && !db) return bodies.dynamic(a) || bodies.dynamic(b);
    if (da && db) return false;
    return bodies.dynamic(da ? a : b);
}

double combinedFriction(double a, double b) { return std::sqrt(a * b); }
double combinedRestitution(double a, double b) { return std::max(a, b); }

void updateInverseInertia(std::span<const BodyId> moving, const Bodies& bodies, ContactSolver& solver) {
    solver.inverseInertia.resize(bodies.size(), Eigen::Matrix3d::Zero());
    for (BodyId id : moving) {
        if (!bodies.dynamic(id)) continue;
        const Eigen::Matrix3d r = bodies.parts[id]->pose().rotation.toRotationMatrix();
        solver.inverseInertia[id] = r * bodies.rigid[id].inverseInertia * r.transpose();
    }
}

void addContacts(std::span<const Contact> contacts, const Bodies& bodies, ContactSolver& solver) {
    for (const Contact& contact : contacts) {
        const BodyId a = contact.partA, b = contact.partB;
        if (!solvedByImpulses(bodies, a, b)) continue;
        const RigidBody& ba = bodies.rigid[a];
        const RigidBody& bb = bodies.rigid[b];
        SolverContact c;
        c.a = a;
        c.b = b;
        c.faceA = contact.faceA;
        c.faceB = contact.faceB;
        c.massB = contact.massB;
        c.ra = contact.point - bodies.centreOfMass(a);
        c.rb = contact.point - bodies.centreOfMass(b);
        c.normal = contact.normal;
        tangentsOf(c.normal, c.tangent1, c.tangent2);
        c.depth = contact.depth;
        prepareDirections(bodies, solver, c);
        c.normalMass = effectiveMass(c, 0);
        c.tangentMass1 = effectiveMass(c, 1);
        c.tangentMass2 = effectiveMass(c, 2);
        c.approachSpeed = relativeVelocity(bodies, c).dot(c.normal);
        c.staticFriction = combinedFriction(ba.staticFriction, bb.staticFriction);
        c.kineticFriction = combinedFriction(ba.kineticFriction, bb.kineticFriction);
        c.restitution = combinedRestitution(ba.restitution, bb.restitution);
        solver.contacts.push_back(c);
    }
}

void keepImpulses(ContactSolver& solver) {
    solver.kept.clear();
    for (const SolverContact& c : solver.contacts)
        solver.kept.push_back({keyOf(c), c.normalImpulse, c.tangentImpulse1 * c.tangent1 + c.tangentImpulse2 * c.tangent2, c.normal});
    std::sort(solver.kept.begin(), solver.kept.end(), [](const auto& x, const auto& y) { return x.key < y.key; });
}

void warmStart(Bodies& bodies, ContactSolver& solver) {
    auto byKey = [](const ContactSolver::Kept& k, const ContactKey& key) { return k.key < key; };
    for (SolverContact& c : solver.contacts) {
        const ContactKey key = keyOf(c);
        const auto found = std::lower_bound(solver.kept.begin(), solver.kept.end(), key, byKey);
        if (found == solver.kept.end() || found->key != key || found->normal.dot(c.normal) < kWarmStartAlignment) continue;
        c.normalImpulse = std::min(found->normalImpulse, c.normalMass * c.bounceThreshold);
        const double kept = found->normalImpulse > 0.0 ? c.normalImpulse / found->normalImpulse : 0.0;
        c.tangentImpulse1 = kept * found->tangentImpulse.dot(c.tangent1);
        c.tangentImpulse2 = kept * found->tangentImpulse.dot(c.tangent2);
        applyImpulse(c, c.normalImpulse * c.normal + c.tangentImpulse1 * c.tangent1 + c.tangentImpulse2 * c.tangent2,
                     c.normalImpulse * c.along[0].turnA + c.tangentImpulse1 * c.along[1].turnA + c.tangentImpulse2 * c.along[2].turnA,
                     c.normalImpulse * c.along[0].turnB + c.tangentImpulse1 * c.along[1].turnB + c.tangentImpulse2 * c.along[2].turnB,
                     bodies);
    }
}

void refreshLeverArms(const Bodies& bodies, ContactSolver& solver) {
    for (SolverContact& c : solver.contacts) {
        const Vec3 comA = bodies.centreOfMass(c.a), comB = bodies.centreOfMass(c.b);
        const Vec3 point = 0.5 * ((comA + c.ra) + (comB + c.rb));
        c.ra = point - comA;
        c.rb = point - comB;
        prepareDirections(bodies, solver, c);
    }
}

void solveVelocities(int iterations, const Separation& separation, Bodies& bodies, ContactSolver& solver) {
    for (int iteration = 0; iteration < iterations; ++iteration)
        for (SolverContact& c : solver.contacts) {
            // Friction first, within the normal impulse of the last pass (Box2D's order); a
            // frictionless pair's tangent impulses stay zero.
            if (c.staticFriction > 0.0 || c.kineticFriction > 0.0) solveFriction(c, bodies);
            solveNormal(c, std::min(separation.rate * std::max(c.depth - separation.slop, 0.0), separation.maxSpeed), bodies);
        }
}

void applyRestitution(int iterations, Bodies& bodies, ContactSolver& solver) {
    auto bounces = [](const SolverContact& c) { return c.restitution > 0.0 && c.approachSpeed < -c.bounceThreshold; };
    const bool any = std::any_of(solver.contacts.begin(), solver.contacts.end(), bounces);
    if (!any) return;
    for (int iteration = 0; iteration < iterations; ++iteration)
        for (SolverContact& c : solver.contacts)
            if (bounces(c)) solveNormal(c, -c.restitution * c.approachSpeed, bodies);
}

}  // namespace flexfit::detail
