#include "flexfit/collision.hpp"

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
template <class BA, class BB, class LeafPair>
void traverse(const Bvh<BA>& a, const Bvh<BB>& b, const RelativePose& bInA, QueryStats& stats, LeafPair leafPair) {
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

const char* toString(ExactTest test) { return test == ExactTest::SphereTriangle ? "sphere-triangle" : "triangle-triangle"; }

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
    const Vec3 p[3] = {positions[face[0]], positions[face[1]], positions[face[2]]};
    return Aabb::around(p);
}

Aabb faceSphereBox(std::span<const Vec3> positions, const Face& face) {
    const Sphere s = faceSphere(positions, face);
    return {s.centre - Vec3::Constant(s.radius), s.centre + Vec3::Constant(s.radius)};
}

PartCollider::PartCollider(const Part& part, BoundingVolumeKind kind, ExactTest test) : kind_(kind), test_(test) {
    if (kind == BoundingVolumeKind::Aabb) bvh_.emplace<Bvh<Aabb>>();
    restSphere_ = Sphere::around(part.model().restPositions);
    faceMark_.assign(part.model().faceCount(), 0);
    rebuild(part);
}

void PartCollider::rebuild(const Part& part) {
    std::visit([&](auto& bvh) { buildHierarchy(bvh, part, test_); }, bvh_);
    maxDisplacement_ = 0.0;
    for (Index m : part.movingMasses())
        maxDisplacement_ = std::max(maxDisplacement_, (part.state().positions[m] - part.model().restPositions[m]).norm());
}

void PartCollider::refit(const Part& part, std::span<const Index> changedMasses) {
    const PartModel& model = part.model();
    if (++epoch_ == 0) {
        std::fill(faceMark_.begin(), faceMark_.end(), 0u);
        epoch_ = 1;
    }
    changedFaces_.clear();
    for (Index m : changedMasses)
        for (Index f : model.topology.facesOf(m))
            if (faceMark_[f] != epoch_) {
                faceMark_[f] = epoch_;
                changedFaces_.push_back(f);
            }
    const std::span<const Vec3> positions = part.state().positions;
    std::visit(
        [&](auto& bvh) {
            using BV = std::decay_t<decltype(bvh.rootVolume())>;
            bvh.refit(changedFaces_, [&](Index f) { return leafVolume((const BV*)nullptr, positions, model.mesh.faces[f], test_); });
        },
        bvh_);
    maxDisplacement_ = 0.0;
    for (Index m : part.movingMasses())
        maxDisplacement_ = std::max(maxDisplacement_, (positions[m] - model.restPositions[m]).norm());
}

Sphere PartCollider::worldSphere(const Part& part) const {
    const Sphere local = localSphere();
    return {part.pose().apply(local.centre), local.radius};
}

std::size_t PartCollider::refitNodeCount() const {
    return std::visit([](const auto& bvh) { return bvh.refitNodeCount(); }, bvh_);
}

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
    auto leafPair = [&](Index fa, Index fb) {
        if (candidates) candidates->emplace_back(fa, fb);
        const Face& f = facesB[fb];
        const Triangle tb{bInA.apply(pb[f[0]]), bInA.apply(pb[f[1]]), bInA.apply(pb[f[2]])};
        ++stats.exactTests;
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
    dispatch(colliderA, colliderB, [&](const auto& bvhA, const auto& bvhB) { traverse(bvhA, bvhB, bInA, stats, leafPair); });
}

}  // namespace flexfit
