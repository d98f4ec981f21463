// The collision world's registry and settings (collision_world.hpp); its stages are in
// broad_phase.cpp and narrow_phase.cpp.
#include "flexfit/collision_world.hpp"

#include <stdexcept>
#include <string>

namespace flexfit {
namespace {


// nullptr for a mesh with no inside (open, inconsistently oriented, inside out): the face
// query, which needs none, serves it.
std::shared_ptr<const SignedDistanceField> buildDistanceField(const Part& part) {
    try {
        return std::make_shared<SignedDistanceField>(part.model().mesh, part.model().topology);
    } catch (const std::invalid_argument&) {
        return nullptr;
    }
}

}  // namespace

CollisionWorld::CollisionWorld(CollisionSettings settings) : settings_(settings) {}

void CollisionWorld::add(BodyId id, const Part& part, BoundingVolumeKind kind) {
    if (id != parts_.size())
        throw std::invalid_argument("CollisionWorld::add: body " + std::to_string(id) + " out of order (expected " +
                                    std::to_string(parts_.size()) + ")");
    // Everything is built before anything is registered: a failure (out of memory) leaves the
    // collision world as it was. Fields and rest-point trees are built now rather than at the
    // first contact, where they would stall a haptic loop.
    PartCollider collider(part, kind, settings_.exactTest);
    const bool pointShell = settings_.rigidDeformable == RigidDeformableQuery::PointShell;
    std::shared_ptr<const SignedDistanceField> field = pointShell && !part.deforms() ? buildDistanceField(part) : nullptr;
    if (pointShell && part.deforms()) collider.buildRestPointTree(part);
    std::vector<Sphere> spheres = partSpheres_;
    spheres.push_back(collider.worldSphere(part));
    Bvh<Sphere> tree;
    tree.build(spheres);  // the tree's shape changes with the set of parts
    const std::size_t n = parts_.size() + 1;
    parts_.reserve(n);
    colliders_.reserve(n);
    fields_.reserve(n);
    refitted_.growTo(n);
    // Nothing below throws.
    parts_.push_back(&part);
    colliders_.push_back(std::move(collider));
    fields_.push_back(std::move(field));
    partSpheres_ = std::move(spheres);
    broadPhase_ = std::move(tree);
}

void CollisionWorld::setExactTest(ExactTest test) {
    if (test == settings_.exactTest) return;
    settings_.exactTest = test;
    for (std::size_t i = 0; i < parts_.size(); ++i) {
        PartCollider rebuilt(*parts_[i], colliders_[i].kind(), test);
        if (!colliders_[i].restPointTree().empty()) rebuilt.buildRestPointTree(*parts_[i]);
        colliders_[i] = std::move(rebuilt);
    }
    coherence_.clear();  // the candidates were of the old hierarchies
}

bool CollisionWorld::pressesFirst(BodyId a, BodyId b) const {
    const bool da = parts_[a]->deforms(), db = parts_[b]->deforms();
    return da == db ? a < b : !da;
}

}  // namespace flexfit
