#include "flexfit/collision.hpp"

#include "collision/pair_query.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <tuple>

namespace flexfit {
using namespace detail;
namespace {

Sphere leafVolume(const Sphere*, std::span<const Vec3> positions, const Face& face, ExactTest) { return faceSphere(positions, face); }
Aabb leafVolume(const Aabb*, std::span<const Vec3> positions, const Face& face, ExactTest test) {
    return test == ExactTest::SphereTriangle ? faceSphereBox(positions, face) : faceBox(positions, face);
}

template <class BV>
void buildHierarchy(Bvh<BV>& bvh, const Part& part, ExactTest test) {
    const auto& faces = part.model().mesh.faces;
    std::vector<BV> leaves(faces.size());
    for (std::size_t f = 0; f < faces.size(); ++f) leaves[f] = leafVolume((const BV*)nullptr, part.state().positions, faces[f], test);
    bvh.build(leaves, Bvh<BV>::Split::SurfaceArea);
}


}  // namespace

QueryStats& QueryStats::operator+=(const QueryStats& o) {
    volumeTests += o.volumeTests;
    candidatePairs += o.candidatePairs;
    exactTests += o.exactTests;
    contacts += o.contacts;
    return *this;
}

Sphere faceSphere(std::span<const Vec3> positions, const Face& face) {
    const Vec3 centre = (positions[face[0]] + positions[face[1]] + positions[face[2]]) / 3.0;
    double radius = 0.0;
    for (Index v : face) radius = std::max(radius, (positions[v] - centre).norm());
    return {centre, radius * (1.0 + 1e-12)};
}

Aabb faceBox(std::span<const Vec3> positions, const Face& face) {
    const Vec3 &a = positions[face[0]], &b = positions[face[1]], &c = positions[face[2]];
    return {a.cwiseMin(b).cwiseMin(c), a.cwiseMax(b).cwiseMax(c)};
}

Aabb faceSphereBox(std::span<const Vec3> positions, const Face& face) {
    const Sphere s = faceSphere(positions, face);
    return {s.centre - Vec3::Constant(s.radius), s.centre + Vec3::Constant(s.radius)};
}

PartCollider::PartCollider(const Part& part, BoundingVolumeKind kind, ExactTest test) : kind_(kind), test_(test) {
    // A triangle's box moves with its vertices; a face sphere's centre moves as far and its
    // radius changes by at most twice that (as does the box around it).
    leafDriftPerMove_ = kind == BoundingVolumeKind::Aabb && test == ExactTest::TriangleTriangle ? 1.0 : 3.0;
    if (kind == BoundingVolumeKind::Aabb) bvh_.emplace<Bvh<Aabb>>();
    restSphere_ = Sphere::around(part.model().restPositions);
    changedFaces_.reset(part.model().faceCount());
    const auto& rest = part.model().restPositions;
    solid_ = solidDefect(rest, part.model().mesh.faces, part.model().topology) == SolidDefect::None;
    restPlanes_.reserve(part.model().faceCount());
    for (const Face& f : part.model().mesh.faces) {
        const Vec3 n = (rest[f[1]] - rest[f[0]]).cross(rest[f[2]] - rest[f[0]]).normalized();
        std::array<Eigen::Vector4d, 4> planes;
        planes[0] << n, n.dot(rest[f[0]]);
        for (int e = 0; e < 3; ++e) {
            const Vec3& p = rest[f[e]];
            const Vec3 out = (rest[f[(e + 1) % 3]] - p).cross(n).normalized();
            planes[std::size_t(e) + 1] << out, out.dot(p);
        }
        restPlanes_.push_back(planes);
    }
    rebuild(part);
}

void PartCollider::rebuild(const Part& part) {
    std::visit(
        [&](auto& bvh) {
            buildHierarchy(bvh, part, test_);
            double sizes = 0.0;
            for (const auto& node : bvh.nodes())
                if (node.isLeaf()) sizes += volumeSize(node.volume);
            leafScale_ = part.model().faceCount() > 0 ? sizes / double(part.model().faceCount()) : 0.0;
        },
        bvh_);
    ++generation_;
    vertexDrift_ = 0.0;
    seenPositions_.assign(part.state().positions.begin(), part.state().positions.end());
    updateDisplacementBound(part);
}

void PartCollider::updateDisplacementBound(const Part& part) {
    // The largest squared norm, then one square root: sqrt is monotonic and correctly rounded,
    // so this is exactly the largest norm, without a root per moving mass every refit. Four
    // running maxima, not one: the loop waited on each max's latency (max is exact, so the
    // same value in any order; a NaN never wins, as before).
    const std::span<const Index> moving = part.movingMasses();
    const Vec3Array& positions = part.state().positions;
    const Vec3Array& rest = part.model().restPositions;
    const auto squaredMove = [&](Index m) { return (positions[m] - rest[m]).squaredNorm(); };
    std::array<double, 4> largest2{};
    std::size_t i = 0;
    for (; i + 4 <= moving.size(); i += 4)
        for (std::size_t j = 0; j < 4; ++j) largest2[j] = std::max(largest2[j], squaredMove(moving[i + j]));
    for (; i < moving.size(); ++i) largest2[0] = std::max(largest2[0], squaredMove(moving[i]));
    maxDisplacement_ = std::sqrt(std::max(std::max(largest2[0], largest2[1]), std::max(largest2[2], largest2[3])));
}

void PartCollider::refit(const Part& part, std::span<const Index> changedMasses) {
    const PartModel& model = part.model();
    double moved2 = 0.0;  // the largest squared move (one root below, as updateDisplacementBound)
    changedFaces_.clear();
    for (Index m : changedMasses) {
        moved2 = std::max(moved2, (part.state().positions[m] - seenPositions_[m]).squaredNorm());
        seenPositions_[m] = part.state().positions[m];
        for (Index f : model.topology.facesOf(m)) changedFaces_.insert(f);
    }
    vertexDrift_ += std::sqrt(moved2);
    const std::span<const Vec3> positions = part.state().positions;
    std::visit(
        [&](auto& bvh) {
            using BV = std::decay_t<decltype(bvh.rootVolume())>;
            bvh.refit(changedFaces_.members(), [&](Index f) { return leafVolume((const BV*)nullptr, positions, model.mesh.faces[f], test_); });
        },
        bvh_);
    updateDisplacementBound(part);
}

void PartCollider::buildRestPointTree(const Part& part) {
    const auto& rest = part.model().restPositions;
    std::vector<Aabb> points(rest.size());
    for (std::size_t m = 0; m < rest.size(); ++m) points[m] = {rest[m], rest[m]};
    restPoints_.build(points);
}

Sphere PartCollider::worldSphere(const Part& part) const {
    const Sphere local = localSphere();
    return {part.pose().apply(local.centre), local.radius};
}

std::size_t PartCollider::refitNodeCount() const {
    return std::visit([](const auto& bvh) { return bvh.refitNodeCount(); }, bvh_);
}

namespace detail {
namespace {
std::size_t chosenLeafGroup = kDefaultLeafGroup;
}  // namespace

std::size_t leafGroup() { return chosenLeafGroup; }
ScopedLeafGroup::ScopedLeafGroup(std::size_t items) { chosenLeafGroup = std::max<std::size_t>(items, 1); }
ScopedLeafGroup::~ScopedLeafGroup() { chosenLeafGroup = kDefaultLeafGroup; }

RestPlaneFilter::Scratch& restPlaneScratch() {
    thread_local RestPlaneFilter::Scratch scratch;
    return scratch;
}
}  // namespace detail

namespace detail {

// Contacts in (faceA, faceB) order: the same whatever order a traversal met them in.
// Sorts (face pair, position) keys, then moves each contact once: a contact is 80 bytes.
void sortContacts(std::vector<Contact>& contacts, std::size_t first) {
    const std::size_t n = contacts.size() - first;
    thread_local std::vector<std::pair<std::uint64_t, std::uint32_t>> keys;
    thread_local std::vector<Contact> sorted;
    keys.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Contact& c = contacts[first + i];
        keys[i] = {std::uint64_t(c.faceA) << 32 | c.faceB, std::uint32_t(i)};
    }
    if (std::is_sorted(keys.begin(), keys.end())) return;
    std::sort(keys.begin(), keys.end());
    sorted.clear();
    for (const auto& key : keys) sorted.push_back(contacts[first + key.second]);
    std::copy(sorted.begin(), sorted.end(), contacts.begin() + std::ptrdiff_t(first));
}

}  // namespace detail

