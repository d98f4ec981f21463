// The world: parts with rigid-body motion, collisions and deformation, advanced by one step
// made of named, profiled stages (SPEC 7-8, thesis 4.4).
//
// Motion types: Static (never moves), Kinematic (moved by the caller or the operator: its pose
// is set, its velocity derived), Dynamic (gravity, forces and torques, inertia from the mesh at
// the body's density). Each body is a Part, so any motion type combines with any deformation
// mode (rigid, rigid-deformable, full-deformable).
//
// No tunnelling (conservative advancement): a dynamic body's motion in a step is cut into
// sub-steps so that no point of it travels more than `maxTravelFraction` of the thinnest body
// it can meet (each body's thickness: its smallest bounding-box half-extent unless given), and
// contacts are detected and resolved after every sub-step. A body can therefore not jump over
// a part, whatever its speed or the time step; the cost grows with speed x dt / thickness.
// Known limit: the thickness estimate assumes parts are at least as thick as the smallest
// half-extent of their box (a thin diagonal feature needs BodySettings::thickness).
//
// Gravity acts on bodies (dynamic ones fall), not on the masses of deformation zones: a part's
// rest shape is its shape under its own weight, and in a falling body's frame its masses feel
// none, so zones deform from contacts and operator forces only.
//
// Deformable contacts: the collision response deforms the part, and a dynamic body pressing it
// receives the force of the displaced springs, k_eff (rest - x) summed over the contacted
// masses (k_eff as in collision_world.hpp), for the next step.
//
// Rigid contacts are resolved by projection: the dynamic body moves out of its contacts
// (Gauss-Seidel over their normals and depths, re-detected up to contactIterations times per
// sub-step) and loses the velocity into them (inelastic, no friction yet). Contacts with
// deformable parts go to the collision world's response.
//
// The operator (thesis 4.1.4; SHARP, VEDAP-II): grab() holds a body; setGrabTarget() moves the
// pose the operator wants it at. A dynamic body is pulled by a spring-damper coupling between
// that target and its pose (linear at the centre of mass, angular on the rotation error), so
// it still collides, deforms parts and snaps; the coupling force and torque are reported for a
// haptic device (the device feels their opposite). A kinematic body follows the target
// exactly. The coupling damps the velocity relative to the target's, so a moving target is
// followed without lag; move the target continuously (a jump d gives an impulse b d).
// A body that snaps is released. Forces on selected masses or faces deform a
// deformable part (zones open there) and push a rigid dynamic one at that point.
//
// Stages, in order, each timed into profile(): operator input, broad phase, narrow phase,
// contact response, zone dynamics (the deformable parts' step, restoration included: the
// constraint is applied inside the integration), zone retirement (inside the parts' step, so
// charged to zone dynamics), assembly (the snapping rules).
#pragma once

#include "flexfit/assembly.hpp"
#include "flexfit/collision_world.hpp"
#include "flexfit/epoch_marks.hpp"
#include "flexfit/mass_properties.hpp"

#include <array>
#include <memory>
#include <tuple>

namespace flexfit {

enum class MotionType { Static, Kinematic, Dynamic };
const char* toString(MotionType motion);

struct BodySettings {
    MotionType motion = MotionType::Static;
    double density = 1.0;                  // mass = density x enclosed volume (dynamic bodies)
    Vec3 linearVelocity = Vec3::Zero();    // initial, world (m/s)
    Vec3 angularVelocity = Vec3::Zero();   // initial, world (rad/s)
    double thickness = 0.0;                // for the no-tunnelling bound; 0: smallest box half-extent
    BoundingVolumeKind boundingVolume = BoundingVolumeKind::Aabb;
};

struct RigidBody {
    MotionType motion = MotionType::Static;
    double mass = 0.0, inverseMass = 0.0;
    Vec3 centreOfMass = Vec3::Zero();                        // part frame
    Eigen::Matrix3d inverseInertia = Eigen::Matrix3d::Zero(); // part frame, about the centre of mass
    Vec3 linearVelocity = Vec3::Zero();   // world, of the centre of mass
    Vec3 angularVelocity = Vec3::Zero();  // world
    Vec3 force = Vec3::Zero();            // world, accumulated for the next step
    Vec3 torque = Vec3::Zero();           // world, about the centre of mass
    double thickness = 0.0;
    double boundingRadius = 0.0;          // from the centre of mass to the farthest mass
};

enum class Stage { OperatorInput, BroadPhase, NarrowPhase, ContactResponse, ZoneDynamics, ZoneRetirement, Assembly, Count };
const char* toString(Stage stage);

struct Profile {
    std::array<double, std::size_t(Stage::Count)> lastSeconds{};   // the last step
    std::array<double, std::size_t(Stage::Count)> totalSeconds{};  // since the start
    std::uint64_t steps = 0;
    std::uint64_t substeps = 0;  // dynamic sub-steps taken in all (no-tunnelling bound)
};

struct WorldSettings {
    double timeStep = 1e-3;
    Vec3 gravity = Vec3(0.0, -9.81, 0.0);
    CollisionSettings collision;
    double maxTravelFraction = 0.25;  // of the thinnest body, per sub-step
    int maxSubsteps = 4096;
    int contactIterations = 4;        // projection passes per sub-step
};

using BodyId = std::uint32_t;

// The operator's spring-damper coupling. Zero stiffness: the body's mass (and smallest
// principal inertia) times w^2, w = min(2 pi frequency, 0.4 / dt), so the explicit coupling is
// stable at any time step; negative damping: critical (2 sqrt(k m)).
struct GrabSettings {
    double frequency = 10.0;          // Hz, for the default stiffnesses
    double stiffness = 0.0;           // N/m
    double damping = -1.0;            // N s/m
    double angularStiffness = 0.0;    // N m/rad
    double angularDamping = -1.0;     // N m s/rad
};

// What the coupling applied to the grabbed body in the last step (world frame).
struct Coupling {
    bool active = false;
    BodyId body = 0;
    Vec3 force = Vec3::Zero();
    Vec3 torque = Vec3::Zero();
};

class World {
public:
    explicit World(WorldSettings settings = {});

