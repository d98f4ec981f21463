// World::step in a running loop allocates nothing once warm: a haptic loop must not take the
// allocator's locks or fresh pages inside its deadline. Warm means that every list has grown
// to the largest size the run needs (the region's sets, the contacts, the spare zones); a loop
// that repeats what it did before therefore allocates nothing.
//
// Its own program: it replaces the global operator new to count the allocations made while a
// step runs (the sanitizers' own operator new is then not used here, so a new/delete mismatch
// in this program would go unreported; the rest of the suite keeps those checks).
#include "test_bodies.hpp"
#include "flexfit/flexfit.hpp"
#include "flexfit/scene_run.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

namespace {

std::atomic<bool> counting{false};
std::atomic<long> allocations{0};

void* allocate(std::size_t size, std::size_t alignment) {
    if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
    if (size == 0) size = 1;
    void* p = alignment <= alignof(std::max_align_t) ? std::malloc(size)
                                                     : std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
    if (p == nullptr) throw std::bad_alloc();
    return p;
}

// The allocations made by f().
template <class F>
long allocationsIn(F&& f) {
    allocations = 0;
    counting = true;
    f();
    counting = false;
    return allocations.load();
}

}  // namespace

// The replaced operators pair malloc with free; GCC, seeing a `new` inlined into a `free` in
// the code that calls them (the sanitizer build), takes them for the standard ones.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) { return allocate(size, 0); }
void* operator new[](std::size_t size) { return allocate(size, 0); }
void* operator new(std::size_t size, std::align_val_t a) { return allocate(size, std::size_t(a)); }
void* operator new[](std::size_t size, std::align_val_t a) { return allocate(size, std::size_t(a)); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

using namespace flexfit;
using namespace flexfit::testing;

TEST(StepAllocations, TheCounterSeesAnAllocation) {
    // The test below can fail: a vector's growth inside the counted call is seen.
    std::vector<int> v;
    EXPECT_EQ(allocationsIn([&] { v.resize(1000); }), 1);
    EXPECT_EQ(allocationsIn([&] { v.resize(10); }), 0);
}

TEST(StepAllocations, ARestingRigidStackAllocatesNothing) {
    // Three boxes at rest on a floor (examples/stack.toml): the broad phase rebuilds its tree,
    // the contact solver warm-starts and every pair keeps its answer, every step.
    SceneRun run(loadScene(FLEXFIT_EXAMPLES_DIR "/stack.toml"));
    for (int i = 0; i < 100; ++i) run.step();
    ASSERT_FALSE(run.world().contacts().empty());
    EXPECT_EQ(allocationsIn([&] {
                  for (int i = 0; i < 500; ++i) run.step();
              }),
              0);
}

// A kinematic ball pressed into a deformable rim and lifted off, until every zone has retired:
// zones open under the ball, deform, restore and retire.
struct PressCycles {
    World world;
    BodyId rim = 0, ball = 0;
    explicit PressCycles(RigidDeformableQuery query) : world(settingsFor(query)) {
        PartSettings deformable;
        deformable.zones.contactLevel = 3;
        deformable.simulation.restoration.constraintRate = 10.0;  // restores in about a second
        rim = world.add(buildPartModel(makeContainerMouth()), deformable, BodySettings{}, Pose{});
        BodySettings kinematic;
        kinematic.motion = MotionType::Kinematic;
        ball = world.add(buildPartModel(makeIcoSphere(8.5, 3)), rigidPart(), kinematic, at(Vec3(0, 6.0, 0)));
    }
    static WorldSettings settingsFor(RigidDeformableQuery query) {
        WorldSettings s;
        s.collision.rigidDeformable = query;
        return s;
    }
    // One press: down 2.5 over 100 steps, held 50, up over 100, then left to rest. Returns the
    // most zones open at once.
    std::size_t cycle() {
        std::size_t zones = 0;
        auto moveTo = [&](double y) {
            world.setKinematicTarget(ball, at(Vec3(0.3, y, 0.1)));
            world.step();
            zones = std::max(zones, world.part(rim).zoneCount());
        };
        for (int i = 1; i <= 100; ++i) moveTo(6.0 - 0.025 * i);
        for (int i = 0; i < 50; ++i) moveTo(3.5);
        for (int i = 1; i <= 100; ++i) moveTo(3.5 + 0.025 * i);
        for (int i = 0; i < 1500 && world.part(rim).zoneCount() > 0; ++i) moveTo(6.0);
        return zones;
    }
};

class PressCycleAllocations : public ::testing::TestWithParam<RigidDeformableQuery> {};

TEST_P(PressCycleAllocations, ARepeatedPressAllocatesNothing) {
    PressCycles press(GetParam());
    const std::size_t first = press.cycle();
    ASSERT_GT(first, 0u) << "the press opened no zone";
    ASSERT_EQ(press.world.part(press.rim).zoneCount(), 0u) << "the zones did not retire";
    press.cycle();  // the second press may still grow what the first did not reach
    std::size_t third = 0;
    EXPECT_EQ(allocationsIn([&] { third = press.cycle(); }), 0);
    EXPECT_EQ(third, first);
    EXPECT_EQ(press.world.part(press.rim).zoneCount(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Queries, PressCycleAllocations,
                         ::testing::Values(RigidDeformableQuery::Faces, RigidDeformableQuery::PointShell),
                         [](const auto& query) { return std::string(query.param == RigidDeformableQuery::Faces ? "Faces" : "PointShell"); });

// Zones reserved (ZoneSettings::reservedZones, Part::reserveZones): zones open, re-level and
// retire with no allocation from the very first, a zone of the reserved level at every face
// and every mass of the part (so the largest ring fits), with forces and steps between. The
// same calls without the reservation allocate.
long zoneCallsAllocations(int reserved) {
    PartSettings settings;
    settings.zones.defaultLevel = 2;
    settings.zones.contactLevel = 4;
    settings.zones.reservedZones = reserved;
    Part part(buildPartModel(makeContainerMouth()), settings);
    const PartModel& model = part.model();
    std::vector<ZoneId> open;  // `reserved` zones at once, spread over the part, some re-levelled
    open.reserve(std::size_t(reserved));
    return allocationsIn([&] {
        for (Index f = 0; f < model.faceCount(); ++f) part.retireZone(part.openZone(ZoneSeed::face(f), 4));
        for (Index m = 0; m < model.massCount(); ++m) part.retireZone(part.openZone(ZoneSeed::mass(m), 4));
        for (int z = 0; z < reserved; ++z) {
            open.push_back(part.openZone(ZoneSeed::face(Index(std::size_t(z) * model.faceCount() / std::size_t(reserved))), 1 + z % 4));
            if (z % 3 == 0) part.setZoneLevel(open.back(), 4);
            if (z % 5 == 0) part.setZoneLevel(open.back(), 1);
        }
        for (int i = 0; i < 20; ++i) {
            part.applyForce(Index(open.size() * 7 % model.massCount()), Vec3(0.0, 0.5, 0.0));
            part.step();
        }
        for (ZoneId z : open) part.retireZone(z);
    });
}

TEST(StepAllocations, ReservedZonesOpenReLevelAndRetireWithoutAllocatingFromTheFirst) {
    EXPECT_GT(zoneCallsAllocations(0), 0);
    EXPECT_EQ(zoneCallsAllocations(40), 0);
}

TEST(StepAllocations, ZonesReservedAgainAtAHigherLevelOpenWithoutAllocating) {
    // Live settings that raise the zone level (or the count) make room again; the same settings
    // again change nothing. Zones of the new level at every face, then 0 allocations.
    PartSettings settings;
    settings.zones.contactLevel = 2;
    settings.zones.reservedZones = 4;
    Part part(buildPartModel(makeContainerMouth()), settings);
    settings.zones.contactLevel = 5;
    part.setSettings(settings);
    part.setSettings(settings);
    EXPECT_EQ(allocationsIn([&] {
                  for (Index f = 0; f < part.model().faceCount(); ++f) part.retireZone(part.openZone(ZoneSeed::face(f), 5));
              }),
              0);
}
