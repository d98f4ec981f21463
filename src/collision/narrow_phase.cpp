// The narrow phase (collision_world.hpp): the contacts of candidate pairs, by face hierarchies
// or by point shell, and one body's contacts for the rigid motion's sub-steps.
#include "flexfit/collision_world.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace flexfit {
const std::vector<Contact>& CollisionWorld::narrowPhase(const KnownContacts* known) {
    refitted_.clear();
    contacts_.clear();
    stats_ = {};
    const bool knownRigid = known != nullptr && !parts_[known->body]->deforms();
    for (auto [i, j] : pairs_) {
        if (!pressesFirst(i, j)) std::swap(i, j);
        const bool covered = knownRigid && (i == known->body || j == known->body) && !parts_[i == known->body ? j : i]->deforms();
        if (!covered) {
            queryPair(i, j, contacts_, stats_);
            continue;
        }
        // contactsOf answers the same pair in the same orientation and order.
        for (const Contact& c : known->contacts)
            if (c.partA == i && c.partB == j) contacts_.push_back(c);
    }
    return contacts_;
}

void CollisionWorld::warmUp() {
    if (!settings_.coherent) return;
    updatePairs();  // not update(): the coherence clock is the steps'
    refitted_.clear();
    // The query counters as they were, however the queries end.
    struct KeptCounters {
        std::uint64_t &queries, &traversals;
        std::uint64_t queriesBefore = queries, traversalsBefore = traversals;
        ~KeptCounters() { queries = queriesBefore, traversals = traversalsBefore; }
    } kept{faceQueries_, faceTraversals_};
    std::vector<Contact> discarded;
    QueryStats ignored;
    for (auto [i, j] : pairs_) {
        if (!pressesFirst(i, j)) std::swap(i, j);
        queryPair(i, j, discarded, ignored);
        discarded.clear();
    }
}

const std::vector<Contact>& CollisionWorld::findContacts() {
    update();
    return narrowPhase();
}

const std::vector<Contact>& CollisionWorld::contactsOf(BodyId id, bool rigidPartnersOnly) {
    if (id >= parts_.size())
        throw std::invalid_argument("CollisionWorld::contactsOf: no body " + std::to_string(id) + " (" + std::to_string(parts_.size()) +
                                    " added)");
    refitted_.clear();
    bodyContacts_.clear();
    const RelativePose identity;
    if (!fixed_[id]) updateBound(id);
    // Other bodies in ascending id: the same pairs, in the same order, as the broad phase gives.
    // Only the bounds this query reads are brought up to date (a deforming part's costs
    // O(its moving masses)); fixed bodies come from their tree (none for a fixed body).
    partners_.clear();
    for (const BodyId other : movingIds_) {
        if (other == id || (rigidPartnersOnly && parts_[other]->deforms())) continue;
        updateBound(other);
        if (overlap(partSpheres_[id], partSpheres_[other], identity)) partners_.push_back(other);
    }
    if (!fixed_[id]) {
        if (!fixedTreeBuilt_) buildFixedTree();
        overlappingLeaves(fixedTree_, partSpheres_[id], leafItems_);
        for (const Index item : leafItems_) partners_.push_back(fixedIds_[item]);
    }
    std::sort(partners_.begin(), partners_.end());
    for (const BodyId other : partners_) {
        BodyId a = std::min(id, other), b = std::max(id, other);
        if (!pressesFirst(a, b)) std::swap(a, b);
        QueryStats ignored;
        queryPair(a, b, bodyContacts_, ignored);
    }
    return bodyContacts_;
}

void CollisionWorld::queryPair(BodyId a, BodyId b, std::vector<Contact>& out, QueryStats& stats) {
    if (usesPointShell(a, b)) return queryPointShellPair(a, b, out, stats);
    refitChanged(a);
    refitChanged(b);
    if (!settings_.coherent) {
        ++faceQueries_;
        ++faceTraversals_;
        return flexfit::queryPair(a, *parts_[a], colliders_[a], b, *parts_[b], colliders_[b], settings_.exactTest, out, stats);
    }
    KeptCoherence& kept = coherence_[std::uint64_t(a) << 32 | b];
    kept.lastUpdate = updates_;
    if (answerStands(kept.answer, a, b)) {  // not a face query: nothing is tested
        out.insert(out.end(), kept.answer.contacts.begin(), kept.answer.contacts.end());
        stats.contacts += kept.answer.contacts.size();
        return;
    }
    ++faceQueries_;
    // Lists taken, and the whole traversals that answered instead of a list.
    const auto traversed = [&] { return kept.coherence.traversals + kept.coherence.plainTraversals; };
    const std::uint64_t before = traversed();
    const std::size_t first = out.size();
    queryPairCoherent(a, *parts_[a], colliders_[a], b, *parts_[b], colliders_[b], settings_.exactTest, kept.coherence, out, stats);
    faceTraversals_ += traversed() - before;
    keepAnswer(kept.answer, a, b, std::span<const Contact>(out).subspan(first));
}

bool CollisionWorld::answerStands(const Answer& answer, BodyId a, BodyId b) const {
    return answer.kept && samePose(answer.poseA, parts_[a]->pose()) && samePose(answer.poseB, parts_[b]->pose());
}

void CollisionWorld::keepAnswer(Answer& answer, BodyId a, BodyId b, std::span<const Contact> found) const {
    answer.kept = !parts_[a]->deforms() && !parts_[b]->deforms();
    if (!answer.kept) return;
    answer.poseA = parts_[a]->pose();
    answer.poseB = parts_[b]->pose();
    answer.contacts.assign(found.begin(), found.end());
}

void CollisionWorld::queryPointShellPair(BodyId a, BodyId b, std::vector<Contact>& out, QueryStats& stats) {
    const SignedDistanceField& field = *fields_[a];
    if (!settings_.coherent) {
        queryPointShell(a, *parts_[a], field, b, *parts_[b], colliders_[b].restPointTree(), out, stats);
    } else {
        KeptCoherence& kept = coherence_[std::uint64_t(a) << 32 | b];
        kept.lastUpdate = updates_;
        queryPointShellCoherent(a, *parts_[a], field, b, *parts_[b], colliders_[b].restPointTree(), colliders_[b].localSphere(),
                                kept.pointShell, out, stats);
    }
    // The sharp faces, against B's faces as they are now: a face query, traversed every time.
    if (features_[a]->empty()) return;
    refitChanged(b);
    ++faceQueries_;
    ++faceTraversals_;
    querySharpFeatures(a, *parts_[a], colliders_[a], *features_[a], b, *parts_[b], colliders_[b], settings_.exactTest, out, stats);
}

void CollisionWorld::refitChanged(BodyId id) {
    const std::span<const Index> changed = parts_[id]->changedMasses();
    if (changed.empty() || refitted_.contains(id)) return;
    colliders_[id].refit(*parts_[id], changed);
    refitted_.insert(id);
}

}  // namespace flexfit
