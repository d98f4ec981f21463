// Internal to src/world: every response to contacts (world.hpp), in one stage.
//
// Deformable parts: a deformable part in contact gets a zone at each contacted face (its
// contactLevel), and the face's masses (or the one mass of a point-shell contact) are pushed
// out along the contact normal by the depth, their velocity into the contact removed. When both
// parts deform the depth is split by stiffness: part A takes kB / (kA + kB) of it, with k the
// part's effective contact stiffness (effectiveContactStiffness). Each mass moves once, by its
// deepest push.
//
// Reactions: a dynamic body pressing a deformable part feels the springs it displaced. The
// contacted masses sit at x, pushed from their rest positions; the part pulls them back with
// k_eff (rest - x), and through the contact the body receives that force, for the next step. A
// weak push is stopped by a stiff rim; a strong one deforms it and passes. The reaction is
// damped along it (a dashpot c = 2 zeta sqrt(k m_share), zeta the world's contactDamping, m_share
// the body's mass over the masses it presses, capped at m_share / h so the explicit force
// cannot reverse the approach in one step), so a fast ball does not bounce off a stiff rim with
// the energy it brought; it never pulls. Coulomb friction acts against the body's sliding over
// the surface at each mass: the force that stops the sliding in one step while within mu_s
// times the normal force, mu_k times it otherwise; the mass feels the opposite. Both speeds are
// the body's relative to the part moving rigidly: a pushed mass's own velocity comes from the
// restoration, and counting it made a fast ball bounce higher with damping than without. The body gets each force at the
// mass's position, so also its torque, and RigidBody::deformableContactForce reports the sum.
//
// Rigid contacts (neither part deforms) belong to the contact solver (contact_solver.hpp),
// inside the rigid motion's sub-steps.
#pragma once

#include "bodies.hpp"
#include "flexfit/collision.hpp"
#include "flexfit/index_set.hpp"

#include <span>
#include <vector>

namespace flexfit::detail {

// The stiffness a deformable part opposes to a contact: its mean spring stiffness plus its
// restoration's (k_a for anchors, c m / h^2 for the constraint at the world's step h).
double effectiveContactStiffness(const Part& part, double timeStep);

struct ContactResponse {
    std::vector<double> stiffness;  // (nbody) effective contact stiffness

    // Scratch, over the world's masses (Bodies::worldMass): the deepest push of each mass, in
    // first-contact order (three lists parallel to pushed's members: a body's run of them goes
    // to Part::displaceMasses as it is), and the masses whose reaction a body feels.
    IndexSet pushed;
    std::vector<BodyId> pushBodies;
    std::vector<Index> pushMasses;         // the body's own mass index
    std::vector<Vec3> pushDisplacements;   // world frame
    IndexSet reacting;
    std::vector<BodyId> reactionOwner;  // (world masses) the body that last counted each
    struct Reaction {
        BodyId body, part;
        Index mass;
    };
    std::vector<Reaction> reactions;
    std::vector<std::uint32_t> reactionCount;  // (nbody) masses each body presses; valid for the reactions' bodies
};

// Deformable pushes, then the reactions dynamic bodies feel, for the contacts of this step.
// Where every contact is one point-shell pair's (a rigid tool in a deformable part), each names
// its own mass, so each is its mass's push and reaction as it stands: the sets that merge a
// mass's contacts are skipped (on the haptic scene's heaviest steps, a quarter of the stage).
void respondToContacts(const StepContext& step, double dampingRatio, std::span<const Contact> contacts, Bodies& bodies,
                       ContactResponse& response);

// The scratch above sized for every mass of `bodies`: every response calls it once, in
// pushDeformableMasses (a no-op once sized), and World::prepare ahead of the first step. A list's capacity is the world's mass
// count (a reaction list holds a mass once per pressing body, so with several bodies pressing one
// mass it can still grow).
void sizeResponseScratch(const Bodies& bodies, ContactResponse& response);

// The deformable pushes alone (zones at the contacted faces, masses moved out): for a body
// pressing parts in the middle of its sub-steps.
void pushDeformableMasses(std::span<const Contact> contacts, Bodies& bodies, ContactResponse& response);

// While at least one scope is alive (on any thread), every response merges its contacts through
// the sets, one point-shell pair's too: the second implementation the tests compare with.
class ScopedMergedResponse {
public:
    ScopedMergedResponse();
    ~ScopedMergedResponse();
    ScopedMergedResponse(const ScopedMergedResponse&) = delete;
    ScopedMergedResponse& operator=(const ScopedMergedResponse&) = delete;
};

}  // namespace flexfit::detail
