// The parts that can touch, their collision hierarchies, and the queries that find their
// contacts (SPEC 6, thesis 4.3). It answers queries and changes nothing but its own caches: the
// parts are registered as read-only views, and every response to a contact (pushing masses,
// moving bodies) belongs to the world's contact-response stage (world.hpp).
//
// Broad phase (thesis 4.3): a hierarchy of the parts' bounding spheres in the world, built
// top-down like the face hierarchies; each part's sphere is tested against it depth-first and
// gives candidate pairs. Moving parts' tree is rebuilt every update by default, or refitted
// bottom-up (BroadPhaseUpdate::Refit, O(moving parts)); fixed parts (Mobility) have a tree of
// their own, built when that set changes. Measured with 200 moving parts (bench/results/
// collision.csv): rebuild 105.6 us, refit 116.5 us per update, because merged spheres are looser
// than the top-down enclosure and the queries then visit more nodes.
//
// Narrow phase: per candidate pair, the two face hierarchies traversed together (collision.hpp),
// or, by default, the pair's candidates from its last traversal while they still cover it
// (queryPairCoherent: exactly the same contacts). The world keeps one PairCoherence per pair
// that a face query has met, and drops those the broad phase has not paired for a while.
// Part A of a pair is the pressing one: the rigid part when exactly one is deformable, otherwise
// the lower id. With ExactTest::SphereTriangle A's faces are spheres and B's triangles.
//
// Shape changes: a deformed part's hierarchy is refitted only when a face query needs it, from
// the part's list of changed masses (Part::changedMasses), once per narrowPhase() or
// contactsOf() call. The collision world never changes a part: refittedBodies() lists the
// bodies the last call refitted, and their owner clears those parts' lists (the world does
// after every call; a list left uncleared is refitted again, which is slower, not wrong).
// collider() never refits: a part met by no face query (point shell only, or alone) keeps the
// hierarchy of its last refit.
#pragma once

#include "flexfit/collision.hpp"
#include "flexfit/distance_field.hpp"

#include <memory>
#include <map>

namespace flexfit {

enum class BroadPhaseUpdate { Refit, Rebuild };
// Its names (names.hpp).
inline constexpr EnumName<BroadPhaseUpdate> kBroadPhaseUpdateNames[] = {
    {BroadPhaseUpdate::Refit, "refit", "refit"},
    {BroadPhaseUpdate::Rebuild, "rebuild", "rebuild"},
};
template <> inline constexpr std::span<const EnumName<BroadPhaseUpdate>> kEnumNames<BroadPhaseUpdate> = kBroadPhaseUpdateNames;

// How a rigid part and a deformable part are tested. Faces: the two face hierarchies, as for
// every other pair. PointShell: the deformable part's masses against the rigid part's signed
// distance field (queryPointShell), built when the rigid part is added (a haptic loop must
// not stall at the first contact); it needs a closed rigid mesh (open ones keep the face
// query) and sees only the masses, so the deformable part should be the finer of the two. Its
// cost follows the masses near the rigid surface, which is what lets a ball press a
// 7,300-mass rim at haptic rates. The rigid part's sharp faces at the deformable part's scale
// are tested as faces too (querySharpFeatures), so no edge or corner slips between masses.
// Auto: the point shell for a pair whose rigid part is closed and whose deformable part is the
// finer (mean rest edge strictly shorter than the rigid part's), the face query otherwise;
// fields are built only for rigid parts some deformable part is finer than, and a rigid part's
// sharp features are found at the scale of the coarsest deformable part its point shell serves.
enum class RigidDeformableQuery { Faces, PointShell, Auto };
// Its names (names.hpp).
inline constexpr EnumName<RigidDeformableQuery> kRigidDeformableQueryNames[] = {
    {RigidDeformableQuery::Faces, "faces", "face hierarchies"},
    {RigidDeformableQuery::PointShell, "point-shell", "point shell"},
    {RigidDeformableQuery::Auto, "auto", "point shell where the deformable part is finer, else faces"},
};
template <> inline constexpr std::span<const EnumName<RigidDeformableQuery>> kEnumNames<RigidDeformableQuery> = kRigidDeformableQueryNames;

// How a body takes part in the broad phase. Fixed: its part neither moves nor deforms (a
// static rigid body; the caller keeps it so). Its sphere is computed once, it sits in a tree of
// the fixed bodies built when that set changes, and two fixed bodies are never a candidate pair
// (neither could respond to a contact), so a world of many fixed parts costs each update
// O(moving parts x log(fixed parts)), not a rebuild over every part. The world fixes its
// static rigid bodies, except an assembly's primary (a snap moves it).
enum class Mobility { Moving, Fixed };

struct CollisionSettings {
    ExactTest exactTest = ExactTest::TriangleTriangle;
    BroadPhaseUpdate broadPhase = BroadPhaseUpdate::Rebuild;
    RigidDeformableQuery rigidDeformable = RigidDeformableQuery::Auto;
    // Queries start from what the pair's last query found (queryPairCoherent,
    // queryPointShellCoherent): the same contacts as full ones, at the cost of what may touch
    // while the pair moves little. Measured: a ball resting on a deforming mouth 2x faster; a
    // part deforming fast under a tool 5-16 % slower, with tails up to 1.6x (false: plain).
    bool coherent = true;
};

class CollisionWorld {
public:
    explicit CollisionWorld(CollisionSettings settings = {});

