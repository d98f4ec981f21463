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

// What adding a part changes in the point shell's service: the rigid parts it makes the point
// shell serve (their fields and features), and its own entries.
struct CollisionWorld::ServiceEntry {
    std::size_t part = 0;
    double radius = 0.0;  // the features' scale
    std::shared_ptr<const SignedDistanceField> field;
    bool tried = false;
    std::shared_ptr<const SharpFeatures> features;
};
struct CollisionWorld::ServiceChange {
    std::vector<ServiceEntry> served;  // rigid parts already added
    ServiceEntry added;                // the new part
    bool addedServes = false;   // the new part (rigid) serves a deforming part already added
};

CollisionWorld::ServiceChange CollisionWorld::serviceChange(const Part& part, double meanEdge, double resolution) const {
    // A rigid part's features are found at the scale of the coarsest deformable part its point
    // shell may serve: the scale they have, grown to the new part's where it deforms; all of
    // those it may serve, where it is the rigid one. Only parts of the other kind can change
    // (O(their count), not O(all parts)).
    ServiceChange change;
    const std::size_t self = parts_.size();
    change.added.part = self;
    if (settings_.rigidDeformable == RigidDeformableQuery::Faces) return change;
    for (const BodyId other : part.deforms() ? rigidParts_ : deformingParts_) {
        if (part.deforms()) {
            if (pointShellServes(meanEdge_[other], meanEdge))
                change.served.push_back({other, std::max(features_[other] ? features_[other]->radius : 0.0, resolution), fields_[other],
                                         fieldTried_[other], features_[other]});
        } else if (pointShellServes(meanEdge, meanEdge_[other])) {
            change.addedServes = true;
            change.added.radius = std::max(change.added.radius, restResolution_[other]);
        }
    }
    for (ServiceEntry& entry : change.served) equip(entry, *parts_[entry.part], true);
    equip(change.added, part, change.addedServes);
    return change;
}

void CollisionWorld::equip(ServiceEntry& entry, const Part& rigid, bool serves) const {
    // Fields for the rigid parts the point shell may serve (under PointShell all of them), and
    // their features at the scale they now serve.
    const RigidDeformableQuery query = settings_.rigidDeformable;
    if (query == RigidDeformableQuery::Faces || rigid.deforms()) return;
    if (!entry.tried && (query != RigidDeformableQuery::Auto || serves)) {
        entry.field = buildDistanceField(rigid);
        entry.tried = true;
    }
    if (entry.field && (!entry.features || entry.features->radius != entry.radius))
        entry.features = std::make_shared<const SharpFeatures>(findSharpFeatures(rigid, entry.radius, settings_.exactTest));
}

void CollisionWorld::reserveRegistry(std::size_t bodies, bool deforms) {
    detail::reserveGrowing(parts_, bodies);
    detail::reserveGrowing(colliders_, bodies);
    for (auto* v : {&meanEdge_, &restResolution_}) detail::reserveGrowing(*v, bodies);
    detail::reserveGrowing(fields_, bodies);
    detail::reserveGrowing(features_, bodies);
    for (auto* v : {&fieldTried_, &fixed_}) detail::reserveGrowing(*v, bodies);
    detail::reserveGrowing(partSpheres_, bodies);
    for (auto* v : {&movingIds_, &fixedIds_}) detail::reserveGrowing(*v, bodies);  // room for every body: setMoving never allocates
    std::vector<BodyId>& kind = deforms ? deformingParts_ : rigidParts_;
    detail::reserveGrowing(kind, kind.size() + 1);
    refitted_.growTo(bodies);
}

void CollisionWorld::add(BodyId id, const Part& part, BoundingVolumeKind kind, Mobility mobility) {
    if (id != parts_.size())
        throw std::invalid_argument("CollisionWorld::add: body " + std::to_string(id) + " out of order (expected " +
                                    std::to_string(parts_.size()) + ")");
    const bool isFixed = mobility == Mobility::Fixed;
    if (isFixed && part.deforms()) throw std::invalid_argument("CollisionWorld::add: body " + std::to_string(id) + " deforms: it cannot be fixed");
    // Everything is built before anything is registered: a failure (out of memory) leaves the
    // collision world as it was. Fields, sharp features and rest-point trees are built now
    // rather than at the first contact, where they would stall a haptic loop.
    PartCollider collider(part, kind, settings_.exactTest);
    const bool shellable = settings_.rigidDeformable != RigidDeformableQuery::Faces && part.deforms();
    if (shellable) collider.buildRestPointTree(part);
    const double meanEdge = meanRestEdge(part), resolution = shellable ? restResolution(part) : 0.0;
    ServiceChange change = serviceChange(part, meanEdge, resolution);
    const Sphere sphere = collider.worldSphere(part);
    reserveRegistry(parts_.size() + 1, part.deforms());
    // Nothing below throws.
    (part.deforms() ? deformingParts_ : rigidParts_).push_back(id);
    (isFixed ? fixedIds_ : movingIds_).push_back(id);
    (isFixed ? fixedTreeBuilt_ : broadPhaseBuilt_) = false;  // built at the next update, once for any number of adds
    parts_.push_back(&part);
    colliders_.push_back(std::move(collider));
    meanEdge_.push_back(meanEdge);
    restResolution_.push_back(resolution);
    fields_.push_back(std::move(change.added.field));
    fieldTried_.push_back(change.added.tried);
    features_.push_back(std::move(change.added.features));
    fixed_.push_back(isFixed);
    partSpheres_.push_back(sphere);
    for (ServiceEntry& entry : change.served) {
        fields_[entry.part] = std::move(entry.field);
        fieldTried_[entry.part] = entry.tried;
        features_[entry.part] = std::move(entry.features);
    }
}

void CollisionWorld::setMoving(BodyId id) {
    if (id >= parts_.size()) throw std::invalid_argument("CollisionWorld::setMoving: no body " + std::to_string(id));
    if (!fixed_[id]) return;
    fixed_[id] = false;
    fixedIds_.erase(std::find(fixedIds_.begin(), fixedIds_.end(), id));
    movingIds_.insert(std::upper_bound(movingIds_.begin(), movingIds_.end(), id), id);  // within the room add() kept
    fixedTreeBuilt_ = broadPhaseBuilt_ = false;
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

bool CollisionWorld::pointShellServes(double rigidMeanEdge, double deformableMeanEdge) const {
    switch (settings_.rigidDeformable) {
        case RigidDeformableQuery::Faces: return false;
        case RigidDeformableQuery::PointShell: return true;
        case RigidDeformableQuery::Auto: return deformableMeanEdge < rigidMeanEdge;
    }
    return false;
}

bool CollisionWorld::usesPointShell(BodyId a, BodyId b) const {
    return fields_[a] && parts_[b]->deforms() && pointShellServes(meanEdge_[a], meanEdge_[b]);
}

}  // namespace flexfit
