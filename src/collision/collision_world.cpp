#include "flexfit/collision_world.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace flexfit {
namespace {

double effectivePartStiffness(const Part& part) {
    const PartModel& m = part.model();
    const double springs = m.springCount() ? std::accumulate(m.stiffness.begin(), m.stiffness.end(), 0.0) / double(m.springCount()) : 0.0;
    const double meanMass = std::accumulate(m.mass.begin(), m.mass.end(), 0.0) / double(m.massCount());
    const SimulationSettings& s = part.settings().simulation;
    switch (s.restoration.method) {
        case RestorationMethod::AnchorSprings: return springs + s.restoration.anchorStiffness;
        case RestorationMethod::Constraint:
            return springs + s.restoration.constraintFraction * meanMass / (s.timeStep * s.timeStep);
        case RestorationMethod::None: break;
    }
    return springs;
}

bool deformable(const Part& p) { return p.mode() != PartMode::Rigid; }

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

const char* toString(RigidDeformableQuery query) { return query == RigidDeformableQuery::PointShell ? "point-shell" : "faces"; }

CollisionWorld::CollisionWorld(CollisionSettings settings) : settings_(settings) {}

std::uint32_t CollisionWorld::add(Part& part, BoundingVolumeKind kind) {
    parts_.push_back(&part);
    colliders_.emplace_back(part, kind, settings_.exactTest);
    stiffness_.push_back(effectivePartStiffness(part));
    // Fields and rest-point trees are built now rather than at the first contact, where they
    // would stall a haptic loop.
    const bool pointShell = settings_.rigidDeformable == RigidDeformableQuery::PointShell;
    fields_.push_back(pointShell && !deformable(part) ? buildDistanceField(part) : nullptr);
    if (pointShell && deformable(part)) colliders_.back().restPointTree(part);
    pushedMarks_.emplace_back();
    pushSlot_.emplace_back();
    part.clearChangedMasses();
    partSpheres_.push_back(colliders_.back().worldSphere(part));
    broadPhase_.build(partSpheres_);  // the tree's shape changes with the set of parts
    return std::uint32_t(parts_.size() - 1);
}

void CollisionWorld::refreshStiffness(std::uint32_t id) { stiffness_[id] = effectivePartStiffness(*parts_[id]); }

void CollisionWorld::setExactTest(ExactTest test) {
    if (test == settings_.exactTest) return;
    settings_.exactTest = test;
    for (std::size_t i = 0; i < parts_.size(); ++i) colliders_[i] = PartCollider(*parts_[i], colliders_[i].kind(), test);
}

void CollisionWorld::update() {
    updateBounds();
    updateBroadPhase();
}

void CollisionWorld::updateBounds() {
    for (std::size_t i = 0; i < parts_.size(); ++i) {
        colliders_[i].updateDisplacementBound(*parts_[i]);
        partSpheres_[i] = colliders_[i].worldSphere(*parts_[i]);
    }
}

const PartCollider& CollisionWorld::collider(std::uint32_t id) {
    Part& part = *parts_[id];
    if (!part.changedMasses().empty()) {
        colliders_[id].refit(part, part.changedMasses());
        part.clearChangedMasses();
    }
    return colliders_[id];
}

const std::vector<Contact>& CollisionWorld::contactsOf(std::uint32_t id, bool rigidPartnersOnly) {
    updateBounds();
    partContacts_.clear();
    const RelativePose identity;
    // Other parts in ascending id: the same pairs, in the same order, as the broad phase gives.
    for (std::uint32_t other = 0; other < parts_.size(); ++other) {
        if (other == id || !overlap(partSpheres_[id], partSpheres_[other], identity)) continue;
        if (rigidPartnersOnly && parts_[other]->mode() != PartMode::Rigid) continue;
        std::uint32_t a = std::min(id, other), b = std::max(id, other);
        if (!pressesFirst(a, b)) std::swap(a, b);
        QueryStats ignored;
        queryCandidates(a, b, partContacts_, ignored);
    }
    return partContacts_;
}

void CollisionWorld::updateBroadPhase() {
    if (settings_.broadPhase == BroadPhaseUpdate::Rebuild)
        broadPhase_.build(partSpheres_);
    else
        broadPhase_.refitAll([&](Index i) { return partSpheres_[i]; });
    // Each part's sphere against the tree, depth-first.
    pairs_.clear();
    const RelativePose identity;
    std::vector<std::int32_t> stack;
    const auto& nodes = broadPhase_.nodes();
    for (std::uint32_t i = 0; i < partSpheres_.size(); ++i) {
        stack.assign(1, 0);
        while (!stack.empty()) {
            const auto& node = nodes[std::size_t(stack.back())];
            stack.pop_back();
            if (!overlap(partSpheres_[i], node.volume, identity)) continue;
            if (!node.isLeaf()) {
                stack.push_back(node.right);
                stack.push_back(node.left);
            } else if (node.item > i) {
                pairs_.emplace_back(i, node.item);
            }
        }
    }
    std::sort(pairs_.begin(), pairs_.end());
}

bool CollisionWorld::pressesFirst(std::uint32_t a, std::uint32_t b) const {
    const bool da = deformable(*parts_[a]), db = deformable(*parts_[b]);
    return da == db ? a < b : !da;
}

const std::vector<Contact>& CollisionWorld::findContacts() {
    update();
    return narrowPhase();
}

const std::vector<Contact>& CollisionWorld::narrowPhase() {
    contacts_.clear();
    stats_ = {};
    for (auto [i, j] : pairs_) {
        if (!pressesFirst(i, j)) std::swap(i, j);
        queryCandidates(i, j, contacts_, stats_);
    }
    return contacts_;
}

void CollisionWorld::queryCandidates(std::uint32_t a, std::uint32_t b, std::vector<Contact>& out, QueryStats& stats) {
    // A field exists only for a rigid part under the point-shell setting.
    if (const SignedDistanceField* field = fields_[a].get(); field != nullptr && deformable(*parts_[b]))
        return queryPointShell(a, *parts_[a], *field, b, *parts_[b], colliders_[b].restPointTree(*parts_[b]), out, stats);
    queryPair(a, *parts_[a], collider(a), b, *parts_[b], collider(b), settings_.exactTest, out, stats);
}



ResponseStats CollisionWorld::respond(std::span<const Contact> contacts) {
    ResponseStats stats;
    // The deepest push of each (part, mass), kept in a slot per mass in first-contact order
    // (deterministic; each mass then moves once, independently of the others).
    for (EpochMarks& pushed : pushedMarks_) pushed.clear();
    pushes_.clear();
    // Pushes the face's masses, or only `mass` when the contact has one (point shell).
    auto pushFace = [&](std::uint32_t id, Index face, Index mass, const Vec3& displacement) {
        Part& part = *parts_[id];
        part.touchFace(face);
        EpochMarks& pushed = pushedMarks_[id];
        auto& slots = pushSlot_[id];
        if (pushed.size() == 0) {
            pushed.reset(part.model().massCount());
            slots.assign(part.model().massCount(), 0u);
        }
        for (Index m : pressedMasses(part.model().mesh.faces[face], mass)) {
            if (pushed.insert(m)) {
                slots[m] = Index(pushes_.size());
                pushes_.push_back({(std::uint64_t(id) << 32) | m, displacement});
            } else if (displacement.squaredNorm() > pushes_[slots[m]].second.squaredNorm()) {
                pushes_[slots[m]].second = displacement;
            }
        }
    };
    for (const Contact& c : contacts) {
        const bool da = deformable(*parts_[c.partA]), db = deformable(*parts_[c.partB]);
        if (!da && !db) continue;
        const double ka = stiffness_[c.partA], kb = stiffness_[c.partB];
        const double shareA = da && db ? (ka + kb > 0 ? kb / (ka + kb) : 0.5) : (da ? 1.0 : 0.0);
        if (shareA > 0.0) pushFace(c.partA, c.faceA, kNoMass, (c.depth * shareA) * c.normal);
        if (shareA < 1.0) pushFace(c.partB, c.faceB, c.massB, (-c.depth * (1.0 - shareA)) * c.normal);
        ++stats.contacts;
    }
    for (const auto& [key, displacement] : pushes_) {
        parts_[key >> 32]->displaceMass(Index(key & 0xffffffffu), displacement);
        stats.maxDisplacement = std::max(stats.maxDisplacement, displacement.norm());
    }
    stats.displacedMasses = pushes_.size();
    return stats;
}

}  // namespace flexfit
