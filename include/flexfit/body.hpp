// A world's bodies: how each moves (SPEC 7-8, thesis 4.4).
//
// Motion types: Static (never moves), Kinematic (moved by the caller or the operator: its pose
// is set, its velocity derived), Dynamic (gravity, forces and torques, inertia from the mesh at
// the body's density). Every body is a Part, so any motion type combines with any deformation
// mode (rigid, rigid-deformable, full-deformable). A body's id is its index in the world, 0, 1,
// 2, ... in the order added: the world and its collision side use the same id.
//
// Contact materials (world.hpp, "Contacts"): Coulomb friction with a static and a kinetic
// coefficient, and restitution, per body. A pair combines them as Box2D and Jolt do: friction
// by the geometric mean sqrt(mu_a mu_b) (a frictionless body makes every contact with it
// frictionless), restitution by the larger of the two (a bouncy ball bounces off a dull floor).
#pragma once

#include "flexfit/names.hpp"
#include "flexfit/bounding_volume.hpp"
#include "flexfit/part_model.hpp"

#include <cstdint>

namespace flexfit {

enum class MotionType { Static, Kinematic, Dynamic };
// Its names (names.hpp).
inline constexpr EnumName<MotionType> kMotionTypeNames[] = {
    {MotionType::Static, "static", "static"},
    {MotionType::Kinematic, "kinematic", "kinematic"},
    {MotionType::Dynamic, "dynamic", "dynamic"},
};
template <> inline constexpr std::span<const EnumName<MotionType>> kEnumNames<MotionType> = kMotionTypeNames;

struct BodySettings {
    MotionType motion = MotionType::Static;
    double density = 1.0;                  // mass = density x enclosed volume (dynamic bodies)
    Vec3 linearVelocity = Vec3::Zero();    // initial, world (m/s)
    Vec3 angularVelocity = Vec3::Zero();   // initial, world (rad/s)
    double thickness = 0.0;                // for the no-tunnelling bound; 0: smallest box half-extent
    BoundingVolumeKind boundingVolume = BoundingVolumeKind::Aabb;
    double staticFriction = 0.0;           // Coulomb, while the contact sticks (>= kinetic)
    double kineticFriction = 0.0;          // Coulomb, while it slides
    double restitution = 0.0;              // 0: inelastic, 1: elastic (normal speed kept)
};

// The rigid-body state of one body. Mass properties are fixed when the body is added; the
// velocities and accumulated loads change every step.
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
    double staticFriction = 0.0, kineticFriction = 0.0, restitution = 0.0;
    // The force (world) deformable parts pressed on the body in the last step: their springs'
    // reaction, its damping and friction (contact_response). Zero without such contact.
    Vec3 deformableContactForce = Vec3::Zero();
};

// A body's rigid description from its model and settings: mass and inertia from the closed
// mesh's volume at the settings' density (dynamic bodies; InputError for an open or inside-out
// mesh), thickness, bounding radius, initial velocities. Throws InputError for a density that
// is not finite and positive, or for non-finite velocities or thickness.
RigidBody makeRigidBody(const PartModel& model, const BodySettings& settings);

}  // namespace flexfit
