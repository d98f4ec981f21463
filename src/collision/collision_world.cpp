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
    const RigidDeformableQuery query = settings_.rigidDeformable;
    const bool shellable = query != RigidDeformableQuery::Faces && part.deforms();
    if (shellable) collider.buildRestPointTree(part);
    // What the new part changes, built before anything is registered: its own entries, and the
    // parts whose point-shell service it changes. A rigid part's features are found at the scale
    // of the coarsest deformable part its point shell may serve: the scale they have, grown to
    // the new part's where it deforms; all of those it may serve, where it is the rigid one.
    // Only the parts of the other kind can change (O(their count), not O(all parts)).
    const std::size_t self = parts_.size();
    const double newMeanEdge = meanRestEdge(part), newResolution = shellable ? restResolution(part) : 0.0;
    struct Served {
        std::size_t part;
        double radius;
        std::shared_ptr<const SignedDistanceField> field;
        bool tried;
        std::shared_ptr<const SharpFeatures> features;
    };
    std::vector<Served> served;  // rigid parts the new part makes the point shell serve
    Served added{self, 0.0, nullptr, false, nullptr};
    bool addedServes = false;
    if (query != RigidDeformableQuery::Faces) {
        for (const BodyId other : part.deforms() ? rigidParts_ : deformingParts_) {
            const std::size_t r = part.deforms() ? other : self, b = part.deforms() ? self : other;
            const double rigidEdge = r == self ? newMeanEdge : meanEdge_[r], deformableEdge = b == self ? newMeanEdge : meanEdge_[b];
            if (!pointShellServes(rigidEdge, deformableEdge)) continue;
            if (r == self) {
                addedServes = true;
                added.radius = std::max(added.radius, restResolution_[b]);
            } else {
                served.push_back({r, std::max(features_[r] ? features_[r]->radius : 0.0, newResolution), fields_[r], fieldTried_[r], features_[r]});
            }
        }
    }
    // Fields for the rigid parts the point shell may serve (under PointShell all of them), and
    // their features at the scale they now serve.
    auto equip = [&](Served& s, const Part& rigid, bool serves) {
        if (query == RigidDeformableQuery::Faces || rigid.deforms()) return;
        if (!s.tried && (query != RigidDeformableQuery::Auto || serves)) {
            s.field = buildDistanceField(rigid);
            s.tried = true;
        }
        if (s.field && (!s.features || s.features->radius != s.radius))
            s.features = std::make_shared<const SharpFeatures>(findSharpFeatures(rigid, s.radius, settings_.exactTest));
    };
    for (Served& s : served) equip(s, *parts_[s.part], true);
    equip(added, part, addedServes);
    const std::size_t n = self + 1;
    for (auto* v : {&meanEdge_, &restResolution_}) detail::reserveGrowing(*v, n);
    detail::reserveGrowing(parts_, n);
    detail::reserveGrowing(colliders_, n);
    detail::reserveGrowing(fields_, n);
    detail::reserveGrowing(features_, n);
    detail::reserveGrowing(fieldTried_, n);
    detail::reserveGrowing(partSpheres_, n);
    detail::reserveGrowing(fixed_, n);
    detail::reserveGrowing(movingIds_, n);  // room for every body: setMoving never allocates
    detail::reserveGrowing(fixedIds_, n);
    detail::reserveGrowing(part.deforms() ? deformingParts_ : rigidParts_, (part.deforms() ? deformingParts_ : rigidParts_).size() + 1);
    const Sphere sphere = collider.worldSphere(part);
    refitted_.growTo(n);
    // Nothing below throws.
    parts_.push_back(&part);
    colliders_.push_back(std::move(collider));
    meanEdge_.push_back(newMeanEdge);
    restResolution_.push_back(newResolution);
    fields_.push_back(std::move(added.field));
    fieldTried_.push_back(added.tried);
    features_.push_back(std::move(added.features));
    partSpheres_.push_back(sphere);
    (part.deforms() ? deformingParts_ : rigidParts_).push_back(BodyId(self));
    fixed_.push_back(isFixed);
    (isFixed ? fixedIds_ : movingIds_).push_back(BodyId(self));
    (isFixed ? fixedTreeBuilt_ : broadPhaseBuilt_) = false;
    for (Served& s : served) {
        fields_[s.part] = std::move(s.field);
        fieldTried_[s.part] = s.tried;
        features_[s.part] = std::move(s.features);
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
