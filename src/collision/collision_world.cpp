// The collision world's registry and settings (collision_world.hpp); its stages are in
// broad_phase.cpp and narrow_phase.cpp.
#include "flexfit/collision_world.hpp"

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
    const double edge = meanRestEdge(part);
    // Which rigid parts (this one included, as index parts_.size()) may meet the point shell.
    const std::size_t n = parts_.size() + 1;
    std::vector<std::shared_ptr<const SignedDistanceField>> fields = fields_;
    std::vector<bool> tried = fieldTried_;
    std::vector<double> meanEdge = meanEdge_;
    fields.push_back(nullptr);
    tried.push_back(false);
    meanEdge.push_back(edge);
    std::vector<const Part*> parts = parts_;
    parts.push_back(&part);
    double radius = featureRadius_, finestEdge = finestDeformableEdge_;
    if (query != RigidDeformableQuery::Faces && part.deforms()) {
        collider.buildRestPointTree(part);
        radius = std::max(radius, restResolution(part));
        finestEdge = std::min(finestEdge, edge);
    }
    for (std::size_t r = 0; r < n && query != RigidDeformableQuery::Faces; ++r) {
        if (parts[r]->deforms() || tried[r]) continue;
        if (query == RigidDeformableQuery::Auto && !(finestEdge < meanEdge[r])) continue;  // no deformable part is finer
        fields[r] = buildDistanceField(*parts[r]);
        tried[r] = true;
    }
    // Sharp features beside every field, at the coarsest deformable part's scale.
    std::vector<std::shared_ptr<const SharpFeatures>> features = features_;
    features.push_back(nullptr);
    for (std::size_t r = 0; r < n; ++r)
        if (fields[r] && (!features[r] || features[r]->radius != radius))
            features[r] = std::make_shared<const SharpFeatures>(findSharpFeatures(*parts[r], radius, settings_.exactTest));
    std::vector<Sphere> spheres = partSpheres_;
    spheres.push_back(collider.worldSphere(part));
    Bvh<Sphere> tree;
    tree.build(spheres);  // the tree's shape changes with the set of parts
    colliders_.reserve(n);
    refitted_.growTo(n);
    // Nothing below throws.
    parts_ = std::move(parts);
    colliders_.push_back(std::move(collider));
    fields_ = std::move(fields);
    features_ = std::move(features);
    meanEdge_ = std::move(meanEdge);
    fieldTried_ = std::move(tried);
    featureRadius_ = radius;
    finestDeformableEdge_ = finestEdge;
    partSpheres_ = std::move(spheres);
    broadPhase_ = std::move(tree);
}

void CollisionWorld::setExactTest(ExactTest test) {
    if (test == settings_.exactTest) return;
    std::vector<PartCollider> colliders;
    std::vector<std::shared_ptr<const SharpFeatures>> features(parts_.size());
    for (std::size_t i = 0; i < parts_.size(); ++i) {
        PartCollider rebuilt(*parts_[i], colliders_[i].kind(), test);
        if (!colliders_[i].restPointTree().empty()) rebuilt.buildRestPointTree(*parts_[i]);
        colliders.push_back(std::move(rebuilt));
        if (features_[i]) features[i] = std::make_shared<const SharpFeatures>(findSharpFeatures(*parts_[i], featureRadius_, test));
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

bool CollisionWorld::usesPointShell(BodyId a, BodyId b) const {
    if (!fields_[a] || !parts_[b]->deforms()) return false;
    return settings_.rigidDeformable == RigidDeformableQuery::PointShell || meanEdge_[b] < meanEdge_[a];
}

}  // namespace flexfit
