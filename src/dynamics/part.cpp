#include "flexfit/part.hpp"
#include "flexfit/surface_embedding.hpp"

#include "divergence.hpp"
#include "region_step.hpp"
#include "model/kring.hpp"
#include "model/spring_blocks.hpp"
#include "core/lanes256.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace flexfit {
namespace {

constexpr std::uint64_t kNeverLoaded = std::numeric_limits<std::uint64_t>::max();
const std::string kPartSource = "part";

void checkZoneSettings(const ZoneSettings& z) {
    if (z.defaultLevel < 0 || z.defaultLevel > 255) throw InputError("zone settings", 0, "default level must be in [0, 255]");
    if (z.contactLevel < 0 || z.contactLevel > 255) throw InputError("zone settings", 0, "contact level must be in [0, 255]");
    if (!(z.activityThreshold > 0.0) || !std::isfinite(z.activityThreshold))
        throw InputError("zone settings", 0, "activity threshold must be finite and > 0");
    if (!(z.restSpeed >= 0.0) || !std::isfinite(z.restSpeed))
        throw InputError("zone settings", 0, "rest speed must be finite and >= 0");
    if (z.retireCheckInterval < 1) throw InputError("zone settings", 0, "retire check interval must be >= 1");
    if (z.reservedZones < 0 || z.reservedZones > 65535) throw InputError("zone settings", 0, "reserved zones must be in [0, 65535]");
}

// The most masses a zone of `level` covers: its ring from the face with the largest, or a
// single mass's where the model has no face.
std::size_t largestZone(const PartModel& model, KRingWalker& walker, int level) {
    if (level == 0) return 0;
    std::vector<RingMember> ring;
    std::size_t largest = model.massCount() > 0 ? 1 : 0;
    for (const Face& f : model.mesh.faces) {
        walker.collect(model.topology, f, level - 1, ring);
        largest = std::max(largest, ring.size());
    }
    return largest;
}

}  // namespace


struct Part::Zone {
    ZoneId id = kNoZone;
    std::vector<Index> seeds;
    int level = 0;
    std::vector<RingMember> members;
};

std::optional<DefaultFractionElsewhere> defaultFractionAt(const PartSettings& part, double timeStep) {
    if (part.mode == PartMode::Rigid) return std::nullopt;
    return defaultFractionAt(part.simulation.restoration, timeStep);
}

namespace {
std::shared_ptr<const PartModel> requireModel(std::shared_ptr<const PartModel> model) {
    if (!model) throw InputError(kPartSource, 0, "a part needs a model (given none)");
    return model;
}
}  // namespace

Part::Part(std::shared_ptr<const PartModel> model, const PartSettings& settings)
    : model_(requireModel(std::move(model))),
      settings_(settings),
      state_(PartState::atRest(*model_)),
      walker_(std::make_unique<KRingWalker>(model_->massCount())),
      region_(*model_),
      lastLoadStep_(model_->massCount(), kNeverLoaded),
      changed_(model_->massCount()) {
    requireNamedValue<InputError>(settings_.mode, kPartSource, "part mode");
    validateSettings(settings_.simulation);
    checkZoneSettings(settings_.zones);
    if (settings_.mode == PartMode::FullDeformable)  // every mass moves, always: the region is the mesh
        for (Index m = 0; m < model_->massCount(); ++m) region_.cover(m);
    reserveSettingsZones();
}

Part::~Part() = default;
Part::Part(Part&&) noexcept = default;
Part& Part::operator=(Part&&) noexcept = default;

// Everything but the k-ring walker, which is scratch: a copy gets its own.
Part::Part(const Part& other)
    : model_(other.model_),
      settings_(other.settings_),
      pose_(other.pose_),
      state_(other.state_),
      walker_(std::make_unique<KRingWalker>(other.model_->massCount())),
      zones_(other.zones_),
      nextZoneId_(other.nextZoneId_),
      region_(other.region_),
      lastLoadStep_(other.lastLoadStep_),
      changed_(other.changed_),
      regionStepped_(other.regionStepped_),
      allChanged_(other.allChanged_),
      allMasses_(other.allMasses_) {}

Part& Part::operator=(const Part& other) {
    if (this != &other) *this = Part(other);
    return *this;
}

