// The broad phase (collision_world.hpp): each body's bounding sphere, the hierarchy of those
// spheres, and the pairs whose spheres overlap.
#include "flexfit/collision_world.hpp"

#include <algorithm>

namespace flexfit {

void CollisionWorld::updateBound(BodyId id) {
    colliders_[id].updateDisplacementBound(*parts_[id]);
    partSpheres_[id] = colliders_[id].worldSphere(*parts_[id]);
}

void CollisionWorld::updateBounds() {
    for (BodyId i = 0; i < parts_.size(); ++i) updateBound(i);
}

void CollisionWorld::update() {
    updatePairs();
    dropStaleCoherence();
}

void CollisionWorld::updatePairs() {
    updateBounds();
    if (settings_.broadPhase == BroadPhaseUpdate::Rebuild || !broadPhaseBuilt_) {
        broadPhase_.build(partSpheres_);
        broadPhaseBuilt_ = true;
    } else
        broadPhase_.refitAll([&](Index i) { return partSpheres_[i]; });
    // Each body's sphere against the tree, depth-first.
    pairs_.clear();
    const RelativePose identity;
    const auto& nodes = broadPhase_.nodes();
    for (BodyId i = 0; i < partSpheres_.size(); ++i) {
        stack_.assign(1, 0);
        while (!stack_.empty()) {
            const auto& node = nodes[std::size_t(stack_.back())];
            stack_.pop_back();
            if (!overlap(partSpheres_[i], node.volume, identity)) continue;
            if (!node.isLeaf()) {
                stack_.push_back(node.right);
                stack_.push_back(node.left);
            } else if (node.item > i) {
                pairs_.emplace_back(i, node.item);
            }
        }
    }
    std::sort(pairs_.begin(), pairs_.end());
}

// A pair unused for this many updates loses its coherence (it is rebuilt by one traversal if
// it comes back).
constexpr std::uint64_t kCoherenceKeptFor = 64;

void CollisionWorld::dropStaleCoherence() {
    ++updates_;
    if (updates_ % kCoherenceKeptFor != 0) return;
    std::erase_if(coherence_, [&](const auto& entry) { return updates_ - entry.second.lastUpdate > kCoherenceKeptFor; });
}

}  // namespace flexfit
