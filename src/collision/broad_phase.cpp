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
    for (const BodyId i : movingIds_) updateBound(i);  // a fixed body's sphere is its sphere at add()
}

void CollisionWorld::update() {
    updatePairs();
    dropStaleCoherence();
}

void CollisionWorld::overlappingLeaves(const Bvh<Sphere>& tree, const Sphere& sphere, std::vector<Index>& items) {
    items.clear();
    const RelativePose identity;
    const auto& nodes = tree.nodes();
    if (nodes.empty()) return;
    stack_.assign(1, 0);
    while (!stack_.empty()) {
        const auto& node = nodes[std::size_t(stack_.back())];
        stack_.pop_back();
        if (!overlap(sphere, node.volume, identity)) continue;
        if (!node.isLeaf()) {
            stack_.push_back(node.right);
            stack_.push_back(node.left);
        } else {
            items.push_back(node.item);
        }
    }
}

void CollisionWorld::buildTree(Bvh<Sphere>& tree, std::span<const BodyId> bodies) {
    treeSpheres_.clear();
    for (const BodyId b : bodies) treeSpheres_.push_back(partSpheres_[b]);
    tree.build(treeSpheres_);
}

void CollisionWorld::buildFixedTree() {
    buildTree(fixedTree_, fixedIds_);
    fixedTreeBuilt_ = true;
}

void CollisionWorld::updatePairs() {
    updateBounds();
    if (!fixedTreeBuilt_) buildFixedTree();
    if (settings_.broadPhase == BroadPhaseUpdate::Rebuild || !broadPhaseBuilt_) {
        buildTree(broadPhase_, movingIds_);
        broadPhaseBuilt_ = true;
    } else {
        broadPhase_.refitAll([&](Index k) { return partSpheres_[movingIds_[k]]; });
    }
    // Each moving body's sphere against the moving tree (its later partners) and the fixed tree.
    pairs_.clear();
    for (std::size_t k = 0; k < movingIds_.size(); ++k) {
        const BodyId i = movingIds_[k];
        overlappingLeaves(broadPhase_, partSpheres_[i], leafItems_);
        for (const Index item : leafItems_)
            if (item > k) pairs_.emplace_back(i, movingIds_[item]);
        overlappingLeaves(fixedTree_, partSpheres_[i], leafItems_);
        for (const Index item : leafItems_) pairs_.emplace_back(std::min(i, fixedIds_[item]), std::max(i, fixedIds_[item]));
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