void Part::setSettings(const PartSettings& settings) {
    if (settings.mode != settings_.mode) throw InputError("part settings", 0, "the mode of a part cannot change");
    validateSettings(settings.simulation);
    checkZoneSettings(settings.zones);
    settings_ = settings;
    reserveSettingsZones();
}

// --- Pose ---

void Part::setPose(const Pose& pose) {
    checkPose(pose, kPartSource, "setPose");
    detail::setPoseUnchecked(*this, pose);
}

void detail::setPoseUnchecked(Part& part, const Pose& pose) {
    part.pose_ = pose;
    part.pose_.rotation.normalize();
}

void Part::translate(const Vec3& offset) {
    if (!(pose_.translation + offset).allFinite()) throw InputError(kPartSource, 0, "translate: the offset must be finite, and the position stay so");
    pose_.translation += offset;
}

void Part::rotateAbout(const Vec3& axis, double angle, const Vec3& point) {
    const double length = axis.norm();
    if (!(length > 0.0) || !std::isfinite(length) || !std::isfinite(angle) || !point.allFinite())
        throw InputError(kPartSource, 0, "rotation needs a finite non-zero axis, angle and point");
    Pose turn;
    turn.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized()));
    turn.translation = point - turn.rotation * point;
    pose_ = pose_.then(turn);
}

void Part::rotate(const Vec3& axis, double angle) { rotateAbout(axis, angle, centre()); }

bool Part::isMoving(Index mass) const {
    requireMass(mass, "isMoving");
    return region_.moves(mass);
}

Vec3 Part::worldPosition(Index mass) const {
    requireMass(mass, "worldPosition");
    return pose_.apply(state_.positions[mass]);
}

void Part::requireMass(Index mass, const char* what) const {
    if (mass >= model_->massCount())
        throw InputError(kPartSource, 0, std::string(what) + ": mass " + std::to_string(mass) + " does not exist (the model has " +
                                             std::to_string(model_->massCount()) + " masses)");
}

Vec3 Part::centre() const { return pose_.apply(boundingBox(model_->mesh).center()); }

// --- Active region bookkeeping ---

// A mass that stops moving returns exactly to rest.
void Part::returnToRest(Index mass) {
    state_.positions[mass] = model_->restPositions[mass];
    state_.velocities[mass] = Vec3::Zero();
    state_.forces[mass] = Vec3::Zero();
    markChanged(mass);
}

void Part::markChanged(Index mass) {
    if (!allChanged_) changed_.insert(mass);
}

void Part::markAllChanged() {
    if (allMasses_.empty()) {
        allMasses_.resize(model_->massCount());
        std::iota(allMasses_.begin(), allMasses_.end(), Index{0});
    }
    allChanged_ = true;
}

std::span<const Index> Part::changedMasses() const {
    if (allChanged_) return allMasses_;
    if (regionStepped_) {
        for (Index m : region_.masses()) changed_.insert(m);
        regionStepped_ = false;
    }
    return changed_.members();
}

void Part::clearChangedMasses() {
    changed_.clear();
    regionStepped_ = false;
    allChanged_ = false;
}

void Part::cover(const Zone& zone) {
    for (const RingMember& m : zone.members) region_.cover(m.mass);
}

void Part::uncover(const Zone& zone) {
    for (const RingMember& m : zone.members)
        if (region_.uncover(m.mass)) returnToRest(m.mass);
}

// --- Zones ---

Part::Zone* Part::findZone(ZoneId id) {
    for (Zone& z : zones_)
        if (z.id == id) return &z;
    return nullptr;
}

void Part::collectMembers(Zone& zone) {
    // Level L moves the masses within distance L-1 of a seed; level 0 moves none.
    if (zone.level == 0) {
        zone.members.clear();
        return;
    }
    walker_->collect(model_->topology, zone.seeds, zone.level - 1, zone.members);
}

