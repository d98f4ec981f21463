// The world: parts with rigid-body motion, collisions and deformation, advanced by one step
// made of named, profiled stages (SPEC 7-8, thesis 4.4). docs/architecture.md draws the
// picture; each stage is one file of src/world/ or src/collision/.
//
// A step, in order (each stage charged to profile(), profile.hpp):
//   1. operator input    the operator's coupling force on the grabbed body; kinematic bodies
//                        aimed at their targets (operator_input.cpp)
//   2. rigid motion      dynamic and kinematic bodies moved in sub-steps, each move
//                        conservative (rigid_motion.cpp), with in each sub-step
//      contact solver    the impulses of the rigid contacts: normal, friction, restitution
//                        (contact_solver.cpp)
//   3. broad phase       bounding spheres, candidate pairs (broad_phase.cpp)
//   4. narrow phase      the contacts of the candidate pairs, refitting the deformed
//                        hierarchies it traverses (narrow_phase.cpp)
//   5. contact response  deformable parts pushed out of their contacts, their reactions on
//                        dynamic bodies (contact_response.cpp)
//   6. zone dynamics     every deformable part's moving masses (zone_dynamics.cpp)
//   7. zone retirement   zones at rest retired (zone_retirement.cpp)
//   8. assembly          the snapping rules (assembly.cpp)
// Each stage's signature shows what it reads and writes: the step context (time step, gravity,
// step index, time) where it needs one, and the pieces of the world it touches. Parts keep the
// settings they were given: the world's time step and gravity reach them through the context,
// never by rewriting their settings (a part's own settings must still be valid on their own).
//
// Bodies (body.hpp): static, kinematic or dynamic, each a Part, so any motion type combines
// with any deformation mode. The world owns them; its collision side sees them read-only under
// the same ids, and only the world's stages change them. part() and collision() are read-only
// views; settings change through setPartSettings().
//
// No tunnelling (conservative advancement): the moving bodies' motion in a step is cut into
// sub-steps so that no point travels more than `maxTravelFraction` of the thinnest body it can
// meet (each body's thickness: its smallest bounding-box half-extent unless given), and a
// sub-step's move that would take a body deeper than `contactSlop` of that thickness into a
// part that does not deform is bisected back to the last fraction that does not. Contact
// normals and depths therefore come from shallow configurations, and no force, speed or time
// step gets a body through a rigid part; the cost grows with speed x dt / thickness. Known
// limits: the thickness estimate assumes parts are at least as thick as the smallest
// half-extent of their box (a thin diagonal feature needs BodySettings::thickness); a move cut
// short loses its remainder (energy, and momentum between two dynamic bodies).
//
// Gravity acts on bodies (dynamic ones fall), not on the masses of deformation zones: a part's
// rest shape is its shape under its own weight, and in a falling body's frame its masses feel
// none, so zones deform from contacts and operator forces only.
//
// Contacts: rigid ones (neither part deforms) are solved by impulses in the sub-steps, by
// inverse mass and inertia, with Coulomb friction and restitution per body (contact_solver.hpp
// and body.hpp give the model and the combining rules). The response deforms rigid-deformable
// parts, and a dynamic body pressing one receives the damped force of the displaced springs,
// friction and their torque for the next step (contact_response.hpp). Kinematic bodies are
// swept: they push dynamic bodies, press the deformable parts they cross, and stop at static
// and kinematic rigid parts.
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
// Threads: one world is stepped and read from one thread at a time (a haptic loop and a
// renderer take turns, or the renderer reads a copy). Separate worlds may step on separate
// threads at once, as `flexfit sweep --jobs` runs its scenes: the library shares no mutable
// state between worlds, only per-thread scratch (checked under ThreadSanitizer in CI,
// tests/threads.txt). Once warm, a step allocates no memory (docs/architecture.md).
#pragma once

#include "flexfit/assembly.hpp"
#include "flexfit/body.hpp"
#include "flexfit/collision_world.hpp"
#include "flexfit/profile.hpp"
#include "flexfit/world_settings.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace flexfit {

namespace detail {
struct WorldData;
}

// What the coupling applied to the grabbed body in the last step (world frame).
struct Coupling {
    bool active = false;
    BodyId body = 0;
    Vec3 force = Vec3::Zero();
    Vec3 torque = Vec3::Zero();
};

class World {
public:
    // Throws InputError for invalid settings.
    explicit World(WorldSettings settings = {});
    ~World();
    // A moved-from World holds nothing: it may only be destroyed or assigned to.
    World(World&&) noexcept;
    World& operator=(World&&) noexcept;

    // Adds a part with its rigid-body description; returns its id (0, 1, 2, ...). Dynamic
    // bodies need a closed mesh (their mass and inertia come from its volume). Throws
    // InputError for invalid settings, and then adds nothing.
    BodyId add(std::shared_ptr<const PartModel> model, const PartSettings& part, const BodySettings& body, const Pose& pose);