    // Adds a part with its rigid-body description; returns its id (0, 1, 2, ...). Dynamic
    // bodies need a closed mesh (their mass and inertia come from its volume). The part's
    // simulation time step is set to the world's, its gravity to zero (see above).
    BodyId add(std::shared_ptr<const PartModel> model, const PartSettings& part, const BodySettings& body, const Pose& pose);

    std::size_t bodyCount() const { return parts_.size(); }
    // Changes a part's settings while the world runs (Part::setSettings; the world's time step
    // and its no-gravity rule for zone masses are kept; the contact stiffness follows).
    void setPartSettings(BodyId id, const PartSettings& settings);
    Part& part(BodyId id) { return *parts_[id]; }
    const Part& part(BodyId id) const { return *parts_[id]; }
    const RigidBody& body(BodyId id) const { return bodies_[id]; }
    const WorldSettings& settings() const { return settings_; }

    // Forces for the next step (dynamic bodies; ignored otherwise).
    void applyForce(BodyId id, const Vec3& worldForce);                           // at the centre of mass
    void applyForceAt(BodyId id, const Vec3& worldForce, const Vec3& worldPoint);  // adds the torque
    void setVelocity(BodyId id, const Vec3& linear, const Vec3& angular);
    // Kinematic bodies: the pose to reach by the end of the next step (velocity derived).
    void setKinematicTarget(BodyId id, const Pose& target);

    // --- The operator ---
    // Grabs a dynamic or kinematic body (throws InputError for a static one, or for coupling
    // settings the time step cannot integrate stably); the target starts at its pose.
    void grab(BodyId id, const GrabSettings& settings = {});
    void setGrabTarget(const Pose& target);  // the grabbed body's desired pose
    void release();
    std::optional<BodyId> grabbed() const { return grabbed_; }
    const Pose& grabTarget() const { return grabTarget_; }
    const Coupling& coupling() const { return coupling_; }
    // A world-frame force for the next step on one mass, or spread over a face's three masses.
    // Throws InputError for an index out of range.
    void applyMassForce(BodyId id, Index mass, const Vec3& worldForce);
    void applyFaceForce(BodyId id, Index face, const Vec3& worldForce);

    // Assembly rules (assembly.hpp), checked in the assembly stage of every step. When a rule
    // triggers, its primary stops being driven (it becomes kinematic), is brought to its final
    // pose over the snap duration, and then stays attached to the secondary. Throws InputError
    // for unknown bodies or a negative duration.
    std::size_t addAssembly(const AssemblyRule& rule);
    const std::vector<AssemblyEvent>& assemblyEvents() const { return events_; }
    bool assembled(std::size_t rule) const { return rules_[rule].phase == RuleState::Phase::Assembled; }

    void step();
    double time() const { return time_; }

    const std::vector<Contact>& contacts() const { return collision_.contacts(); }
    const Profile& profile() const { return profile_; }
    CollisionWorld& collision() { return collision_; }

    // 64-bit FNV-1a over time, every pose, body velocity and part state (part_state.hpp), bit
    // for bit, plus the assembly events: equal hashes mean the same run (determinism tests).
    std::uint64_t stateHash() const;

    // World position of a body's centre of mass.
    Vec3 centreOfMass(BodyId id) const { return parts_[id]->pose().apply(bodies_[id].centreOfMass); }

private:
    void operatorInput();
    void applyCoupling();
    struct CouplingGains { double k, b, kr, br; };
    CouplingGains couplingGains(BodyId id, const GrabSettings& settings) const;
    std::optional<BodyId> grabbed_;
    CouplingGains gains_{};
    Pose grabTarget_, previousGrabTarget_;
    Coupling coupling_;

    void integrateDynamicBodies();
    void advanceBody(BodyId id, double dt);
    void resolveRigidContacts(BodyId id);
    double minimumThickness() const;
    void assemble();
    void applyDeformableReactions(std::span<const Contact> contacts);
    // A part's settings as the world runs them: its time step, no gravity on zone masses.
    PartSettings inWorld(PartSettings settings) const;
    std::vector<std::tuple<BodyId, BodyId, Index>> reactionMasses_;  // scratch: (body, part, mass)
    // Per part: the masses counted in this step, and for which body each was last counted.
    std::vector<std::pair<EpochMarks, std::vector<BodyId>>> reactionMarks_;
    bool touching(BodyId a, BodyId b) const;

    struct RuleState {
        AssemblyRule rule;
        enum class Phase { Waiting, Snapping, Assembled } phase = Phase::Waiting;
        double start = 0.0;
        Pose from;
    };
    std::vector<RuleState> rules_;
    std::vector<AssemblyEvent> events_;

    WorldSettings settings_;
    std::vector<std::unique_ptr<Part>> parts_;
    std::vector<RigidBody> bodies_;
    std::vector<std::optional<Pose>> kinematicTargets_;
    CollisionWorld collision_;
    std::vector<std::pair<Vec3, double>> pushes_;  // scratch: contact direction and depth
    Profile profile_;
    double time_ = 0.0;
};

}  // namespace flexfit