ZoneId Part::openZone(ZoneSeed seed, int level) {
    if (level < 0 || level > 255) throw InputError(kPartSource, 0, "zone level " + std::to_string(level) + " is outside [0, 255]");
    if (zones_.size() >= kMaxOpenZones)  // a mass counts the zones covering it in 16 bits
        throw InputError(kPartSource, 0, "a part keeps at most " + std::to_string(kMaxOpenZones) + " zones open at once");
    Zone zone = spareZone();
    zone.id = nextZoneId_;
    zone.level = level;
    if (seed.kind == ZoneSeed::Kind::Mass) {
        if (seed.index >= model_->massCount())
            throw InputError(kPartSource, 0, "zone seed mass " + std::to_string(seed.index) + " does not exist (the model has " +
                                                 std::to_string(model_->massCount()) + " masses)");
        zone.seeds.assign(1, seed.index);
    } else {
        if (seed.index >= model_->faceCount())
            throw InputError(kPartSource, 0, "zone seed face " + std::to_string(seed.index) + " does not exist (the model has " +
                                                 std::to_string(model_->faceCount()) + " faces)");
        const Face& f = model_->mesh.faces[seed.index];
        zone.seeds.assign(f.begin(), f.end());
    }
    if (settings_.mode != PartMode::RigidDeformable) {
        keepSpare(std::move(zone));
        return kNoZone;
    }
    ++nextZoneId_;
    collectMembers(zone);
    cover(zone);
    zones_.push_back(std::move(zone));
    return zones_.back().id;
}

void Part::setZoneLevel(ZoneId id, int level) {
    if (level < 0 || level > 255) throw InputError(kPartSource, 0, "zone level " + std::to_string(level) + " is outside [0, 255]");
    Zone* zone = findZone(id);
    if (zone == nullptr || zone->level == level) return;
    // Cover the new members before uncovering the old, so masses in both keep their state.
    Zone old = spareZone();
    old.level = zone->level;
    std::swap(old.members, zone->members);
    zone->level = level;
    collectMembers(*zone);
    cover(*zone);
    uncover(old);
    keepSpare(std::move(old));
}

void Part::retireZone(ZoneId id) {
    auto it = std::find_if(zones_.begin(), zones_.end(), [id](const Zone& z) { return z.id == id; });
    if (it == zones_.end()) return;
    uncover(*it);
    keepSpare(std::move(*it));
    zones_.erase(it);
}

void Part::reserveZones(std::size_t zones, int level) {
    if (level < 0 || level > 255) throw InputError(kPartSource, 0, "zone level " + std::to_string(level) + " is outside [0, 255]");
    if (zones > 65535) throw InputError(kPartSource, 0, "cannot reserve " + std::to_string(zones) + " zones (at most 65,535)");
    if (settings_.mode != PartMode::RigidDeformable || zones == 0) return;
    if (zones <= reservedZones_ && level <= reservedLevel_) return;  // the room is there: no walk again
    zones = std::max(zones, reservedZones_);
    level = std::max(level, reservedLevel_);
    const std::size_t members = largestZone(*model_, *walker_, level);
    region_.reserveWholeModel();
    changed_.reserve(model_->massCount());
    retiring_.reserve(model_->massCount());
    walker_->reserve(members);
    zones_.reserve(zones);
    // Re-levelling a zone takes one list more than the open zones, for its old members.
    const std::size_t lists = zones + 1;
    spareZones_.reserve(lists);
    auto makeRoom = [members](Zone& zone) {
        zone.seeds.reserve(3);
        zone.members.reserve(members);
    };
    for (Zone& zone : zones_) makeRoom(zone);
    for (Zone& zone : spareZones_) makeRoom(zone);
    while (zones_.size() + spareZones_.size() < lists) makeRoom(spareZones_.emplace_back());
    reservedZones_ = zones;
    reservedLevel_ = level;
}

void Part::reserveSettingsZones() {
    const ZoneSettings& z = settings_.zones;
    reserveZones(std::size_t(z.reservedZones), std::max(z.defaultLevel, z.contactLevel));
}

Part::Zone Part::spareZone() {
    if (spareZones_.empty()) return Zone{};
    Zone zone = std::move(spareZones_.back());
    spareZones_.pop_back();
    return zone;
}

void Part::keepSpare(Zone&& zone) { spareZones_.push_back(std::move(zone)); }

std::size_t Part::zoneCount() const { return zones_.size(); }