    // Registers body `id` with a read-only view of its part, which must outlive the collision
    // world. Ids come in order, 0, 1, 2, ... (the world's body ids); throws
    // std::invalid_argument otherwise, or for a Fixed part that deforms.
    void add(BodyId id, const Part& part, BoundingVolumeKind kind = BoundingVolumeKind::Aabb, Mobility mobility = Mobility::Moving);
    // A fixed body becomes a moving one from the next update on (its part is about to move).
    void setMoving(BodyId id);
    bool fixed(BodyId id) const { return fixed_[id]; }
    std::size_t bodyCount() const { return parts_.size(); }
    // The body's collider as of its last refit. Reading it changes nothing.
    const PartCollider& collider(BodyId id) const { return colliders_[id]; }
    const CollisionSettings& settings() const { return settings_; }
    // Switches the exact test; the face hierarchies are rebuilt for it.
    void setExactTest(ExactTest test);

    // --- Broad phase (broad_phase.cpp) ---
    // Updates every moving body's bounding sphere, then the broad-phase trees and their pairs.
    void update();
    // Updates every moving body's bounding sphere (the first half of update()), or one body's.
    void updateBounds();
    void updateBound(BodyId id);
    // Broad-phase candidate pairs (a < b), from the last update.
    const std::vector<std::pair<BodyId, BodyId>>& candidatePairs() const { return pairs_; }
    // The broad phase's hierarchies of part spheres (world frame), as of the last update (parts
    // added since are in them from the next update on): the moving bodies' and the fixed
    // bodies'. A leaf's item is the body's place among the moving or the fixed bodies, in id order.
    const Bvh<Sphere>& broadPhaseTree() const { return broadPhase_; }
    const Bvh<Sphere>& fixedBroadPhaseTree() const { return fixedTree_; }

    // --- Narrow phase (narrow_phase.cpp) ---
    // Contacts already found at the current poses: contactsOf(body, true)'s answer. The narrow
    // phase copies them for those pairs instead of querying them again.
    struct KnownContacts {
        BodyId body = 0;
        std::span<const Contact> contacts;
    };
    // The contacts of the candidate pairs of the last update(). Part A of a pair is the
    // pressing one: the rigid part when exactly one is deformable, otherwise the lower id.
    // Pairs covered by `known` are not queried (stats() does not count them).
    const std::vector<Contact>& narrowPhase(const KnownContacts* known = nullptr);
    // update(), then narrowPhase(): for a caller without a world.
    const std::vector<Contact>& findContacts();
    // The contacts of one body with every body whose sphere touches its own, without updating
    // the broad-phase tree or querying other pairs: for a body moving in sub-steps while the
    // others wait. Same pairs and order as update() + narrowPhase() restricted to that body;
    // with rigidPartnersOnly, pairs with deformable parts are skipped. std::invalid_argument
    // for a body not added.
    const std::vector<Contact>& contactsOf(BodyId id, bool rigidPartnersOnly = false);
    // update(), then every candidate pair's query run for its coherence alone: what the pair's
    // first query would traverse (a point shell's walk of the rest masses near the rigid part,
    // a face pair's traversal) is done now, at the current poses, so that the next
    // narrowPhase() starts from it. Contacts, stats(), contacts() and the query counters are
    // left as they were; the next narrowPhase() gives the contacts it would have given without.
    // For a real-time loop: the haptic scene's first step cost 1.0-1.6 ms without it. Without
    // coherent queries there is nothing to keep, and it does nothing. The point shell's scratch
    // is per thread: warm up on the thread that steps.
    void warmUp();
    const std::vector<Contact>& contacts() const { return contacts_; }  // of the last narrowPhase()
    const QueryStats& stats() const { return stats_; }                  // of the last narrowPhase()
    // The bodies whose hierarchy the last narrowPhase() or contactsOf() refitted from their
    // part's changed masses: those parts' lists can be cleared (Part::clearChangedMasses).
    std::span<const BodyId> refittedBodies() const { return refitted_.members(); }
    // Face queries answered so far, and how many of them needed a traversal: every plain
    // query; a coherent one when it took a list, or when the pair moved too fast for lists and
    // a whole traversal answered (queryPairCoherent); the other coherent queries scanned the
    // pair's candidates. A point-shell pair's sharp faces count as one face query, always
    // traversed.
    std::uint64_t faceQueries() const { return faceQueries_; }
    std::uint64_t faceTraversals() const { return faceTraversals_; }

private:
    bool pressesFirst(BodyId a, BodyId b) const;
    // Whether the settings let the point shell answer a rigid part against a deformable part,
    // given their mean rest edges (Auto: the deformable part strictly finer).
    bool pointShellServes(double rigidMeanEdge, double deformableMeanEdge) const;
    // add()'s parts (collision_world.cpp): what a new part changes in the point shell's
    // service, built before anything is registered; a rigid part's field and features for it;
    // room in every registry vector for `bodies`.
    struct ServiceEntry;
    struct ServiceChange;
    ServiceChange serviceChange(const Part& part, double meanEdge, double resolution) const;
    void equip(ServiceEntry& entry, const Part& rigid, bool serves) const;
    void reserveRegistry(std::size_t bodies, bool deforms);
    // Whether the pair (a presses b) is answered by the point shell.
    bool usesPointShell(BodyId a, BodyId b) const;
    // The point shell's contacts of the pair (a rigid with a field, b deforming), with those of
    // a's sharp faces.
    void queryPointShellPair(BodyId a, BodyId b, std::vector<Contact>& out, QueryStats& stats);
    // Contacts of the pair (a presses b) appended to `out`, by the query the settings choose.
    void queryPair(BodyId a, BodyId b, std::vector<Contact>& out, QueryStats& stats);
    // update() without its bookkeeping: the spheres, the tree and the candidate pairs.
    void updatePairs();
    // Forgets the coherence of pairs no query has used lately (broad_phase.cpp).
    void dropStaleCoherence();
    // Refits the body's hierarchy from its part's changed masses, once per query call.
    void refitChanged(BodyId id);

