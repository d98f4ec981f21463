// The collision world's registry and settings (collision_world.hpp); its stages are in
// broad_phase.cpp and narrow_phase.cpp.
#include "flexfit/collision_world.hpp"
#include "core/reserve.hpp"

#include <algorithm>
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

namespace {

double meanRestEdge(const Part& part) {
    const Topology& topology = part.model().topology;
    const auto& vertices = part.model().mesh.vertices;
    double sum = 0.0;
    for (std::size_t e = 0; e < topology.edgeCount(); ++e) sum += (vertices[topology.edgeA[e]] - vertices[topology.edgeB[e]]).norm();
    return topology.edgeCount() > 0 ? sum / double(topology.edgeCount()) : 0.0;
}

}  // namespace

void CollisionWorld::add(BodyId id, const Part& part, BoundingVolumeKind kind) {
    if (id != parts_.size())
        throw std::invalid_argument("CollisionWorld::add: body " + std::to_string(id) + " out of order (expected " +
                                    std::to_string(parts_.size()) + ")");
    // Everything is built before anything is registered: a failure (out of memory) leaves the
    // collision world as it was. Fields, sharp features and rest-point trees are built now
    // rather than at the first contact, where they would stall a haptic loop.
    PartCollider collider(part, kind, settings_.exactTest);
    const RigidDeformableQuery query = settings_.rigidDeformable;
    const bool shellable = query != RigidDeformableQuery::Faces && part.deforms();
    if (shellable) collider.buildRestPointTree(part);
    // The registry with this part in it (index self), in copies until nothing can throw.
    const std::size_t self = parts_.size(), n = self + 1;
    std::vector<const Part*> parts = parts_;
    parts.push_back(&part);
    std::vector<double> meanEdge = meanEdge_, resolution = restResolution_;
    meanEdge.push_back(meanRestEdge(part));
    resolution.push_back(shellable ? restResolution(part) : 0.0);
    // A rigid part's features are found at the scale of the coarsest deformable part its point
    // shell may serve: the scale they have, grown to the new part's where it deforms; all of
    // those it may serve, where it is the rigid one.
    std::vector<double> radius(n, 0.0);
    for (std::size_t r = 0; r < self; ++r) radius[r] = features_[r] ? features_[r]->radius : 0.0;
    auto serves = [&](std::size_t r, std::size_t b) {
        return !parts[r]->deforms() && parts[b]->deforms() && pointShellServes(r, b, meanEdge);
    };
    std::vector<bool> servesNew(n, false);  // rigid parts the new part makes the point shell serve
    for (std::size_t r = 0; r < self; ++r) {
        if (serves(r, self)) {
            servesNew[r] = true;
            radius[r] = std::max(radius[r], resolution[self]);
        }
        if (serves(self, r)) {
            servesNew[self] = true;
            radius[self] = std::max(radius[self], resolution[r]);
        }
    }
    // Fields for the rigid parts the point shell may serve (under PointShell all of them).
    std::vector<std::shared_ptr<const SignedDistanceField>> fields = fields_;
    std::vector<bool> tried = fieldTried_;
    fields.push_back(nullptr);
    tried.push_back(false);
    for (std::size_t r = 0; r < n && query != RigidDeformableQuery::Faces; ++r) {
        if (parts[r]->deforms() || tried[r] || (query == RigidDeformableQuery::Auto && !servesNew[r])) continue;
        fields[r] = buildDistanceField(*parts[r]);
        tried[r] = true;
    }
    std::vector<std::shared_ptr<const SharpFeatures>> features = features_;
    features.push_back(nullptr);
    for (std::size_t r = 0; r < n; ++r)
        if (fields[r] && (!features[r] || features[r]->radius != radius[r]))
            features[r] = std::make_shared<const SharpFeatures>(findSharpFeatures(*parts[r], radius[r], settings_.exactTest));
    std::vector<Sphere> spheres = partSpheres_;
    spheres.push_back(collider.worldSphere(part));
    detail::reserveGrowing(colliders_, n);
    refitted_.growTo(n);
    // Nothing below throws.
    parts_ = std::move(parts);
    colliders_.push_back(std::move(collider));
    fields_ = std::move(fields);
    features_ = std::move(features);
    meanEdge_ = std::move(meanEdge);
    restResolution_ = std::move(resolution);
    fieldTried_ = std::move(tried);
    partSpheres_ = std::move(spheres);
    broadPhaseBuilt_ = false;  // the tree's shape changes with the set of parts: built at the next update, once for any number of adds
}

void CollisionWorld::setExactTest(ExactTest test) {
    if (test == settings_.exactTest) return;
    std::vector<PartCollider> colliders;
    std::vector<std::shared_ptr<const SharpFeatures>> features(parts_.size());
    for (std::size_t i = 0; i < parts_.size(); ++i) {
        PartCollider rebuilt(*parts_[i], colliders_[i].kind(), test);
        if (!colliders_[i].restPointTree().empty()) rebuilt.buildRestPointTree(*parts_[i]);
        colliders.push_back(std::move(rebuilt));
        if (features_[i]) features[i] = std::make_shared<const SharpFeatures>(findSharpFeatures(*parts_[i], features_[i]->radius, test));
    }
    settings_.exactTest = test;
    colliders_ = std::move(colliders);
    features_ = std::move(features);
    coherence_.clear();  // the candidates were of the old hierarchies
}

bool CollisionWorld::pressesFirst(BodyId a, BodyId b) const {
    const bool da = parts_[a]->deforms(), db = parts_[b]->deforms();
    return da == db ? a < b : !da;
}

bool CollisionWorld::pointShellServes(std::size_t rigid, std::size_t deformable, std::span<const double> meanEdge) const {
    switch (settings_.rigidDeformable) {
        case RigidDeformableQuery::Faces: return false;
        case RigidDeformableQuery::PointShell: return true;
        case RigidDeformableQuery::Auto: return meanEdge[deformable] < meanEdge[rigid];
    }
    return false;
}

bool CollisionWorld::usesPointShell(BodyId a, BodyId b) const {
    return fields_[a] && parts_[b]->deforms() && pointShellServes(a, b, meanEdge_);
}

}  // namespace flexfit
