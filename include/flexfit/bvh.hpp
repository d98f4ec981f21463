// A bounding-volume hierarchy over items (faces of a part, or parts of a scene), generic over
// the volume (Sphere or Aabb).
//
// Built top-down as the thesis does (4.3): the root encloses every item; a node splits its
// items at the centre of their centres' bounding box along its longest axis (at the median
// when that leaves a side empty), down to one item per leaf. Nodes live in one array, children
// after their parent, with parent links for refits.
//
// refit() updates the leaves of the items that changed and then their ancestors bottom-up, and
// stops climbing where a volume came out unchanged (a leaf moving inside its parent's box), so
// a local deformation costs O(changed x the depth its changes reach), at most O(changed x
// depth), not O(items). The result is the same as refitting every ancestor: a node is
// recomputed whenever one of its children changed. The dirty ancestors are a compact index set
// and a heap by node index (children come after their parent): a refit allocates nothing once
// it has grown.
#pragma once

#include "flexfit/bounding_volume.hpp"
#include "flexfit/index_set.hpp"

#include <algorithm>
#include <cstdint>
#include <functional>
#include <numeric>
#include <vector>

namespace flexfit {

// Volume enclosing a set of child volumes, as the top-down build makes it.
Sphere encloseAll(std::span<const Sphere> volumes, std::span<const Index> which);
Aabb encloseAll(std::span<const Aabb> volumes, std::span<const Index> which);
inline Sphere mergeVolumes(const Sphere& a, const Sphere& b) { return Sphere::merge(a, b); }
inline Aabb mergeVolumes(const Aabb& a, const Aabb& b) { return Aabb::merge(a, b); }
inline bool sameVolume(const Sphere& a, const Sphere& b) { return a.centre == b.centre && a.radius == b.radius; }
inline bool sameVolume(const Aabb& a, const Aabb& b) { return a.min == b.min && a.max == b.max; }
inline Vec3 centreOf(const Sphere& s) { return s.centre; }
inline Vec3 centreOf(const Aabb& b) { return b.centre(); }

template <class BV>
class Bvh {
public:
    struct Node {
        BV volume;
        std::int32_t left = -1;   // child indices; -1 for a leaf
        std::int32_t right = -1;
        std::int32_t parent = -1;
        Index item = 0;           // the leaf's item
        std::uint16_t depth = 0;
        bool isLeaf() const { return left < 0; }
    };

    // Builds over items 0..n-1 with the given leaf volumes.
    void build(std::span<const BV> leafVolumes) {
        nodes_.clear();
        leafOf_.assign(leafVolumes.size(), 0);
        if (leafVolumes.empty()) return;
        nodes_.reserve(2 * leafVolumes.size());
        std::vector<Index> items(leafVolumes.size());
        std::iota(items.begin(), items.end(), Index(0));
        buildNode(leafVolumes, items, 0, items.size(), -1, 0);
        dirty_.reset(nodes_.size());
    }

    // Leaves of `items` get new volumes from leafVolume(item); their ancestors are refitted as
    // far as the changes reach.
    template <class LeafVolume>
    void refit(std::span<const Index> items, LeafVolume leafVolume) {
        if (nodes_.empty()) return;
        dirty_.clear();
        heap_.clear();
        auto markParent = [&](const Node& node) {
            if (node.parent >= 0 && dirty_.insert(Index(node.parent))) {
                heap_.push_back(node.parent);
                std::push_heap(heap_.begin(), heap_.end());
            }
        };
        for (Index item : items) {
            Node& leaf = nodes_[leafOf_[item]];
            const BV volume = leafVolume(item);
            ++refitNodes_;
            if (sameVolume(volume, leaf.volume)) continue;
            leaf.volume = volume;
            markParent(leaf);
        }
        // Highest index first: every child of a node is done before it.
        while (!heap_.empty()) {
            std::pop_heap(heap_.begin(), heap_.end());
            Node& node = nodes_[std::size_t(heap_.back())];
            heap_.pop_back();
            const BV volume = mergeVolumes(nodes_[std::size_t(node.left)].volume, nodes_[std::size_t(node.right)].volume);
            ++refitNodes_;
            if (sameVolume(volume, node.volume)) continue;
            node.volume = volume;
            markParent(node);
        }
    }

    // Every leaf from leafVolume(item), then every internal node, bottom-up.
    template <class LeafVolume>
    void refitAll(LeafVolume leafVolume) {
        for (std::size_t i = nodes_.size(); i-- > 0;) {
            Node& node = nodes_[i];
            node.volume = node.isLeaf() ? leafVolume(node.item)
                                        : mergeVolumes(nodes_[std::size_t(node.left)].volume, nodes_[std::size_t(node.right)].volume);
        }
        refitNodes_ += nodes_.size();
    }

    const std::vector<Node>& nodes() const { return nodes_; }
    const BV& leafVolume(Index item) const { return nodes_[leafOf_[item]].volume; }
    bool empty() const { return nodes_.empty(); }
    const BV& rootVolume() const { return nodes_.front().volume; }
    std::size_t refitNodeCount() const { return refitNodes_; }  // nodes recomputed by refits so far

private:
    std::int32_t buildNode(std::span<const BV> leaves, std::vector<Index>& items, std::size_t begin, std::size_t end,
                           std::int32_t parent, std::uint16_t depth) {
        const auto index = std::int32_t(nodes_.size());
        nodes_.push_back({});
        nodes_.back().parent = parent;
        nodes_.back().depth = depth;
        const std::span<const Index> range(items.data() + begin, end - begin);
        if (end - begin == 1) {
            nodes_[std::size_t(index)].volume = leaves[items[begin]];
            nodes_[std::size_t(index)].item = items[begin];
            leafOf_[items[begin]] = Index(index);
            return index;
        }
        nodes_[std::size_t(index)].volume = encloseAll(leaves, range);
        const std::size_t middle = split(leaves, items, begin, end);
        const std::int32_t left = buildNode(leaves, items, begin, middle, index, std::uint16_t(depth + 1));
        const std::int32_t right = buildNode(leaves, items, middle, end, index, std::uint16_t(depth + 1));
        nodes_[std::size_t(index)].left = left;
        nodes_[std::size_t(index)].right = right;
        return index;
    }

    // Splits at the centre of the centres' bounds, along its longest axis.
    static std::size_t split(std::span<const BV> leaves, std::vector<Index>& items, std::size_t begin, std::size_t end) {
        Eigen::AlignedBox3d centres;
        for (std::size_t i = begin; i < end; ++i) centres.extend(centreOf(leaves[items[i]]));
        int axis = 0;
        centres.sizes().maxCoeff(&axis);
        const double cut = centres.center()[axis];
        auto first = items.begin() + std::ptrdiff_t(begin), last = items.begin() + std::ptrdiff_t(end);
        auto middle = std::partition(first, last, [&](Index i) { return centreOf(leaves[i])[axis] < cut; });
        if (middle == first || middle == last) {  // all centres on one side: median split
            middle = first + (last - first) / 2;
            std::nth_element(first, middle, last,
                             [&](Index x, Index y) { return centreOf(leaves[x])[axis] < centreOf(leaves[y])[axis]; });
        }
        return std::size_t(middle - items.begin());
    }

    std::vector<Node> nodes_;
    std::vector<Index> leafOf_;          // item -> leaf node
    IndexSet dirty_;                     // (nodes) ancestors to merge in a refit
    std::vector<std::int32_t> heap_;     // the same, by index (max-heap)
    std::size_t refitNodes_ = 0;
};

}  // namespace flexfit
