// The collision world's registry and settings (collision_world.hpp); its stages are in
// broad_phase.cpp and narrow_phase.cpp.
#include "flexfit/collision_world.hpp"

#include <stdexcept>
#include <string>

namespace flexfit {
namespace {

bool deformable(const Part& p) { return p.mode() != PartMode::Rigid; }

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
    parts_.push_back(&part);
    colliders_.emplace_back(part, kind, settings_.exactTest);
    // Fields and rest-point trees are built now rather than at the first contact, where they
    // would stall a haptic loop.
    const bool pointShell = settings_.rigidDeformable == RigidDeformableQuery::PointShell;
    fields_.push_back(pointShell && !deformable(part) ? buildDistanceField(part) : nullptr);
    if (pointShell && deformable(part)) colliders_.back().buildRestPointTree(part);
    partSpheres_.push_back(colliders_.back().worldSphere(part));
    refitted_.growTo(parts_.size());
    broadPhase_.build(partSpheres_);  // the tree's shape changes with the set of parts
}

void CollisionWorld::setExactTest(ExactTest test) {
    if (test == settings_.exactTest) return;
    settings_.exactTest = test;
    for (std::size_t i = 0; i < parts_.size(); ++i) {
        PartCollider rebuilt(*parts_[i], colliders_[i].kind(), test);
        if (!colliders_[i].restPointTree().empty()) rebuilt.buildRestPointTree(*parts_[i]);
        colliders_[i] = std::move(rebuilt);
    }
}

bool CollisionWorld::pressesFirst(BodyId a, BodyId b) const {
    const bool da = deformable(*parts_[a]), db = deformable(*parts_[b]);
    return da == db ? a < b : !da;
}

}  // namespace flexfit
