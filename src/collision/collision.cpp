#include "flexfit/collision.hpp"

#include "collision/triangle_queries.hpp"
#include "flexfit/distance_field.hpp"

#include <stdexcept>

namespace flexfit {
namespace {

Triangle triangleOf(std::span<const Vec3> positions, const Face& f) { return {positions[f[0]], positions[f[1]], positions[f[2]]}; }

Sphere leafVolume(const Sphere*, std::span<const Vec3> positions, const Face& face, ExactTest) { return faceSphere(positions, face); }
Aabb leafVolume(const Aabb*, std::span<const Vec3> positions, const Face& face, ExactTest test) {
    return test == ExactTest::SphereTriangle ? faceSphereBox(positions, face) : faceBox(positions, face);
}

template <class BV>
void buildHierarchy(Bvh<BV>& bvh, const Part& part, ExactTest test) {
    const auto& faces = part.model().mesh.faces;
    std::vector<BV> leaves(faces.size());
    for (std::size_t f = 0; f < faces.size(); ++f) leaves[f] = leafVolume((const BV*)nullptr, part.state().positions, faces[f], test);
    bvh.build(leaves);
}

double volumeSize(const Sphere& s) { return 2.0 * s.radius; }
double volumeSize(const Aabb& b) { return b.size(); }

// Simultaneous depth-first traversal; leafPair(faceA, faceB) for every overlapping leaf pair.
// prune(faceA, volumeB) may cut a subtree of B that cannot touch A's leaf face.
template <class BA, class BB, class LeafPair, class Prune>
void traverse(const Bvh<BA>& a, const Bvh<BB>& b, const RelativePose& bInA, QueryStats& stats, LeafPair leafPair, Prune prune) {
    if (a.empty() || b.empty()) return;
    thread_local std::vector<std::pair<std::int32_t, std::int32_t>> stack;
    stack.clear();
    stack.emplace_back(0, 0);
    const auto& na = a.nodes();
    const auto& nb = b.nodes();
    while (!stack.empty()) {
        const auto [i, j] = stack.back();
        stack.pop_back();
        const auto& x = na[std::size_t(i)];
        const auto& y = nb[std::size_t(j)];
        ++stats.volumeTests;
        if (!overlap(x.volume, y.volume, bInA)) continue;
        if (x.isLeaf() && !y.isLeaf() && prune(x.item, y.volume)) continue;
        if (x.isLeaf() && y.isLeaf()) {
            ++stats.candidatePairs;
            leafPair(x.item, y.item);
        } else if (x.isLeaf() || (!y.isLeaf() && volumeSize(y.volume) > volumeSize(x.volume))) {
            stack.emplace_back(i, y.right);
            stack.emplace_back(i, y.left);
        } else {
            stack.emplace_back(x.right, j);
            stack.emplace_back(x.left, j);
        }
    }
}

template <class Visit>
void dispatch(const PartCollider& a, const PartCollider& b, Visit visit) {
    if (a.spheres() && b.spheres()) return visit(*a.spheres(), *b.spheres());
    if (a.spheres() && b.boxes()) return visit(*a.spheres(), *b.boxes());
    if (a.boxes() && b.spheres()) return visit(*a.boxes(), *b.spheres());
    return visit(*a.boxes(), *b.boxes());
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
    if (kind == BoundingVolumeKind::Aabb) bvh_.emplace<Bvh<Aabb>>();
    restSphere_ = Sphere::around(part.model().restPositions);
    changedFaces_.reset(part.model().faceCount());
    const auto& rest = part.model().restPositions;
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
    std::visit([&](auto& bvh) { buildHierarchy(bvh, part, test_); }, bvh_);
    updateDisplacementBound(part);
}

void PartCollider::updateDisplacementBound(const Part& part) {
    maxDisplacement_ = 0.0;
    for (Index m : part.movingMasses())
        maxDisplacement_ = std::max(maxDisplacement_, (part.state().positions[m] - part.model().restPositions[m]).norm());
}

void PartCollider::refit(const Part& part, std::span<const Index> changedMasses) {
    const PartModel& model = part.model();
    changedFaces_.clear();
    for (Index m : changedMasses)
        for (Index f : model.topology.facesOf(m)) changedFaces_.insert(f);
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

// Cheap rejection before the triangle test, when A's face is at rest (its planes are cached
// in A's frame, and moved to B's frame once per face and query): B's triangle entirely beyond
// the face's plane (either side) or beyond one of its edge planes is separated from it along
// that direction, and needs no transform. The margin is far wider than the triangle test's
// own tolerance, so only pairs that test would also reject are skipped.
class RestPlaneFilter {
public:
    RestPlaneFilter(const Part& a, const PartCollider& colliderA, const RelativePose& bInA) : a_(a), collider_(colliderA), bInA_(bInA) {
        movedPlanes_.clear();
        movedPlanes_.growTo(a.model().faceCount());
        if (planesInB_.size() < a.model().faceCount()) planesInB_.resize(a.model().faceCount());
    }
    bool separated(Index fa, std::span<const Vec3> pb, const Face& fb) {
        if (!atRest(fa)) return false;
        const auto& planes = planesInB(fa);
        for (std::size_t k = 0; k < planes.size(); ++k) {
            const Vec3 n = planes[k].head<3>();
            const double margin = 1e-9 * (1.0 + std::abs(collider_.restPlanes(fa)[k][3]));
            const double d0 = n.dot(pb[fb[0]]) - planes[k][3], d1 = n.dot(pb[fb[1]]) - planes[k][3], d2 = n.dot(pb[fb[2]]) - planes[k][3];
            if (d0 > margin && d1 > margin && d2 > margin) return true;
            if (k == 0 && d0 < -margin && d1 < -margin && d2 < -margin) return true;
        }
        return false;
    }

    // A subtree of B whose volume lies entirely beyond one of A's face planes holds no
    // triangle the face can touch (each would be rejected by separated()).
    template <class Volume>
    bool separated(Index fa, const Volume& volumeB) {
        if (!atRest(fa)) return false;
        const auto& planes = planesInB(fa);
        for (std::size_t k = 0; k < planes.size(); ++k) {
            const Vec3 n = planes[k].head<3>();
            const double margin = 1e-9 * (1.0 + std::abs(collider_.restPlanes(fa)[k][3]));
            const auto [lowest, highest] = extent(volumeB, n);
            if (lowest - planes[k][3] > margin) return true;
            if (k == 0 && highest - planes[k][3] < -margin) return true;
        }
        return false;
    }

private:
    bool atRest(Index fa) const {
        const Face& f = a_.model().mesh.faces[fa];
        return a_.mode() == PartMode::Rigid || !(a_.isMoving(f[0]) || a_.isMoving(f[1]) || a_.isMoving(f[2]));
    }
    // Range of n.x over the volume.
    static std::pair<double, double> extent(const Aabb& box, const Vec3& n) {
        const double centre = n.dot(box.centre()), reach = n.cwiseAbs().dot(box.halfExtents());
        return {centre - reach, centre + reach};
    }
    static std::pair<double, double> extent(const Sphere& sphere, const Vec3& n) {
        const double centre = n.dot(sphere.centre);
        return {centre - sphere.radius, centre + sphere.radius};
    }
    // n.(R x + t) = d  <=>  (R^T n).x = d - n.t
    const std::array<Eigen::Vector4d, 4>& planesInB(Index fa) {
        if (movedPlanes_.insert(fa)) {
            const auto& planes = collider_.restPlanes(fa);
            for (std::size_t k = 0; k < planes.size(); ++k) {
                const Vec3 n = planes[k].head<3>();
                planesInB_[fa][k] << bInA_.rotation.transpose() * n, planes[k][3] - n.dot(bInA_.translation);
            }
        }
        return planesInB_[fa];
    }
    const Part& a_;
    const PartCollider& collider_;
    const RelativePose& bInA_;
    static thread_local std::vector<std::array<Eigen::Vector4d, 4>> planesInB_;
    static thread_local IndexSet movedPlanes_;  // faces whose planes are in planesInB_ for this query
};
thread_local std::vector<std::array<Eigen::Vector4d, 4>> RestPlaneFilter::planesInB_;
thread_local IndexSet RestPlaneFilter::movedPlanes_;

void queryPair(std::uint32_t idA, const Part& a, const PartCollider& colliderA, std::uint32_t idB, const Part& b,
               const PartCollider& colliderB, ExactTest test, std::vector<Contact>& contacts, QueryStats& stats,
               std::vector<std::pair<Index, Index>>* candidates) {
    if (colliderA.exactTest() != test || colliderB.exactTest() != test)
        throw std::invalid_argument("queryPair: a collider was built for another exact test");
    // B's frame seen from A's: x_A = Ra^T (Rb x_B + tb - ta).
    const Eigen::Matrix3d ra = a.pose().rotation.toRotationMatrix(), rb = b.pose().rotation.toRotationMatrix();
    const RelativePose bInA(ra.transpose() * rb, ra.transpose() * (b.pose().translation - a.pose().translation));
    const std::span<const Vec3> pa = a.state().positions, pb = b.state().positions;
    const auto& facesA = a.model().mesh.faces;
    const auto& facesB = b.model().mesh.faces;
    RestPlaneFilter filter(a, colliderA, bInA);
    auto leafPair = [&](Index fa, Index fb) {
        if (candidates) candidates->emplace_back(fa, fb);
        const Face& f = facesB[fb];
        ++stats.exactTests;
        if (test == ExactTest::TriangleTriangle && filter.separated(fa, pb, f)) return;
        const Triangle tb{bInA.apply(pb[f[0]]), bInA.apply(pb[f[1]]), bInA.apply(pb[f[2]])};
        std::optional<TriangleContact> hit;
        if (test == ExactTest::SphereTriangle) {
            const Sphere s = faceSphere(pa, facesA[fa]);
            hit = sphereTriangleContact(s.centre, s.radius, tb);
        } else {
            hit = intersectTriangles(triangleOf(pa, facesA[fa]), tb);
        }
        if (!hit) return;
        ++stats.contacts;
        contacts.push_back({idA, idB, fa, fb, a.pose().apply(hit->point), ra * hit->normal, hit->depth});
    };
    dispatch(colliderA, colliderB, [&](const auto& bvhA, const auto& bvhB) { 
        // Listing candidates means every leaf pair whose volumes overlap: no pruning then.
        auto prune = [&](Index fa, const auto& volumeB) {
            return !candidates && test == ExactTest::TriangleTriangle && filter.separated(fa, volumeB);
        };
        traverse(bvhA, bvhB, bInA, stats, leafPair, prune);
    });
}

void queryPointShell(std::uint32_t idA, const Part& a, const SignedDistanceField& fieldA, std::uint32_t idB, const Part& b,
                     const Bvh<Aabb>& restPointsB, std::vector<Contact>& contacts, QueryStats& stats) {
    const Eigen::Matrix3d ra = a.pose().rotation.toRotationMatrix(), rb = b.pose().rotation.toRotationMatrix();
    const RelativePose bInA(ra.transpose() * rb, ra.transpose() * (b.pose().translation - a.pose().translation));
    const std::span<const Vec3> pb = b.state().positions;
    const Topology& topology = b.model().topology;
    auto sampleMass = [&](Index m) {
        if (topology.facesOf(m).empty()) return;  // a free vertex: no surface to push
        const Vec3 p = bInA.apply(pb[m]);
        ++stats.candidatePairs;
        if (!fieldA.inGrid(p)) return;
        ++stats.exactTests;
        const SignedDistanceField::Interpolated s = fieldA.sample(p);
        if (s.distance > 0.0) return;
        // The gradient is the outward normal (zero only on a symmetry plane of the field,
        // where the exact closest point decides).
        const double g = s.gradient.norm();
        const Vec3 outward = g > 1e-9 ? Vec3(s.gradient / g) : fieldA.query(p).normal;
        ++stats.contacts;
        contacts.push_back({idA, idB, 0, topology.facesOf(m)[0], a.pose().apply(p), -(ra * outward), -s.distance, m});
    };
    for (Index m : b.movingMasses()) sampleMass(m);
    // The masses at rest, through the tree of rest positions (their current positions).
    if (restPointsB.empty()) return;
    const auto& nodes = restPointsB.nodes();
    thread_local std::vector<std::int32_t> stack;
    stack.assign(1, 0);
    while (!stack.empty()) {
        const auto& node = nodes[std::size_t(stack.back())];
        stack.pop_back();
        ++stats.volumeTests;
        if (node.isLeaf()) {
            if (!b.isMoving(node.item)) sampleMass(node.item);
            continue;
        }
        if (!fieldA.clearOf(bInA.apply(node.volume.centre()), node.volume.halfExtents().norm())) {
            stack.push_back(node.right);
            stack.push_back(node.left);
        }
    }
}

}  // namespace flexfit