    std::size_t bodyCount() const;
    // Read-only views (InputError for a missing body, as every call that names one).
    const Part& part(BodyId id) const;
    const RigidBody& body(BodyId id) const;
    const WorldSettings& settings() const;
    // Changes a part's settings while the world runs (Part::setSettings; its contact stiffness
    // follows). Throws InputError for a missing body or invalid settings.
    void setPartSettings(BodyId id, const PartSettings& settings);
    // Opens a zone on a body's part (Part::openZone), e.g. to deform it ahead of a contact. A
    // mass seed names the user's vertex, as below.
    ZoneId openZone(BodyId id, ZoneSeed seed, int level);
    // The stiffness a deformable part opposes to contacts: its mean spring stiffness plus its
    // restoration's (k_a for anchors, c m / h^2 for the constraint at the world's step h). It
    // splits a depth between two deformable parts and scales the reaction a body feels.
    double contactStiffness(BodyId id) const;

    // Forces for the next step (dynamic bodies; ignored otherwise).
    void applyForce(BodyId id, const Vec3& worldForce);                           // at the centre of mass
    void applyForceAt(BodyId id, const Vec3& worldForce, const Vec3& worldPoint);  // adds the torque
    void setVelocity(BodyId id, const Vec3& linear, const Vec3& angular);
    // Kinematic bodies: the pose to reach by the end of the next step (velocity derived).
    // Forces, velocities and poses must be finite (InputError).
    void setKinematicTarget(BodyId id, const Pose& target);

    // --- The operator ---
    // Grabs a dynamic or kinematic body (throws InputError for a static one, or for coupling
    // settings the time step cannot integrate stably); the target starts at its pose.
    void grab(BodyId id, const GrabSettings& settings = {});
    void setGrabTarget(const Pose& target);  // the grabbed body's desired pose
    void release();
    std::optional<BodyId> grabbed() const;
    const Pose& grabTarget() const;
    const Coupling& coupling() const;
    // A world-frame force for the next step on one mass, or spread over a face's three masses.
    // Throws InputError for an index out of range. Here, in kickMass and in openZone a mass is
    // named by the user's vertex index, whatever order the model keeps its masses in (the file's
    // vertex when the read welded or removed some, else the given mesh's: PartModel::massOf),
    // as scenes and the Python module name it; faces keep their indices in every order.
    void applyMassForce(BodyId id, Index vertex, const Vec3& worldForce);
    void applyFaceForce(BodyId id, Index face, const Vec3& worldForce);
    // A velocity kick on one mass (Part::kickMass) of a deforming part; on a part that does not
    // deform, the same momentum (the mass's share, m_i dv) as an impulse at that mass on the
    // rigid body (static and kinematic bodies ignore it). Throws InputError for an index out of
    // range or a non-finite change.
    void kickMass(BodyId id, Index vertex, const Vec3& worldVelocityChange);

    // Assembly rules (assembly.hpp), checked in the assembly stage of every step. When a rule
    // triggers, its primary stops being driven (it becomes kinematic), is brought to its final
    // pose over the snap duration, and then stays attached to the secondary. Throws InputError
    // for unknown bodies or a negative duration.
    std::size_t addAssembly(const AssemblyRule& rule);
    std::size_t assemblyCount() const;  // rules added
    const std::vector<AssemblyEvent>& assemblyEvents() const;
    bool assembled(std::size_t rule) const;

    // One step of the stages above. Divergence is an error, never silent garbage: when a body's
    // pose, velocity, force or torque, or a moving mass of a part, is no longer finite at the
    // end of the step, throws DivergenceError (core.hpp) naming the body, the time at the start
    // of the step and the likely cause (the part's time step above its stability bound, or a
    // force beyond what the model can take). The check costs O(bodies + moving masses); the
    // world then holds that step's state, partly non-finite, and every later step() throws a
    // DivergenceError saying so (and quoting the first) without touching it.
    void step();
    // Optional, before a real-time loop: does now what the first step would do once and then
    // not again, so that the first step costs what the next ones do. The collision world's
    // first query of each pair whose spheres touch (CollisionWorld::warmUp) and the contact
    // response's scratch, sized for every mass. Changes no result: a run with it gives the
    // same states, bit for bit. Call it after adding the parts (a part added later, or a pair
    // that comes into reach later, is warmed by its first step). SceneRun calls it.
    void prepare();
    double time() const;
    std::uint64_t stepCount() const;

    const std::vector<Contact>& contacts() const;  // of the last step's narrow phase
    // What the world noticed and went on with, in order. Today one kind: a deforming part added
    // (or given settings) whose restoration constraint takes the default per-step fraction at a
    // world time step other than the 1 ms it was chosen for, so that it restores faster and
    // resists loads more stiffly than at 1 ms (defaultFractionAt, part.hpp; the text names both
    // factors and the two ways out). A fraction other than the default, or a rate, is taken
    // as chosen; the default value set explicitly cannot be told apart and is reported too.
    // Scene files and Python report the same in their own key names.
    const std::vector<std::string>& warnings() const;
    const Profile& profile() const;
    const CollisionWorld& collision() const;

    // 64-bit FNV-1a over time, every pose, body velocity and part state (part_state.hpp), bit
    // for bit, plus the assembly events: equal hashes mean the same run (determinism tests).
    std::uint64_t stateHash() const;

    // World position of a body's centre of mass.
    Vec3 centreOfMass(BodyId id) const;

private:
    void checkBody(BodyId id, const char* what) const;
    // The mass of a body's user vertex; InputError when it has none.
    Index massOfUserVertex(BodyId id, Index vertex, const char* what) const;
    void applyForceOnMass(BodyId id, Index mass, const Vec3& worldForce);
    std::unique_ptr<detail::WorldData> data_;
};

}  // namespace flexfit
