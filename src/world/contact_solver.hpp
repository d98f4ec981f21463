// Internal to src/world: the contact solver stage (world.hpp, "Contacts"). It runs inside the
// rigid motion's sub-steps, on the contacts between bodies whose parts do not deform (rigid
// mode), at least one of them dynamic; and on a dynamic deforming body's contacts with rigid
// parts (its rigid motion meets them as a rigid body's would, while the contact response
// deforms it there and gives no spring reaction for that pair).
//
// Sequential impulses (Catto's, as Box2D and Jolt use): each contact point is a normal
// constraint (relative normal speed >= 0, impulse >= 0) and two friction constraints along the
// tangent plane, solved one point at a time over a few iterations. Every impulse goes to both
// bodies at the same point, weighted by inverse mass and world inverse inertia, so two dynamic
// bodies conserve linear and angular momentum to rounding.
//
//   Friction (Coulomb, static and kinetic): a point's tangential impulse is the one that stops
//   the sliding, while it stays within mu_s times the normal impulse (the point sticks); beyond
//   that the point slides and gets mu_k times the normal impulse, against the sliding (a disc,
//   not a pyramid: no preferred direction).
//   Depth: a penetrating point asks for a separating speed beta (depth - linear slop) / dt
//   (Baumgarte) in a first pass; the sub-step's positions move with those velocities, and a
//   second pass without it (relax, as Box2D v3's soft step) takes back the speed that only
//   served to separate. Both passes are impulses, so correcting a depth conserves momentum too.
//   Restitution: after the relax, a point that approached faster than its threshold (twice
//   the speed the loads give in a step: resting contacts never bounce) gets the
//   normal impulse that makes it separate at e times its approach speed.
//
//   Warm starting (Catto; Box2D, Jolt): a point found again in the next sub-step (the same
//   pair of bodies and faces, or point-shell mass) starts from the impulses it ended the last
//   one with, applied before the first pass, so a resting load is carried from the first
//   iteration on instead of rebuilt from zero each sub-step: stacks and pegs held by friction
//   stand still instead of creeping. Two guards keep a stale impulse from launching a body: a
//   point whose normal turned by more than 18 degrees starts from zero, and the normal impulse
//   kept is at most what stops the point's bounce threshold (twice the speed the loads give in
//   a step), with its friction scaled alike, so an impact's impulse (a ball thrown at 1e4 into
//   a wedge) is not applied again.
//
// Known limits: contact points come from triangle pairs, several per face pair, so a box on a
// face is held at several points of its face, not exactly at its corners.
#pragma once

#include "bodies.hpp"
#include "flexfit/collision.hpp"
#include "flexfit/world_settings.hpp"

#include <span>
#include <vector>