namespace {

// A turned pair's traversal tests each node pair by the oriented-box test (overlapRotated). When
// one part's tree is far the smaller (a ball against a container mouth of 45 times its faces),
// it is boxed again in the other part's frame, once per query: the tree copied, each leaf the
// box of its triangle turned into that frame, the nodes refitted. Every node pair is then tested
// axis-aligned. A leaf's box is its triangle's in either frame, so every pair of triangles that
// touch still meets (the exact test, at the parts' own poses, decides the contacts). Each
// reboxed leaf is grown by kReboxSlack of the largest coordinate in play: the turned vertices
// are rounded otherwise than the exact test's (B's turned into A's frame), and triangles lying
// exactly on each other (flush boxes turned alike) then had leaf boxes an ulp apart: the full
// query lost their contacts of depth 0, which the coherent query's oriented-box test and a
// brute-force query find (a fuzzing of coherent against full queries, 17.7 million queries).
constexpr std::size_t kReboxRatio = 8;  // the smaller tree's nodes at most 1/8 of the other's

struct Reboxed {
    Bvh<Aabb> tree;
    std::vector<Vec3> positions;  // the part's, in the other part's frame
};

constexpr double kReboxSlack = 1e-12;  // far above a turn's rounding (a few 1e-16 of the coordinates)

// `tree` (of `part`, its leaves as a triangle query builds them) boxed in the frame
// x' = rotation x + translation; `reach` bounds every coordinate in play (reachOf).
const Bvh<Aabb>& reboxed(const Bvh<Aabb>& tree, const Part& part, const Eigen::Matrix3d& rotation, const Vec3& translation, double reach) {
    thread_local Reboxed r;
    const auto& positions = part.state().positions;
    r.positions.resize(positions.size());
    for (std::size_t i = 0; i < positions.size(); ++i) r.positions[i] = rotation * positions[i] + translation;
    const double slack = kReboxSlack * (1.0 + reach);
    r.tree = tree;
    const auto& faces = part.model().mesh.faces;
    r.tree.refitAll([&](Index f) { return detail::grown(leafVolume((const Aabb*)nullptr, r.positions, faces[f], ExactTest::TriangleTriangle), slack); });
    return r.tree;
}

// A bound on every coordinate a turned pair's query handles: both parts' vertices in their own
// frames (by their bounding spheres, O(1)), turned into the other's (plus the translation).
double reachOf(const PartCollider& colliderA, const PartCollider& colliderB, const RelativePose& bInA) {
    const Sphere a = colliderA.localSphere(), b = colliderB.localSphere();
    return a.centre.norm() + a.radius + b.centre.norm() + b.radius + bInA.translation.norm();
}

bool smallerByFar(const Bvh<Aabb>& x, const Bvh<Aabb>& y) { return kReboxRatio * x.nodes().size() <= y.nodes().size(); }

}  // namespace