    CollisionSettings settings_;
    std::vector<const Part*> parts_;                                  // (nbody)
    std::vector<PartCollider> colliders_;                             // (nbody)
    std::vector<std::shared_ptr<const SignedDistanceField>> fields_;  // (nbody) rigid closed parts the point shell may serve; else null
    std::vector<std::shared_ptr<const SharpFeatures>> features_;      // (nbody) beside each field, at the scale of the parts it serves
    std::vector<double> meanEdge_;                                    // (nbody) mean rest edge length
    std::vector<double> restResolution_;  // (nbody) of deformable parts the point shell may serve (restResolution), else 0
    std::vector<bool> fieldTried_;        // (nbody) a field was built, or the mesh has no inside
    std::vector<Sphere> partSpheres_;                                 // (nbody) world frame
    std::vector<BodyId> rigidParts_, deformingParts_;                 // the bodies of each kind, in order (add() pairs only across them)
    std::vector<bool> fixed_;                                         // (nbody) Mobility::Fixed
    std::vector<BodyId> movingIds_, fixedIds_;                        // the bodies of each mobility, in order (room for every body)
    std::vector<Sphere> treeSpheres_;                                 // scratch: the spheres a tree is built over
    std::vector<BodyId> partners_;                                    // scratch: contactsOf's bodies in reach
    Bvh<Sphere> fixedTree_;
    bool fixedTreeBuilt_ = false;
    Bvh<Sphere> broadPhase_;        // the moving bodies' spheres
    bool broadPhaseBuilt_ = false;  // for the parts added so far (add() leaves it to the next update: adding n parts builds it once)
    // The items of the leaves of `tree` whose spheres overlap `sphere`, depth-first, into
    // `items` (cleared first).
    void overlappingLeaves(const Bvh<Sphere>& tree, const Sphere& sphere, std::vector<Index>& items);
    std::vector<Index> leafItems_;  // scratch of overlappingLeaves' callers
    void buildTree(Bvh<Sphere>& tree, std::span<const BodyId> bodies);  // over those bodies' spheres
    void buildFixedTree();
    std::vector<std::pair<BodyId, BodyId>> pairs_;
    std::vector<Contact> contacts_;
    std::vector<Contact> bodyContacts_;  // contactsOf()
    std::vector<std::int32_t> stack_;    // broad-phase traversal
    IndexSet refitted_;                  // (nbody) refitted by the last query call
    QueryStats stats_;
    // A face pair of two rigid parts (neither deforms: their shapes are the models') keeps its
    // last answer with the poses it was found at; while both poses stay bit for bit the same,
    // the answer is the query's (its contacts, in order) and no query runs. Bodies at rest
    // meet each other at the same poses between a step's sub-step queries, the rigid motion's
    // settling and the narrow phase: a resting stack's pairs are each queried once a step.
    struct Answer {
        bool kept = false;
        Pose poseA, poseB;
        std::vector<Contact> contacts;
    };
    struct KeptCoherence {
        PairCoherence coherence;
        PointShellCoherence pointShell;
        Answer answer;                 // coherent face queries of two rigid parts
        std::uint64_t lastUpdate = 0;  // the update() count when last used
    };
    // Whether the pair's kept answer stands at the parts' current poses; keeps `found` (the
    // contacts just appended) as its answer otherwise, when both parts are rigid.
    bool answerStands(const Answer& answer, BodyId a, BodyId b) const;
    void keepAnswer(Answer& answer, BodyId a, BodyId b, std::span<const Contact> found) const;
    std::map<std::uint64_t, KeptCoherence> coherence_;  // by (a << 32 | b), a presses b (ordered: no hash order in a step)
    std::uint64_t updates_ = 0;
    std::uint64_t faceQueries_ = 0, faceTraversals_ = 0;
};

}  // namespace flexfit