namespace flexfit::detail {

// Which contact a point is, from one sub-step to the next: its bodies and faces (and the mass
// of a point-shell contact).
struct ContactKey {
    BodyId a = 0, b = 0;
    Index faceA = 0, faceB = 0, massB = kNoMass;
    auto operator<=>(const ContactKey&) const = default;
};

struct SolverContact {
    BodyId a = 0, b = 0;       // pushing a along +normal separates them
    Index faceA = 0, faceB = 0, massB = kNoMass;  // the contact's (its key with a and b)
    Vec3 ra, rb;               // from each body's centre of mass to the point (world)
    Vec3 normal, tangent1, tangent2;
    double depth = 0.0;
    double normalMass = 0.0, tangentMass1 = 0.0, tangentMass2 = 0.0;  // 1 / effective inverse mass
    double normalImpulse = 0.0, tangentImpulse1 = 0.0, tangentImpulse2 = 0.0;  // accumulated
    // What an impulse along each of normal, tangent1, tangent2 (k = 0, 1, 2) does, prepared
    // once a sub-step and after the lever arms move (prepareDirections), so the passes need no
    // cross product or inertia product: r x d of each body (its angular velocity's share of the
    // point's speed along d) and I^-1 (r x d) (the angular velocity a unit impulse along d
    // gives it; zero for a body that is not dynamic, whose velocity no impulse changes).
    struct Direction {
        Vec3 armA, armB, turnA, turnB;
    };
    Direction along[3];
    double inverseMassA = 0.0, inverseMassB = 0.0;  // 0 for a body that is not dynamic
    bool dynamicA = false, dynamicB = false;
    double approachSpeed = 0.0;  // relative normal speed before the solve (< 0: approaching)
    double bounceThreshold = 1e-9;  // approach speed below which it does not bounce
    double staticFriction = 0.0, kineticFriction = 0.0, restitution = 0.0;
};

inline ContactKey keyOf(const SolverContact& c) { return {c.a, c.b, c.faceA, c.faceB, c.massB}; }

struct ContactSolver {
    std::vector<SolverContact> contacts;
    std::vector<Eigen::Matrix3d> inverseInertia;  // (nbody) world frame, at the sub-step's start
    // The last sub-step's points, by key, sorted (keepImpulses): what warmStart starts from.
    struct Kept {
        ContactKey key;
        double normalImpulse = 0.0;
        Vec3 tangentImpulse = Vec3::Zero();  // world
        Vec3 normal = Vec3::UnitY();
    };
    std::vector<Kept> kept;
};

// A kept point warm-starts a new one only while their normals agree this well (cos 18 deg).
inline constexpr double kWarmStartAlignment = 0.95;

// Records the points' accumulated impulses; call before the points are replaced.
void keepImpulses(ContactSolver& solver);
// Gives each new point the impulses its key ended the last sub-step with (the guards above) and
// applies them to the bodies. After addContacts and the bounce thresholds, before the passes.
void warmStart(Bodies& bodies, ContactSolver& solver);

// Whether the tangent impulse (x, y) is inside the static cone of radius `cone` by far more
// than rounding: then std::hypot(x, y) > cone is false, and hypot (a libm call, 8 % of the
// stack scene's samples in perf, where every resting contact is well inside) need not run.
// The squares round by a few ulps against hypot's one, far within the 1e-12 margin; cones
// below 1e-150 (whose squares could lose digits below the normal range) always take hypot.
// Inline: a call of its own was 6 % of the stack scene's samples.
inline bool wellInsideCone(double x, double y, double cone) {
    return cone > 1e-150 && x * x + y * y < cone * cone * (1.0 - 1e-12);
}

// Combining rules (body.hpp): geometric mean of the frictions, larger restitution.
double combinedFriction(double a, double b);
double combinedRestitution(double a, double b);

// World inverse inertia of the dynamic bodies among `moving` (every dynamic body moves) at
// their current pose; the others' entries are never read.
void updateInverseInertia(std::span<const BodyId> moving, const Bodies& bodies, ContactSolver& solver);

// Appends one solver point per contact, with its effective masses and approach speed. Skips
// the contacts the solver does not own (see above).
void addContacts(std::span<const Contact> contacts, const Bodies& bodies, ContactSolver& solver);

// After the sub-step's move: each point's lever arms from the bodies' new centres of mass to
// one common point (the middle of where the two bodies carried it), so that the passes after
// the move still give both bodies the impulse at the same point (angular momentum conserved).
void refreshLeverArms(const Bodies& bodies, ContactSolver& solver);

// How fast a penetrating point asks to separate: rate (beta / dt) times its depth beyond
// `slop`, at most maxSpeed. The cap matters in wedges (a ball in a ring, a peg in a hole): normals
// nearly opposite turn a small separating speed along them into a large one along the wedge,
// which the relax pass converges too slowly to take back. Rate 0: the relax pass.
struct Separation {
    double rate = 0.0, slop = 0.0, maxSpeed = 0.0;
};

// `iterations` passes over the points, friction then normal at each.
void solveVelocities(int iterations, const Separation& separation, Bodies& bodies, ContactSolver& solver);

// Normal impulses that turn each point's approach into a separation at restitution times its
// approach speed, for points that approached faster than their bounce threshold.
void applyRestitution(int iterations, Bodies& bodies, ContactSolver& solver);

// Whether the solver owns the contacts of the pair (see above).
bool solvedByImpulses(const Bodies& bodies, BodyId a, BodyId b);

}  // namespace flexfit::detail
