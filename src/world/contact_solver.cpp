// The contact solver stage (contact_solver.hpp).
#include "contact_solver.hpp"

#include <algorithm>
#include <cmath>

namespace flexfit::detail {
namespace {

// The solver's inner calls are forced inline (GCC kept them out of line): the stack scene's
// solve 73 -> 64 us a step, the same bits.

// Velocity of the body's material point at r from its centre of mass.
[[gnu::always_inline]] inline Vec3 pointVelocity(const RigidBody& body, const Vec3& r) {
    return body.linearVelocity + body.angularVelocity.cross(r);
}

[[gnu::always_inline]] inline Vec3 relativeVelocity(const Bodies& bodies, const SolverContact& c) {
    return pointVelocity(bodies.rigid[c.a], c.ra) - pointVelocity(bodies.rigid[c.b], c.rb);
}

// The inverse of the effective mass the pair opposes to an impulse along `direction`.
double effectiveMass(const Bodies& bodies, const ContactSolver& s, const SolverContact& c, const Vec3& direction) {
    double inverse = 0.0;
    for (const auto& [id, r] : {std::pair{c.a, c.ra}, std::pair{c.b, c.rb}}) {
        if (!bodies.dynamic(id)) continue;
        const Vec3 rn = r.cross(direction);
        inverse += bodies.rigid[id].inverseMass + rn.dot(s.inverseInertia[id] * rn);
    }
    return inverse > 0.0 ? 1.0 / inverse : 0.0;
}

// Impulse p on a at the point, -p on b.
[[gnu::always_inline]] inline void applyImpulse(const Vec3& p, const ContactSolver& s, const SolverContact& c, Bodies& bodies) {
    if (bodies.dynamic(c.a)) {
        RigidBody& a = bodies.rigid[c.a];
        a.linearVelocity += a.inverseMass * p;
        a.angularVelocity += s.inverseInertia[c.a] * c.ra.cross(p);
    }
    if (bodies.dynamic(c.b)) {
        RigidBody& b = bodies.rigid[c.b];
        b.linearVelocity -= b.inverseMass * p;
        b.angularVelocity -= s.inverseInertia[c.b] * c.rb.cross(p);
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
void solveFriction(SolverContact& c, const ContactSolver& s, Bodies& bodies) {
    const Vec3 v = relativeVelocity(bodies, c);
    const double old1 = c.tangentImpulse1, old2 = c.tangentImpulse2;
    double new1 = old1 - c.tangentMass1 * v.dot(c.tangent1);
    double new2 = old2 - c.tangentMass2 * v.dot(c.tangent2);
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
    applyImpulse((new1 - old1) * c.tangent1 + (new2 - old2) * c.tangent2, s, c, bodies);
}

void solveNormal(SolverContact& c, double targetSpeed, const ContactSolver& s, Bodies& bodies) {
    const double speed = relativeVelocity(bodies, c).dot(c.normal);
    const double accumulated = std::max(c.normalImpulse - c.normalMass * (speed - targetSpeed), 0.0);
    const double change = accumulated - c.normalImpulse;
    c.normalImpulse = accumulated;
    applyImpulse(change * c.normal, s, c, bodies);
}

}  // namespace

// Whether the tangent impulse (x, y) is inside the static cone of radius `cone` by far more
// than rounding: then std::hypot(x, y) > cone is false, and hypot (a libm call, 8 % of the
// stack scene's samples in perf, where every resting contact is well inside) need not run.
// The squares round by a few ulps against hypot's one, far within the 1e-12 margin; cones
// below 1e-150 (whose squares could lose digits below the normal range) always take hypot.
bool wellInsideCone(double x, double y, double cone) {
    return cone > 1e-150 && x * x + y * y < cone * cone * (1.0 - 1e-12);
}

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
        c.normalMass = effectiveMass(bodies, solver, c, c.normal);
        c.tangentMass1 = effectiveMass(bodies, solver, c, c.tangent1);
        c.tangentMass2 = effectiveMass(bodies, solver, c, c.tangent2);
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
        applyImpulse(c.normalImpulse * c.normal + c.tangentImpulse1 * c.tangent1 + c.tangentImpulse2 * c.tangent2, solver, c, bodies);
    }
}

void refreshLeverArms(const Bodies& bodies, ContactSolver& solver) {
    for (SolverContact& c : solver.contacts) {
        const Vec3 comA = bodies.centreOfMass(c.a), comB = bodies.centreOfMass(c.b);
        const Vec3 point = 0.5 * ((comA + c.ra) + (comB + c.rb));
        c.ra = point - comA;
        c.rb = point - comB;
    }
}

void solveVelocities(int iterations, const Separation& separation, Bodies& bodies, ContactSolver& solver) {
    for (int iteration = 0; iteration < iterations; ++iteration)
        for (SolverContact& c : solver.contacts) {
            // Friction first, within the normal impulse of the last pass (Box2D's order); a
            // frictionless pair's tangent impulses stay zero.
            if (c.staticFriction > 0.0 || c.kineticFriction > 0.0) solveFriction(c, solver, bodies);
            solveNormal(c, std::min(separation.rate * std::max(c.depth - separation.slop, 0.0), separation.maxSpeed), solver, bodies);
        }
}

void applyRestitution(int iterations, Bodies& bodies, ContactSolver& solver) {
    auto bounces = [](const SolverContact& c) { return c.restitution > 0.0 && c.approachSpeed < -c.bounceThreshold; };
    const bool any = std::any_of(solver.contacts.begin(), solver.contacts.end(), bounces);
    if (!any) return;
    for (int iteration = 0; iteration < iterations; ++iteration)
        for (SolverContact& c : solver.contacts)
            if (bounces(c)) solveNormal(c, -c.restitution * c.approachSpeed, solver, bodies);
}

}  // namespace flexfit::detail
