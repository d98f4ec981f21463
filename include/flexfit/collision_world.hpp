// The parts that can touch, their collision hierarchies, the broad phase, and the response
// of rigid-deformable parts to contacts (SPEC 6, thesis 4.3).
//
// Broad phase (thesis 4.3): a hierarchy of the parts' bounding spheres in the world, built
// top-down like the face hierarchies; each part's sphere is tested against it depth-first and
// gives candidate pairs. Parts move every step: the tree is rebuilt by default, or refitted
// bottom-up (BroadPhaseUpdate::Refit, O(parts)). Measured with 200 moving parts (bench/results/
// collision.csv): rebuild 105.6 us, refit 116.5 us per update, because merged spheres are looser
// than the top-down enclosure and the queries then visit more nodes.
//
// Narrow phase: per candidate pair, the two face hierarchies traversed together (collision.hpp).
// Part A of a pair is the pressing one: the rigid part when exactly one is deformable, otherwise
// the lower id. With ExactTest::SphereTriangle A's faces are spheres and B's triangles.
//
// Response (respond()): a deformable part in contact gets a zone at each contacted face
// (contactLevel) and the face's masses are pushed out along the contact normal by the depth,
// their velocity into the contact removed. When both parts deform, the depth is split by
// stiffness: part A takes kB / (kA + kB) of it, with k the part's effective stiffness (mean
// spring stiffness plus the restoration's: k_a for anchors, c m / h^2 for the constraint).
// Each mass moves once per response, by its deepest contact. Rigid-rigid contacts are only
// reported (the world's rigid dynamics resolve them).
#pragma once

#include "flexfit/collision.hpp"
#include "flexfit/distance_field.hpp"
#include "flexfit/epoch_marks.hpp"

#include <memory>

namespace flexfit {

enum class BroadPhaseUpdate { Refit, Rebuild };

// How a rigid part and a deformable part are tested. Faces: the two face hierarchies, as for
// every other pair. PointShell: the deformable part's masses against the rigid part's signed
// distance field (queryPointShell), built when the rigid part is added (a haptic loop must
// not stall at the first contact); it needs a closed rigid mesh (open ones keep the face query) and sees only the masses,
// so the deformable part should be the finer of the two. Its cost follows the masses near the
// rigid surface, which is what lets a ball press a 7,300-mass rim at haptic rates.
enum class RigidDeformableQuery { Faces, PointShell };
const char* toString(RigidDeformableQuery query);

struct CollisionSettings {
    ExactTest exactTest = ExactTest::TriangleTriangle;
    BroadPhaseUpdate broadPhase = BroadPhaseUpdate::Rebuild;
    RigidDeformableQuery rigidDeformable = RigidDeformableQuery::Faces;
};

struct ResponseStats {
    std::size_t contacts = 0;         // contacts that moved a deformable part
    std::size_t displacedMasses = 0;
    double maxDisplacement = 0.0;
};

class CollisionWorld {
public:
    explicit CollisionWorld(CollisionSettings settings = {});

    // Registers a part (it must outlive the world); returns its id, 0, 1, 2, ...
    std::uint32_t add(Part& part, BoundingVolumeKind kind = BoundingVolumeKind::Aabb);
    std::size_t partCount() const { return parts_.size(); }
    Part& part(std::uint32_t id) { return *parts_[id]; }
    // The part's collider, its face hierarchy refitted to the current shape (refits are lazy:
    // done when a face query or this call needs them).
    const PartCollider& collider(std::uint32_t id);
    const CollisionSettings& settings() const { return settings_; }
    // Switches the exact test; the face hierarchies are rebuilt for it.
    void setExactTest(ExactTest test);

    // Updates each part's bounding sphere, then the broad phase. Face hierarchies are refitted
    // lazily, from the part's change list, when collider() is asked for them.
    void update();
    // Broad-phase candidate pairs (a < b), from the last update.
    const std::vector<std::pair<std::uint32_t, std::uint32_t>>& candidatePairs() const { return pairs_; }
    // update(), then the narrow phase over the candidate pairs.
    const std::vector<Contact>& findContacts();
    // The narrow phase alone, over the candidate pairs of the last update.
    const std::vector<Contact>& narrowPhase();
    // Updates every part's bounding sphere (the first half of update()).
    void updateBounds();
    // The contacts of one part with every part whose sphere touches its own, without updating
    // the broad-phase tree or querying other pairs: for a body moving in sub-steps while the
    // others wait. Same pairs and order as update() + narrowPhase() restricted to that part;
    // with rigidPartnersOnly, pairs with deformable parts are skipped (the world's rigid
    // projection only needs the others).
    const std::vector<Contact>& contactsOf(std::uint32_t id, bool rigidPartnersOnly = false);
    const std::vector<Contact>& contacts() const { return contacts_; }
    // The broad phase's hierarchy of part spheres (world frame), as of the last update.
    const Bvh<Sphere>& broadPhaseTree() const { return broadPhase_; }
    const QueryStats& stats() const { return stats_; }  // of the last findContacts()

    ResponseStats respond(std::span<const Contact> contacts);
    double effectiveStiffness(std::uint32_t id) const { return stiffness_[id]; }
    // After a part's settings changed (its restoration adds to the effective stiffness).
    void refreshStiffness(std::uint32_t id);

private:
    void updateBroadPhase();
    bool pressesFirst(std::uint32_t a, std::uint32_t b) const;
    // Contacts of the pair (a presses b) appended to `out`, by the query the settings choose.
    void queryCandidates(std::uint32_t a, std::uint32_t b, std::vector<Contact>& out, QueryStats& stats);

    CollisionSettings settings_;
    std::vector<Part*> parts_;
    std::vector<PartCollider> colliders_;
    std::vector<double> stiffness_;
    std::vector<std::shared_ptr<const SignedDistanceField>> fields_;  // rigid closed parts, PointShell; else null
    Bvh<Sphere> broadPhase_;
    std::vector<Sphere> partSpheres_;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs_;
    std::vector<Contact> contacts_;
    std::vector<Contact> partContacts_;  // contactsOf()
    // respond(): (part << 32 | mass, deepest displacement), and per part the masses pushed in
    // this call and each one's slot in pushes_.
    std::vector<std::pair<std::uint64_t, Vec3>> pushes_;
    std::vector<EpochMarks> pushedMarks_;
    std::vector<std::vector<Index>> pushSlot_;
    QueryStats stats_;
};

}  // namespace flexfit
