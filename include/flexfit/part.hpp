// A rigid-deformable part (SPEC 5, thesis 4.2): a rigid body everywhere except in deformation
// zones, where its masses move as a mass-spring-damper model.
//
// Frames. The model's rest positions live in the part frame; the pose T maps them to the world.
// A moving mass keeps its position and velocity in the part frame, so moving the part rigidly
// is O(1) and never disturbs a zone. A mass outside every zone sits at its rest position by
// construction (its "fixedPosition" T*rest is never stored).
//
// Zones. A zone has seeds (a mass, or a face's 3 masses) and a depth level L: level 0 moves
// nothing; level L moves every mass within graph distance L-1 of a seed; every spring touching
// a moving mass is computed, and masses beyond stay at their rest positions. Zones may
// overlap: the region is their union (a mass moves while any zone covers it).
//
// Active region. Moving masses and computed springs are compact index sets kept incrementally
// (active_region.hpp): opening, growing, shrinking or retiring a zone costs what it changes, and
// a step costs O(moving masses + computed springs). An untouched part's step is O(1).
//
// Lifecycle. A zone opens on request or when a force is applied to a mass no zone covers; it
// stays while any of its masses was loaded in the last `retireCheckInterval` steps; every
// `retireCheckInterval` steps the zones are checked, and one retires when its springs are all
// inactive (| |d| - L | <= threshold), its masses slower than
// `restSpeed` and within `threshold` of rest. Retired masses return exactly to rest.
//
// Modes. Rigid: never deforms (zones and forces are ignored). RigidDeformable: zones.
// FullDeformable: every mass moves always (the thesis's baseline), stepped by stepFullModel.
// A zone covering the whole mesh is stepped by the same full step (fullSweepWhenComplete: spring
// blocks and listed springs), and the compact-array path gives the same trajectory up to
// summation order (tested).
//
// Stepping. step() advances a part on its own, with its settings' time step and gravity (on
// moving masses, in the part frame). A world drives its parts through the same two halves,
// advance() with the world's step context and retireRestingZones(), as two stages.
//
// Known limits: the part's own rigid-body motion (velocities, contacts) belongs to the world.
#pragma once

#include "flexfit/names.hpp"
#include "flexfit/active_region.hpp"
#include "flexfit/pose.hpp"
#include "flexfit/simulation.hpp"

#include <memory>
#include <span>
#include <vector>