std::vector<ZoneId> Part::zoneIds() const {
    std::vector<ZoneId> ids;
    for (const Zone& z : zones_) ids.push_back(z.id);
    return ids;
}

// --- Loads ---

bool Part::loadMass(Index mass, const Vec3& worldLoad, const char* what) {
    if (mass >= model_->massCount())
        throw InputError(kPartSource, 0, "mass " + std::to_string(mass) + " does not exist (the model has " +
                                             std::to_string(model_->massCount()) + " masses)");
    if (!worldLoad.allFinite()) throw InputError(kPartSource, 0, std::string(what) + " must be finite");
    if (settings_.mode == PartMode::Rigid) return false;
    if (settings_.mode == PartMode::RigidDeformable) {
        if (!region_.moves(mass)) openZone(ZoneSeed::mass(mass), std::max(settings_.zones.defaultLevel, 1));
        lastLoadStep_[mass] = state_.stepCount;  // keeps the zones covering it alive
    }
    return true;
}

void Part::applyForce(Index mass, const Vec3& worldForce) {
    if (loadMass(mass, worldForce, "force")) state_.forces[mass] += pose_.rotateInverse(worldForce);
}

void Part::kickMass(Index mass, const Vec3& worldVelocityChange) {
    if (!loadMass(mass, worldVelocityChange, "velocity kick")) return;
    state_.velocities[mass] += pose_.rotateInverse(worldVelocityChange);
    markChanged(mass);
}

// --- Step ---

void Part::step(StepCounters* counters) {
    const double start = state_.time;
    if (!advance({settings_.simulation.timeStep, settings_.simulation.gravity}, counters))
        detail::checkRegionFinite(*model_, settings_.simulation, state_, region_, std::nullopt, start);
    retireRestingZones();
}

bool Part::advance(const StepContext& context, StepCounters* counters) {
    if (region_.empty()) {  // rigid, or no zone open: nothing moves, O(1)
        state_.time += context.timeStep;
        ++state_.stepCount;
        return true;
    }
    SimulationSettings s = settings_.simulation;
    s.timeStep = context.timeStep;
    s.gravity = pose_.rotateInverse(context.gravity);  // world gravity seen in the part frame
    bool checked = true;  // the full model's step checks every mass itself (and throws)
    if (region_.coversEveryMass() && settings_.zones.fullSweepWhenComplete)
        detail::stepAllMasses(*model_, s, {}, nullptr, state_, counters);  // stepFullModel without its entry checks: the part checked its settings
    // The implicit solve holds a region's edge fixed; the full step would solve for it too.
    else if (settings_.zones.fullStepWhenCheaper && s.integrator != Integrator::ImplicitEuler &&
             fullStepCostsLess(*model_, RegionWork::of(region_)))
        detail::stepRegionByFullModelFromRest(*model_, s, region_, state_, counters);  // the held masses are at rest
    else {
        detail::PositionCheck check(model_->positionBound);
        detail::stepRegion(*model_, s, region_, state_, counters, &check);
        checked = check.passed();
    }
    if (region_.coversEveryMass())
        markAllChanged();
    else
        regionStepped_ = true;  // changedMasses() adds the region's masses when read
    return checked;
}

// --- Contacts ---

void Part::touchFace(Index face) {
    if (face >= model_->faceCount())
        throw InputError(kPartSource, 0, "face " + std::to_string(face) + " does not exist (the model has " +
                                             std::to_string(model_->faceCount()) + " faces)");
    if (settings_.mode == PartMode::Rigid) return;
    const Face& f = model_->mesh.faces[face];
    if (settings_.mode == PartMode::RigidDeformable && !(region_.moves(f[0]) && region_.moves(f[1]) && region_.moves(f[2])))
        openZone(ZoneSeed::face(face), std::max(settings_.zones.contactLevel, 1));
    for (Index m : f) lastLoadStep_[m] = state_.stepCount;
}

void Part::displaceMass(Index mass, const Vec3& worldDisplacement) {
    if (!worldDisplacement.allFinite()) throw InputError(kPartSource, 0, "displaceMass: the displacement must be finite");
    applyDisplacement(mass, worldDisplacement);
}

