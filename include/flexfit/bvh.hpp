// A bounding-volume hierarchy over items (faces of a part, or parts of a scene), generic over
// the volume (Sphere or Aabb).
//
// Built top-down as the thesis does (4.3): the root encloses every item; a node splits its
// items at the centre of their centres' bounding box along its longest axis (at the median
// when that leaves a side empty), down to one item per leaf. Split::SurfaceArea splits by the
// binned surface-area heuristic instead (16 bins per axis): the face hierarchies use it, which
// took 8-11 % off a tool's narrow phase in a deforming part (tools/tool_press.py, Wuson x1 /
// x4) for twice the build time; the contacts are the same, only the tree's shape differs. The
// other trees (broad phase, rest points, distance fields' faces) keep the centre split: their
// walks' orders reach results (contact order, grid bits). Nodes live in one array, children
// after their parent; parent links for refits in an array of their own.
//
// refit() updates the leaves of the items that changed and then only their ancestors, bottom-up
// in order of depth, so a local deformation costs O(changed x depth), not O(items). The dirty
// ancestors are a compact index set: a refit allocates nothing once it has grown.
#pragma once

#include "flexfit/bounding_volume.hpp"
#include "flexfit/index_set.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <numeric>
#include <vector>

namespace flexfit {

// Volume enclosing a set of child volumes, as the top-down build makes it.
Sphere encloseAll(std::span<const Sphere> volumes, std::span<const Index> which);
Aabb encloseAll(std::span<const Aabb> volumes, std::span<const Index> which);
inline Sphere mergeVolumes(const Sphere& a, const Sphere& b) { return Sphere::merge(a, b); }
inline Aabb mergeVolumes(const Aabb& a, const Aabb& b) { return Aabb::merge(a, b); }
inline Vec3 centreOf(const Sphere& s) { return s.centre; }
inline Vec3 centreOf(const Aabb& b) { return b.centre(); }

template <class BV>
class Bvh {
public:
    struct Node {
        BV volume;
        std::int32_t left = -1;   // child indices; -1 for a leaf
        std::int32_t right = -1;
        Index item = 0;           // the leaf's item
        std::uint16_t depth = 0;
        bool isLeaf() const { return left < 0; }
    };

    // How a node's items are split: at the centre of their centres' bounds along its longest
    // axis (the thesis's), or by the binned surface-area heuristic.
    enum class Split { Centre, SurfaceArea };

    // Builds over items 0..n-1 with the given leaf volumes.
    void build(std::span<const BV> leafVolumes, Split how = Split::Centre) {
        nodes_.clear();
        parents_.clear();
        maxDepth_ = 0;
        leafOf_.assign(leafVolumes.size(), 0);
        if (leafVolumes.empty()) return;
        nodes_.reserve(2 * leafVolumes.size());
        parents_.reserve(2 * leafVolumes.size());
        subtreeEnd_.assign(2 * leafVolumes.size() - 1, 0);
        // Kept between builds: a tree rebuilt every step (the broad phase's) allocates nothing.
        items_.resize(leafVolumes.size());
        std::iota(items_.begin(), items_.end(), Index(0));
        buildNode(leafVolumes, items_, 0, items_.size(), -1, 0, how);
        dirty_.reset(nodes_.size());
    }