namespace flexfit {

enum class PartMode { Rigid, RigidDeformable, FullDeformable };
// Its names (names.hpp).
inline constexpr EnumName<PartMode> kPartModeNames[] = {
    {PartMode::Rigid, "rigid", "rigid"},
    {PartMode::RigidDeformable, "rigid-deformable", "rigid-deformable (zones)"},
    {PartMode::FullDeformable, "full-deformable", "full-deformable"},
};
template <> inline constexpr std::span<const EnumName<PartMode>> kEnumNames<PartMode> = kPartModeNames;
inline constexpr DeprecatedName<PartMode> kPartModeOldNames[] = {{"zones", PartMode::RigidDeformable}, {"full", PartMode::FullDeformable}};
template <> inline constexpr std::span<const DeprecatedName<PartMode>> kDeprecatedNames<PartMode> = kPartModeOldNames;

struct ZoneSettings {
    int defaultLevel = 2;            // level of zones opened by forces
    int contactLevel = 2;            // level of zones opened by contacts
    double activityThreshold = 0.01; // spring activity and rest-distance threshold (length units)
    double restSpeed = 1e-3;         // masses slower than this are at rest
    int retireCheckInterval = 16;    // steps between retirement checks of an unloaded zone
    bool fullSweepWhenComplete = true;  // step a region covering every mass with stepFullModel
    // Step a region with stepFullModel, its other masses held at rest, whenever that costs less
    // (fullStepCostsLess): a part never costs much more than its whole model.
    bool fullStepWhenCheaper = true;
    // Zones that can be open at once, from the first, with no allocation (Part::reserveZones at
    // max(defaultLevel, contactLevel)): for a real-time loop whose first press must not allocate
    // either. 0: each zone's lists grow the first time it opens. At most 65,535.
    int reservedZones = 0;
};

struct PartSettings {
    PartMode mode = PartMode::RigidDeformable;
    // In a world, simulation.timeStep and simulation.gravity are not used (the world's step
    // context gives them, world.hpp), but they must still be valid: a part can be stepped alone.
    SimulationSettings simulation;
    ZoneSettings zones;
};

// defaultFractionAt (simulation.hpp) for a part's restoration: nullopt too for a rigid part.
std::optional<DefaultFractionElsewhere> defaultFractionAt(const PartSettings& part, double timeStep);

struct ZoneSeed {
    enum class Kind { Mass, Triangle } kind = Kind::Mass;
    Index index = 0;
    static ZoneSeed mass(Index m) { return {Kind::Mass, m}; }
    static ZoneSeed face(Index f) { return {Kind::Triangle, f}; }
};

using ZoneId = std::uint32_t;
inline constexpr ZoneId kNoZone = 0;

class KRingWalker;

class Part;
namespace detail {
// Part::setPose without its check, for the world's rigid motion and snapping: a pose they
// compute from a diverging body is reported by the world's divergence check, which names the
// body and the likely cause.
void setPoseUnchecked(Part& part, const Pose& pose);
// Part::displaceMasses without its finiteness check, for the world's contact response (the
// same reason).
void displaceMassesUnchecked(Part& part, std::span<const Index> masses, std::span<const Vec3> worldDisplacements);
}  // namespace detail

class Part {
public:
    // Throws InputError for invalid settings.
    explicit Part(std::shared_ptr<const PartModel> model, const PartSettings& settings = {});
    ~Part();
    Part(const Part& other);  // an independent copy: same model, settings, pose, state and zones
    Part& operator=(const Part& other);
    Part(Part&&) noexcept;
    Part& operator=(Part&&) noexcept;

    const PartModel& model() const { return *model_; }
    const std::shared_ptr<const PartModel>& sharedModel() const { return model_; }
    PartMode mode() const { return settings_.mode; }
    bool deforms() const { return settings_.mode != PartMode::Rigid; }
    const PartSettings& settings() const { return settings_; }
    // Live changes (restoration method and constants, damping, zone levels and thresholds):
    // the next step uses them; open zones keep their level. The mode cannot change (throws
    // InputError, as for invalid settings, and the part keeps its settings).
    void setSettings(const PartSettings& settings);

    // --- Pose (O(1)) ---
    // setPose and translate throw InputError for a pose that is not one (checkPose, pose.hpp),
    // the rotations for a non-finite or zero axis, angle or point; the pose is then unchanged.
    const Pose& pose() const { return pose_; }
    void setPose(const Pose& pose);
    void translate(const Vec3& offset);
    // Rotation by `angle` radians about `axis` (world frame) through the part's centre.
    void rotate(const Vec3& axis, double angle);
    // Rotation about an axis through a world point.
    void rotateAbout(const Vec3& axis, double angle, const Vec3& point);
    Vec3 centre() const;  // world position of the rest shape's bounding-box centre

    // --- Zones ---
    // Opens a zone; returns kNoZone in Rigid and FullDeformable modes. Throws InputError for a
    // seed out of range, a level outside [0, 255], or kMaxOpenZones zones already open.
    ZoneId openZone(ZoneSeed seed, int level);
    static constexpr std::size_t kMaxOpenZones = 65535;  // a mass's cover count is 16 bits
    void setZoneLevel(ZoneId zone, int level);
    void retireZone(ZoneId zone);
    std::size_t zoneCount() const;
    std::vector<ZoneId> zoneIds() const;
    // Room for `zones` zones open at once, each of level up to `level`, so that opening,
    // re-levelling and retiring them allocate nothing from the first zone on (without it, a
    // zone's lists grow the first time it opens: a haptic loop's first press allocates). Costs
    // one walk of the level's ring from every face, to size the largest zone, and room for the
    // whole model in the region's lists (about 45 bytes a spring). Nothing outside
    // RigidDeformable mode. Throws InputError for a level outside [0, 255] or more than 65,535
    // zones. Again with no more zones and no higher level (setSettings calls it), it does
    // nothing. A copy of the part starts without the room (scratch, as the spare lists are).
    void reserveZones(std::size_t zones, int level);