void queryPair(std::uint32_t idA, const Part& a, const PartCollider& colliderA, std::uint32_t idB, const Part& b,
               const PartCollider& colliderB, ExactTest test, std::vector<Contact>& contacts, QueryStats& stats,
               std::vector<std::pair<Index, Index>>* candidates) {
    requireBuiltFor(colliderA, colliderB, test);
    const RelativePose bInA = relativePose(a, b);
    const std::size_t first = contacts.size();
    LeafPairTester tester(idA, a, colliderA, idB, b, colliderB, test, bInA, contacts, stats);
    auto leafPair = [&](Index fa, Index fb) {
        if (candidates) candidates->emplace_back(fa, fb);
        tester(fa, fb);
    };
    // Listing candidates means every leaf pair whose volumes overlap: no pruning then.
    auto prune = [&](Index fa, const auto& volumeB) { return !candidates && tester.prunes(fa, volumeB); };
    auto pruneA = [&](Index fb, const auto& volumeA) { return !candidates && tester.prunesByB(fb, volumeA); };
    const bool turnedBoxes = !bInA.pureTranslation && !candidates && test == ExactTest::TriangleTriangle && colliderA.boxes() && colliderB.boxes();
    const RelativePose same;  // both trees in one frame
    if (turnedBoxes && smallerByFar(*colliderA.boxes(), *colliderB.boxes())) {
        // A's boxes in B's frame: x_B = R^T (x_A - t). A's face planes still prune B's subtrees
        // (they are moved to B's frame); B's are in A's frame, which A's boxes no longer are.
        const Eigen::Matrix3d toB = bInA.rotation.transpose();
        traverse(reboxed(*colliderA.boxes(), a, toB, -(toB * bInA.translation), reachOf(colliderA, colliderB, bInA)), *colliderB.boxes(), same, stats, leafPair, prune, 0.0);
    } else if (turnedBoxes && smallerByFar(*colliderB.boxes(), *colliderA.boxes())) {
        // B's boxes in A's frame; B's face planes prune A's subtrees.
        traverse(*colliderA.boxes(), reboxed(*colliderB.boxes(), b, bInA.rotation, bInA.translation, reachOf(colliderA, colliderB, bInA)), same, stats, leafPair, NoPrune{},
                 0.0, pruneA);
    } else {
        dispatch(colliderA, colliderB, [&](const auto& bvhA, const auto& bvhB) { traverse(bvhA, bvhB, bInA, stats, leafPair, prune, 0.0, pruneA); });
    }
    sortContacts(contacts, first);
}

}  // namespace flexfit