    // Leaves of `items` get new volumes from leafVolume(item); their ancestors are refitted.
    template <class LeafVolume>
    void refit(std::span<const Index> items, LeafVolume leafVolume) {
        if (nodes_.empty()) return;
        dirty_.clear();
        for (Index item : items) {
            const Index leaf = leafOf_[item];
            nodes_[leaf].volume = leafVolume(item);
            // Its ancestors, up to the first one already marked (whose ancestors are marked too),
            // climbed in the compact parent array: through the nodes themselves each step
            // waited on a cache miss (a face-query refit of 2,300 moving masses spent a quarter
            // of its time there).
            std::int32_t n = parents_[leaf];
            while (n >= 0 && dirty_.insert(Index(n))) n = parents_[std::size_t(n)];
        }
        // Children come after their parent in the node array: descending index is bottom-up.
        // Many dirty nodes: one backward scan of the marks beats sorting them.
        auto merge = [&](std::size_t n) {
            Node& node = nodes_[n];
            node.volume = mergeVolumes(nodes_[std::size_t(node.left)].volume, nodes_[std::size_t(node.right)].volume);
        };
        if (dirty_.size() * 16 > nodes_.size()) {
            for (std::size_t n = nodes_.size(); n-- > 0;)
                if (dirty_.contains(Index(n))) merge(n);
        } else {
            // Deepest first (a counting sort by depth: sorting the indices cost a tenth of a
            // tool press's narrow phase); a node's children are one deeper, so they come first.
            for (Index n : byDepth(dirty_.members())) merge(n);
        }
        refitNodes_ += items.size() + dirty_.size();
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
    // Node n's subtree is nodes [n, subtreeEnd(n)) (children follow their parent), holding
    // itemCount(n) leaves.
    std::int32_t subtreeEnd(std::int32_t n) const { return subtreeEnd_[std::size_t(n)]; }
    std::size_t itemCount(std::int32_t n) const { return std::size_t(subtreeEnd_[std::size_t(n)] - n + 1) / 2; }
    const BV& leafVolume(Index item) const { return nodes_[leafOf_[item]].volume; }
    bool empty() const { return nodes_.empty(); }
    const BV& rootVolume() const { return nodes_.front().volume; }
    std::size_t refitNodeCount() const { return refitNodes_; }  // nodes recomputed by refits so far
    std::int32_t parent(std::size_t node) const { return parents_[node]; }  // -1 for the root

private:
    std::int32_t buildNode(std::span<const BV> leaves, std::vector<Index>& items, std::size_t begin, std::size_t end,
                           std::int32_t parent, std::uint16_t depth, Split how) {
        const auto index = std::int32_t(nodes_.size());
        nodes_.push_back({});
        parents_.push_back(parent);
        nodes_.back().depth = depth;
        maxDepth_ = std::max(maxDepth_, depth);
        const std::span<const Index> range(items.data() + begin, end - begin);
        if (end - begin == 1) {
            nodes_[std::size_t(index)].volume = leaves[items[begin]];
            nodes_[std::size_t(index)].item = items[begin];
            leafOf_[items[begin]] = Index(index);
            subtreeEnd_[std::size_t(index)] = index + 1;
            return index;
        }
        nodes_[std::size_t(index)].volume = encloseAll(leaves, range);
        const std::size_t middle = how == Split::SurfaceArea ? splitBySurfaceArea(leaves, items, begin, end) : split(leaves, items, begin, end);
        const std::int32_t left = buildNode(leaves, items, begin, middle, index, std::uint16_t(depth + 1), how);
        const std::int32_t right = buildNode(leaves, items, middle, end, index, std::uint16_t(depth + 1), how);
        nodes_[std::size_t(index)].left = left;
        nodes_[std::size_t(index)].right = right;
        subtreeEnd_[std::size_t(index)] = std::int32_t(nodes_.size());
        return index;
    }

    // `nodes` ordered by depth, deepest first (stable within a depth); uses the refit's scratch.
    std::span<const Index> byDepth(std::span<const Index> nodes) {
        perDepth_.assign(maxDepth_ + 2, 0);
        for (Index n : nodes) ++perDepth_[maxDepth_ - nodes_[n].depth + 1];
        for (std::size_t d = 1; d < perDepth_.size(); ++d) perDepth_[d] += perDepth_[d - 1];
        ordered_.resize(nodes.size());
        for (Index n : nodes) ordered_[perDepth_[maxDepth_ - nodes_[n].depth]++] = n;
        return ordered_;
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

    static Eigen::AlignedBox3d boxOf(const Aabb& b) { return {b.min, b.max}; }
    static Eigen::AlignedBox3d boxOf(const Sphere& s) { return {s.centre.array() - s.radius, s.centre.array() + s.radius}; }
    static double halfArea(const Eigen::AlignedBox3d& b) {
        if (b.isEmpty()) return 0.0;
        const Vec3 d = b.sizes();
        return d.x() * d.y() + d.y() * d.z() + d.z() * d.x();
    }

    // A surface-area split: the items whose centres fall in bins [0, bin) of `axis` go left.
    struct BinCut {
        int axis = -1, bin = 0;
        double cost = std::numeric_limits<double>::infinity();
    };
    static constexpr int kBins = 16;

    // Which of kBins equal bins of the centres' bounds along `axis` the item's centre is in.
    static int binOf(std::span<const BV> leaves, Index item, const Eigen::AlignedBox3d& centres, int axis) {
        const double t = (centreOf(leaves[item])[axis] - centres.min()[axis]) / centres.sizes()[axis] * kBins;
        return std::clamp(int(t), 0, kBins - 1);
    }

    // The cut along `axis` whose sides' half areas times their item counts sum least, if
    // better than `best`.
    static BinCut cheapestCut(std::span<const BV> leaves, std::span<const Index> items, const Eigen::AlignedBox3d& centres, int axis,
                              BinCut best) {
        std::array<Eigen::AlignedBox3d, kBins> boxes;  // empty to start with
        std::array<std::size_t, kBins> counts{};
        for (Index item : items) {
            const auto b = std::size_t(binOf(leaves, item, centres, axis));
            boxes[b].extend(boxOf(leaves[item]));
            ++counts[b];
        }
        std::array<double, kBins> rightCost{};  // of bins [b, kBins)
        Eigen::AlignedBox3d side;
        std::size_t count = 0;
        for (std::size_t b = kBins; b-- > 1;) {
            side.extend(boxes[b]);
            count += counts[b];
            rightCost[b] = halfArea(side) * double(count);
        }
        side.setEmpty();
        count = 0;
        for (std::size_t b = 1; b < kBins; ++b) {
            side.extend(boxes[b - 1]);
            count += counts[b - 1];
            const double cost = halfArea(side) * double(count) + rightCost[b];
            if (count > 0 && count < items.size() && cost < best.cost) best = {axis, int(b), cost};
        }
        return best;
    }

    // Binned surface-area heuristic (Wald 2007): the cheapest cut over the three axes; the
    // centre split for two items, for coincident centres, or when no cut leaves both sides
    // items.
    static std::size_t splitBySurfaceArea(std::span<const BV> leaves, std::vector<Index>& items, std::size_t begin, std::size_t end) {
        Eigen::AlignedBox3d centres;
        for (std::size_t i = begin; i < end; ++i) centres.extend(centreOf(leaves[items[i]]));
        const std::span<const Index> range(items.data() + begin, end - begin);
        BinCut best;
        if (range.size() > 2)
            for (int axis = 0; axis < 3; ++axis)
                if (centres.sizes()[axis] > 0.0) best = cheapestCut(leaves, range, centres, axis, best);
        if (best.axis < 0) return split(leaves, items, begin, end);
        auto first = items.begin() + std::ptrdiff_t(begin), last = items.begin() + std::ptrdiff_t(end);
        return std::size_t(std::partition(first, last, [&](Index i) { return binOf(leaves, i, centres, best.axis) < best.bin; }) - items.begin());
    }

    std::vector<Node> nodes_;
    std::vector<std::int32_t> parents_;  // (nodes) parent node, -1 for the root
    std::vector<Index> leafOf_;          // item -> leaf node
    std::vector<std::int32_t> subtreeEnd_;  // (nodes) one past the last node of each subtree
    IndexSet dirty_;                     // (nodes) ancestors to merge in a refit
    std::uint16_t maxDepth_ = 0;
    std::vector<std::uint32_t> perDepth_;  // byDepth()'s counts, then slots
    std::vector<Index> ordered_;           // byDepth()'s result
    std::vector<Index> items_;             // build()'s items, split in place
    std::size_t refitNodes_ = 0;
};

}  // namespace flexfit