    // --- Loads, for the next step ---
    // Mass indices here and below are the model's (PartModel::massOf gives a renumbered model's
    // mass of a mesh vertex); face indices are the mesh's, in every order.
    // A world-frame force on one mass. Opens a zone (defaultLevel) when no zone covers it and
    // keeps the covering zones alive. Ignored in Rigid mode. Throws InputError for a bad mass.
    void applyForce(Index mass, const Vec3& worldForce);
    // A velocity kick: adds a world-frame velocity change to one mass at once (the thesis's
    // perturbation, chapter 5: one mass's velocity increased along x). Opens a zone
    // (defaultLevel) when none covers it. Ignored in Rigid mode. Throws InputError for a bad
    // mass or a non-finite change.
    void kickMass(Index mass, const Vec3& worldVelocityChange);

    // --- Contacts (collision response) ---
    // Opens a zone at `face` (contactLevel) unless zones already move its masses, and keeps the
    // zones there alive. Ignored in Rigid mode. Throws InputError for a bad face.
    void touchFace(Index face);
    // Moves a moving mass by a world-frame displacement and removes the part of its velocity
    // that points against it (the contact is inelastic). Ignored for masses that do not move.
    // InputError for a displacement that is not finite (displaceMasses: for any, before any moves).
    void displaceMass(Index mass, const Vec3& worldDisplacement);
    // displaceMass for each (masses[i], worldDisplacements[i]), in order: the same bits, 4 distinct
    // moving masses at a time on CPUs with AVX2 (internal lanes256.hpp). The spans must have the
    // same size (InputError otherwise), and the displacements must not be this part's own state
    // (a group of 4 reads its inputs before it writes).
    void displaceMasses(std::span<const Index> masses, std::span<const Vec3> worldDisplacements);
    // Masses whose position may have changed since clearChangedMasses(): every mass stepped or
    // displaced, and every mass that returned to rest. Collision hierarchies refit from it.
    // (After a region step the region's masses join the list when it is first read: a part
    // stepped with no one reading it pays nothing for it. So this const read writes the part's
    // bookkeeping: not for concurrent readers.)
    std::span<const Index> changedMasses() const;
    void clearChangedMasses();

    // --- Step ---
    // One step alone: advance() with the settings' time step and gravity, then
    // retireRestingZones(). Throws DivergenceError (core.hpp: "part", the time at the start of
    // the step) when a moving mass's position, velocity or force is no longer finite; the check
    // costs O(moving masses) (with semi-implicit Euler and a vector kernel, made as the step
    // writes the positions).
    void step(StepCounters* counters = nullptr);
    // The moving masses by one step of context.timeStep, under context.gravity (world frame);
    // O(1) when nothing moves. Returns true when the step itself found every moving mass's new
    // position within the model's bound, as checkRegionFinite would: the full model's step
    // (which throws DivergenceError otherwise), or the region step's vector integration pass
    // with semi-implicit Euler. False: the caller checks (step() does; a world checks the part
    // after its whole step, world.hpp).
    bool advance(const StepContext& context, StepCounters* counters = nullptr);
    // Every retireCheckInterval steps: retires the zones at rest (see Lifecycle above).
    void retireRestingZones();

