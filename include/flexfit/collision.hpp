// Collision detection between parts (SPEC 6, thesis 4.3): face hierarchies, the narrow phase
// and contacts.
//
// PartCollider keeps one part's face hierarchy in the part's own frame: a rigid motion never
// touches it (queries carry the relative pose), and a deformation refits only the leaves of
// the faces around masses that moved and their ancestors. Leaf volumes: the face sphere
// (barycentre, radius to the farthest vertex, thesis 4.3) or the face's box.
//
// queryPair() traverses two hierarchies together (descending the larger volume first) and
// tests each overlapping leaf pair exactly:
//   SphereTriangle   (the thesis's test) the face sphere of part A against the triangle of
//                    part B, closest point on the triangle (Ericson 5.1.5);
//   TriangleTriangle the two triangles (separating axes; point, normal, depth), which does not
//                    report sphere-sized false contacts on large faces.
// A contact's normal is a world unit vector: moving part A by depth * normal (or part B by
// the opposite) separates the pair.
#pragma once

#include "flexfit/names.hpp"

#include <array>
#include <limits>
#include <span>

#include "flexfit/bvh.hpp"
#include "flexfit/part.hpp"

#include <variant>

namespace flexfit {

enum class ExactTest { SphereTriangle, TriangleTriangle };
// Its names (names.hpp).
inline constexpr EnumName<ExactTest> kExactTestNames[] = {
    {ExactTest::SphereTriangle, "sphere", "face sphere against triangle"},
    {ExactTest::TriangleTriangle, "triangle", "triangle against triangle"},
};
template <> inline constexpr std::span<const EnumName<ExactTest>> kEnumNames<ExactTest> = kExactTestNames;

inline constexpr Index kNoMass = std::numeric_limits<Index>::max();

struct Contact {
    std::uint32_t partA = 0, partB = 0;
    Index faceA = 0, faceB = 0;
    Vec3 point = Vec3::Zero();   // world
    Vec3 normal = Vec3::UnitY(); // world, unit: pushes A out of B
    double depth = 0.0;
    // Point-shell contacts: the one mass of B inside A (faceB is a face around it; faceA is not
    // looked up and stays 0). kNoMass for face-face contacts.
    Index massB = kNoMass;
};

// The masses a contact presses on one side: the face's three, or `mass` alone when it is not
// kNoMass (a point-shell contact's massB). The span refers to `mass`, which must outlive it.
inline std::span<const Index> pressedMasses(const Face& face, const Index& mass) {
    return mass == kNoMass ? std::span<const Index>(face) : std::span<const Index>(&mass, 1);
}

struct QueryStats {
    std::size_t volumeTests = 0;     // bounding-volume overlap tests (nodes visited in pairs)
    std::size_t candidatePairs = 0;  // leaf pairs whose volumes overlap
    std::size_t exactTests = 0;
    std::size_t contacts = 0;
    QueryStats& operator+=(const QueryStats& o);
};

class PartCollider {
public:
    // `test` decides what the leaves bound: sphere leaves are face spheres either way; box
    // leaves bound the triangle for TriangleTriangle and the face sphere for SphereTriangle
    // (whose exact test uses the sphere, so a box of the triangle could cull true contacts).
    PartCollider(const Part& part, BoundingVolumeKind kind, ExactTest test = ExactTest::TriangleTriangle);

    BoundingVolumeKind kind() const { return kind_; }
    ExactTest exactTest() const { return test_; }
    // Rebuilds the hierarchy from the part's current (part-frame) positions.
    void rebuild(const Part& part);
    // Refits the faces around `changedMasses` from the part's positions, and their ancestors
    // (O(changed x valence x depth)). CollisionWorld refits in its queries, only the
    // hierarchies a face query needs, so a part met only by point-shell queries never pays.
    void refit(const Part& part, std::span<const Index> changedMasses);
    // The bounding sphere's growth: the largest displacement of a moving mass from rest
    // (O(moving)).
    void updateDisplacementBound(const Part& part);
    // Masses at their rest positions in a hierarchy of points, for point-shell queries: the
    // masses at rest never move, so this tree never needs a refit. Empty until built.
    void buildRestPointTree(const Part& part);
    const Bvh<Aabb>& restPointTree() const { return restPoints_; }