void Part::applyDisplacement(Index mass, const Vec3& worldDisplacement) {
    if (!displaces(mass)) return;
    const Vec3 d = pose_.rotateInverse(worldDisplacement);
    state_.positions[mass] += d;
    const double length = d.norm();
    if (length > 0.0) {
        const Vec3 direction = d / length;
        const double against = state_.velocities[mass].dot(direction);
        if (against < 0.0) state_.velocities[mass] -= against * direction;
    }
    markChanged(mass);
}

#if defined(FLEXFIT_LANES256)
namespace {

// displaceMass's arithmetic for 4 moving masses (lanes256.hpp's orders, the same bits): the
// displacement turned into the part's frame, the positions moved, the velocities' components
// against it removed.
FLEXFIT_AVX2_LANES void displaceFour(const Eigen::Quaterniond& rotation, const Index* masses, const Vec3* worldDisplacements, PartState& state) {
    using namespace detail::lanes;
    const Lanes3 d = rotate(broadcast(rotation.conjugate()), gather([&](int j) -> const Vec3& { return worldDisplacements[j]; }));
    const Lanes3 moved = add(gather([&](int j) -> const Vec3& { return state.positions[masses[j]]; }), d);
    const __m256d zero = _mm256_setzero_pd(), length = _mm256_sqrt_pd(dot(d, d));
    const Lanes3 direction = divide(d, length);
    const Lanes3 v = gather([&](int j) -> const Vec3& { return state.velocities[masses[j]]; });
    const __m256d against = dot(v, direction);
    // Only where length > 0 and against < 0 (NaN: neither, as the scalar tests).
    const __m256d removes = _mm256_and_pd(_mm256_cmp_pd(length, zero, _CMP_GT_OQ), _mm256_cmp_pd(against, zero, _CMP_LT_OQ));
    const Lanes3 slowed = sub(v, scale(against, direction));
    const Stored3 positions = store(moved), velocities = store({_mm256_blendv_pd(v.x, slowed.x, removes), _mm256_blendv_pd(v.y, slowed.y, removes),
                                                                 _mm256_blendv_pd(v.z, slowed.z, removes)});
    for (int j = 0; j < 4; ++j) {
        state.positions[masses[j]] = positions[j];
        state.velocities[masses[j]] = velocities[j];
    }
}

}  // namespace
#endif

void Part::displaceMasses(std::span<const Index> masses, std::span<const Vec3> worldDisplacements) {
    for (std::size_t i = 0; i < worldDisplacements.size(); ++i)
        if (!worldDisplacements[i].allFinite())
            throw InputError(kPartSource, 0, "displaceMasses: displacement " + std::to_string(i) + " is not finite");
    detail::displaceMassesUnchecked(*this, masses, worldDisplacements);
}

void detail::displaceMassesUnchecked(Part& part, std::span<const Index> masses, std::span<const Vec3> worldDisplacements) {
    if (masses.size() != worldDisplacements.size())
        throw InputError(kPartSource, 0, "displaceMasses: " + std::to_string(masses.size()) + " masses but " +
                                             std::to_string(worldDisplacements.size()) + " displacements");
    part.applyDisplacements(masses, worldDisplacements);
}

void Part::applyDisplacements(std::span<const Index> masses, std::span<const Vec3> worldDisplacements) {
    std::size_t i = 0;
#if defined(FLEXFIT_LANES256)
    if (detail::lanesEnabled())
        for (; i + 4 <= masses.size(); i += 4) {
            const Index* four = &masses[i];
            const bool distinct = four[0] != four[1] && four[0] != four[2] && four[0] != four[3] && four[1] != four[2] &&
                                  four[1] != four[3] && four[2] != four[3];
            if (!(distinct && displaces(four[0]) && displaces(four[1]) && displaces(four[2]) && displaces(four[3]))) {
                for (int j = 0; j < 4; ++j) applyDisplacement(four[j], worldDisplacements[i + std::size_t(j)]);
                continue;
            }
            displaceFour(pose_.rotation, four, &worldDisplacements[i], state_);
            for (int j = 0; j < 4; ++j) markChanged(four[j]);
        }
#endif
    for (; i < masses.size(); ++i) applyDisplacement(masses[i], worldDisplacements[i]);
}