    // --- Read-out ---
    const ActiveRegion& region() const { return region_; }
    std::span<const Index> movingMasses() const { return region_.masses().members(); }
    std::span<const Index> computedSprings() const { return region_.springs().members(); }
    // Throws InputError for a mass out of range (region().moves() does not check).
    bool isMoving(Index mass) const;
    const PartState& state() const { return state_; }  // part frame; non-moving masses at rest
    Vec3 worldPosition(Index mass) const;  // InputError for a mass out of range
    void worldPositions(std::vector<Vec3>& out) const;
    // The vertices of model().drawnMesh() as the part looks now, in the part frame / the world
    // (the mass positions in the user's vertex order, PartModel::userMesh(), when the model has
    // no drawn mesh of its own).
    void drawnPositions(std::vector<Vec3>& out) const;
    void drawnWorldPositions(std::vector<Vec3>& out) const;
    // The mass positions in the user's vertex order (PartModel::vertexCount() of them), in the
    // part frame / the world: a welded file vertex at its survivor's, a removed one carried
    // rigidly at its file position.
    void vertexPositions(std::vector<Vec3>& out) const;
    void vertexWorldPositions(std::vector<Vec3>& out) const;
    // Depth of each mass in the zones covering it (minimum; 0 = seed), -1 when not moving.
    void zoneDepths(std::vector<int>& out) const;
    double time() const { return state_.time; }

private:
    friend void detail::setPoseUnchecked(Part& part, const Pose& pose);
    friend void detail::displaceMassesUnchecked(Part& part, std::span<const Index> masses, std::span<const Vec3> worldDisplacements);
    void applyDisplacement(Index mass, const Vec3& worldDisplacement);  // displaceMass, unchecked
    void applyDisplacements(std::span<const Index> masses, std::span<const Vec3> worldDisplacements);
    // Part-frame points to the world, in place.
    void toWorld(std::vector<Vec3>& points) const;
    struct Zone;  // its seeds, level and members (part.cpp)

    void cover(const Zone& zone);
    void uncover(const Zone& zone);
    void returnToRest(Index mass);
    Zone* findZone(ZoneId id);
    // A retired zone's lists, kept for the next zone to open (empty when none is kept), so that
    // zones opening and retiring in a running loop allocate nothing once warm.
    Zone spareZone();
    void keepSpare(Zone&& zone);
    void reserveSettingsZones();  // settings_.zones.reservedZones at the part's largest zone level
    void collectMembers(Zone& zone);
    bool zoneAtRest(const Zone& zone) const;
    void markChanged(Index mass);
    void requireMass(Index mass, const char* what) const;  // InputError naming `what` when out of range
    // Whether displaceMass moves this mass: in range, moving, and the part not Rigid.
    bool displaces(Index mass) const {
        return mass < model_->massCount() && region_.moves(mass) && settings_.mode != PartMode::Rigid;
    }
    // Checks a load on one mass (range, finite) and opens or keeps its zone; false in Rigid mode.
    bool loadMass(Index mass, const Vec3& worldLoad, const char* what);
    void markAllChanged();

    std::shared_ptr<const PartModel> model_;
    PartSettings settings_;
    Pose pose_;
    PartState state_;
    std::unique_ptr<KRingWalker> walker_;

    std::vector<Zone> zones_;
    std::vector<Zone> spareZones_;  // retired zones' lists (scratch: a copy starts without)
    std::size_t reservedZones_ = 0; // what reserveZones has made room for (a copy: nothing)
    int reservedLevel_ = -1;
    ZoneId nextZoneId_ = 1;
    ActiveRegion region_;
    std::vector<std::uint64_t> lastLoadStep_; // (V) step of the last force on each mass
    std::vector<Index> retiring_;             // scratch: masses whose last zone retires (retireRestingZones)
    mutable IndexSet changed_;                // (V) masses changed since clearChangedMasses()
    mutable bool regionStepped_ = false;      // the region's masses moved and are not in changed_ yet
    // Every mass changed (a step moved them all): O(1) instead of marking each.
    bool allChanged_ = false;
    std::vector<Index> allMasses_;  // 0 .. V-1, built the first time every mass moves
};

}  // namespace flexfit