    // The part's bounding sphere in its own frame: the thesis's sphere of the rest shape
    // (midpoint of the masses' box, radius to the farthest mass), grown by the largest
    // displacement of a mass from rest. world: transformed by the pose.
    Sphere localSphere() const { return {restSphere_.centre, restSphere_.radius + maxDisplacement_}; }
    Sphere worldSphere(const Part& part) const;

    const Bvh<Sphere>* spheres() const { return std::get_if<Bvh<Sphere>>(&bvh_); }
    const Bvh<Aabb>* boxes() const { return std::get_if<Bvh<Aabb>>(&bvh_); }
    std::size_t refitNodeCount() const;

    // Planes of a face of the rest shape, in the part frame: [0] its own (unit normal n,
    // offset n.a), [1..3] through each edge, perpendicular to it, normals pointing out. The
    // narrow phase's cheap rejection for faces whose masses are at rest: a triangle entirely
    // beyond one of them cannot touch the face.
    const std::array<Eigen::Vector4d, 4>& restPlanes(Index face) const { return restPlanes_[face]; }

private:
    std::vector<std::array<Eigen::Vector4d, 4>> restPlanes_;  // (F)
    BoundingVolumeKind kind_;
    ExactTest test_;
    std::variant<Bvh<Sphere>, Bvh<Aabb>> bvh_;
    Sphere restSphere_;
    double maxDisplacement_ = 0.0;
    IndexSet changedFaces_;  // (F) scratch of refit()
    Bvh<Aabb> restPoints_;
};

// Leaf volumes of a face from part-frame positions.
Sphere faceSphere(std::span<const Vec3> positions, const Face& face);
Aabb faceBox(std::span<const Vec3> positions, const Face& face);
Aabb faceSphereBox(std::span<const Vec3> positions, const Face& face);  // box of the face sphere

// Contacts between parts a and b (ids are written into the contacts). Appends to `contacts`;
// when `candidates` is given, also appends every leaf pair whose volumes overlap (otherwise
// subtrees that lie beyond the planes of an at-rest face of A are pruned, and the statistics
// count what was visited; the contacts are the same either way). Both
// colliders must have been built for `test` (std::invalid_argument otherwise).
void queryPair(std::uint32_t idA, const Part& a, const PartCollider& colliderA, std::uint32_t idB, const Part& b,
               const PartCollider& colliderB, ExactTest test, std::vector<Contact>& contacts, QueryStats& stats,
               std::vector<std::pair<Index, Index>>* candidates = nullptr);

// Point-shell contacts of a rigid part A with part B: every mass of B whose distance sampled
// from A's field (distance_field.hpp) is <= 0 is one contact (massB), with depth = minus that
// distance, point = the mass, normal = minus the field's normalised gradient (so it pushes A
// out of B, as for face contacts). B's moving masses are each sampled; its masses at rest are
// found through restPointsB (PartCollider::restPointTree, built), pruned with the field's Lipschitz
// bound, so the cost follows the masses near A's surface, not the pairs of faces, and needs no
// refit. Faces of A that poke between B's masses are not seen: meant for B finer than A (a
// deformable part against a rigid tool or ball). stats: volumeTests = tree nodes visited,
// candidatePairs = masses reached, exactTests = masses sampled.
class SignedDistanceField;
void queryPointShell(std::uint32_t idA, const Part& a, const SignedDistanceField& fieldA, std::uint32_t idB, const Part& b,
                     const Bvh<Aabb>& restPointsB, std::vector<Contact>& contacts, QueryStats& stats);

}  // namespace flexfit