bool Part::zoneAtRest(const Zone& zone) const {
    const double threshold = settings_.zones.activityThreshold;
    const double restSpeed2 = settings_.zones.restSpeed * settings_.zones.restSpeed;
    const auto interval = std::uint64_t(settings_.zones.retireCheckInterval);
    // Each test is "within the threshold", so a NaN (which compares false with anything) keeps
    // the zone: a diverged zone is never retired, and the divergence check sees it.
    for (const RingMember& m : zone.members) {
        const Index i = m.mass;
        if (lastLoadStep_[i] != kNeverLoaded && state_.stepCount - lastLoadStep_[i] <= interval) return false;
        if (!(state_.velocities[i].squaredNorm() <= restSpeed2)) return false;
        if (!((state_.positions[i] - model_->restPositions[i]).norm() <= threshold)) return false;
        for (Index e : model_->springsAt(i)) {
            const double length = (state_.positions[model_->springA[e]] - state_.positions[model_->springB[e]]).norm();
            if (!(std::abs(length - model_->restLength[e]) <= threshold)) return false;
        }
    }
    return true;
}

void Part::retireRestingZones() {
    // Nothing moves: nothing to retire, in O(1) (an untouched part costs nothing here either).
    if (settings_.mode != PartMode::RigidDeformable || region_.empty()) return;
    if (state_.stepCount % std::uint64_t(settings_.zones.retireCheckInterval) != 0) return;
    // Each retiring zone's masses return to rest as it retires (the next zones' checks read
    // them), but the region's lists wait until every zone is checked (no check reads them): when
    // every zone retired, the region is emptied at once (a scene's zones often come to rest
    // together, and that step was the slowest outside contact: the lists' churn of blocks
    // dropping below their minimum and back); otherwise the masses whose last zone retired are
    // uncovered in the order they retired, which makes the same lists (uncoverUnlessLast).
    retiring_.clear();
    for (std::size_t z = 0; z < zones_.size();) {
        const Zone& zone = zones_[z];
        if (zoneAtRest(zone)) {
            for (const RingMember& m : zone.members)
                if (region_.uncoverUnlessLast(m.mass)) {
                    returnToRest(m.mass);
                    retiring_.push_back(m.mass);
                }
            keepSpare(std::move(zones_[z]));
            zones_.erase(zones_.begin() + std::ptrdiff_t(z));
        } else {
            ++z;
        }
    }
    if (zones_.empty()) return region_.clear();
    for (Index m : retiring_) region_.uncover(m);
}

// --- Read-out ---

void Part::worldPositions(std::vector<Vec3>& out) const {
    out.resize(model_->massCount());
    const Eigen::Matrix3d r = pose_.rotation.toRotationMatrix();
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = r * state_.positions[i] + pose_.translation;
}

void Part::drawnPositions(std::vector<Vec3>& out) const {
    if (model_->drawn) return embeddedPositions(*model_->drawn, model_->mesh.faces, state_.positions, out);
    vertexPositions(out);
}

void Part::drawnWorldPositions(std::vector<Vec3>& out) const {
    if (!model_->drawn) return vertexWorldPositions(out);
    drawnPositions(out);
    toWorld(out);
}

void Part::vertexPositions(std::vector<Vec3>& out) const {
    inVertexOrder(*model_, std::span<const Vec3>(state_.positions), out, [&](Index v) { return model_->file->vertices.positions[v]; });
}

void Part::vertexWorldPositions(std::vector<Vec3>& out) const {
    if (model_->massesAreVertices()) return worldPositions(out);
    vertexPositions(out);
    toWorld(out);
}

void Part::toWorld(std::vector<Vec3>& points) const {
    const Eigen::Matrix3d r = pose_.rotation.toRotationMatrix();
    for (Vec3& p : points) p = r * p + pose_.translation;
}

void Part::zoneDepths(std::vector<int>& out) const {
    out.assign(model_->massCount(), -1);
    if (settings_.mode == PartMode::FullDeformable) std::fill(out.begin(), out.end(), 0);
    for (const Zone& z : zones_)
        for (const RingMember& m : z.members)
            if (out[m.mass] < 0 || m.depth < out[m.mass]) out[m.mass] = m.depth;
}

}  // namespace flexfit
