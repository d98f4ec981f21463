// Rigid-deformable parts: zones against brute-force k-rings and spring sets, counters against
// the active region, frame invariance, retirement, and equivalence with the full MSD model.
#include "flexfit/flexfit.hpp"
#include "core/lanes256.hpp"
#include "golden.hpp"
#include "model/spring_blocks.hpp"
#include "model/vertex_order.hpp"
#include "shuffled_mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

using namespace flexfit;

namespace {

PartSettings zoneSettings(double dt = 1e-3) {
    PartSettings s;
    s.simulation.timeStep = dt;
    s.simulation.restoration = {RestorationMethod::AnchorSprings, 0.1, 0.01, 0.05};
    s.simulation.globalDamping = 0.1;
    return s;
}

std::set<Index> asSet(std::span<const Index> s) { return {s.begin(), s.end()}; }

// Springs with at least one end in `masses`, by scanning every spring.
std::set<Index> springsTouching(const PartModel& model, const std::set<Index>& masses) {
    std::set<Index> out;
    for (Index e = 0; e < model.springCount(); ++e)
        if (masses.count(model.springA[e]) || masses.count(model.springB[e])) out.insert(e);
    return out;
}

// Masses within `rings` of the seeds by repeated neighbourhood expansion over the spring list.
std::set<Index> ringByExpansion(const PartModel& model, std::set<Index> region, int rings) {
    for (int r = 0; r < rings; ++r) {
        std::set<Index> next = region;
        for (Index e = 0; e < model.springCount(); ++e) {
            if (region.count(model.springA[e])) next.insert(model.springB[e]);
            if (region.count(model.springB[e])) next.insert(model.springA[e]);
        }
        region = next;
    }
    return region;
}

double maxRelativeDifference(std::span<const Vec3> a, std::span<const Vec3> b) {
    double scale = 0.0, diff = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        scale = std::max(scale, a[i].norm());
        diff = std::max(diff, (a[i] - b[i]).norm());
    }
    return diff / scale;
}

}  // namespace

TEST(Part, LevelZeroMovesNothingLevelOneOnlyTheSeeds) {
    const auto model = buildPartModel(makeTorus1());
    Part part(model, zoneSettings());
    part.openZone(ZoneSeed::mass(10), 0);
    EXPECT_TRUE(part.movingMasses().empty());
    EXPECT_TRUE(part.computedSprings().empty());
    part.openZone(ZoneSeed::mass(10), 1);
    EXPECT_EQ(asSet(part.movingMasses()), std::set<Index>({10}));
    EXPECT_EQ(asSet(part.computedSprings()), springsTouching(*model, {10}));
    const Face& f = model->mesh.faces[40];
    Part byFace(model, zoneSettings());
    byFace.openZone(ZoneSeed::face(40), 1);
    EXPECT_EQ(asSet(byFace.movingMasses()), std::set<Index>({f[0], f[1], f[2]}));
}

TEST(Part, RegionIsTheUnionOfKRingsAndItsSprings) {
    const auto model = buildPartModel(makeTorus2());
    Part part(model, zoneSettings());
    for (int level = 1; level <= 6; ++level) {
        Part single(model, zoneSettings());
        single.openZone(ZoneSeed::mass(77), level);
        const std::set<Index> expected = ringByExpansion(*model, {77}, level - 1);
        EXPECT_EQ(asSet(single.movingMasses()), expected) << "level " << level;
        EXPECT_EQ(asSet(single.computedSprings()), springsTouching(*model, expected)) << "level " << level;
    }
    // Two overlapping zones act as one region.
    part.openZone(ZoneSeed::mass(77), 4);
    part.openZone(ZoneSeed::mass(79), 3);
    std::set<Index> expected = ringByExpansion(*model, {77}, 3);
    for (Index m : ringByExpansion(*model, {79}, 2)) expected.insert(m);
    EXPECT_EQ(asSet(part.movingMasses()), expected);
    EXPECT_EQ(asSet(part.computedSprings()), springsTouching(*model, expected));
    EXPECT_EQ(part.movingMasses().size(), expected.size());  // no duplicates
}

TEST(Part, SpringsEvaluatedEqualTheActiveRegion) {
    const auto model = buildPartModel(makeHeart());
    Part part(model, zoneSettings());
    StepCounters untouched;
    for (int i = 0; i < 10; ++i) part.step(&untouched);
    EXPECT_EQ(untouched.springsEvaluated, 0u);
    EXPECT_EQ(untouched.massesIntegrated, 0u);

    part.openZone(ZoneSeed::face(500), 3);
    part.openZone(ZoneSeed::mass(6000), 2);
    StepCounters counters;
    part.applyForce(6000, Vec3(0, 0.5, 0));
    part.step(&counters);
    EXPECT_EQ(counters.springsEvaluated, part.computedSprings().size());
    EXPECT_EQ(counters.massesIntegrated, part.movingMasses().size());
    EXPECT_LT(part.computedSprings().size(), 200u);
}

TEST(Part, ZonesRetireAndMassesReturnExactlyToRest) {
    const auto model = buildPartModel(makeTorus1(), {Material::rigid(), 1.0, {}, {}, {}, {}});
    PartSettings settings = zoneSettings();
    settings.simulation.restoration = {RestorationMethod::AnchorSprings, 1.0, 0.5, 0.05};
    Part part(model, settings);
    for (int i = 0; i < 200; ++i) {
        part.applyForce(3, Vec3(2.0, 0, 0));
        part.step();
    }
    ASSERT_EQ(part.zoneCount(), 1u);  // opened by the force at the default level
    ASSERT_GT(countActiveSprings(*model, part.state().positions, 0.01), 0u);
    int steps = 0;
    while (part.zoneCount() > 0 && steps < 100000) {
        part.step();
        ++steps;
    }
    EXPECT_EQ(part.zoneCount(), 0u);
    EXPECT_TRUE(part.movingMasses().empty());
    EXPECT_TRUE(part.computedSprings().empty());
    EXPECT_EQ(part.state().positions, model->restPositions);
    StepCounters after;
    part.step(&after);
    EXPECT_EQ(after.springsEvaluated, 0u);
}

TEST(Part, LoadedZoneStaysOpen) {
    const auto model = buildPartModel(makeTorus1(), {Material::rigid(), 1.0, {}, {}, {}, {}});
    Part part(model, zoneSettings());
    for (int i = 0; i < 2000; ++i) {
        part.applyForce(3, Vec3(1e-9, 0, 0));  // tiny: the zone is at rest but loaded
        part.step();
    }
    EXPECT_EQ(part.zoneCount(), 1u);
}

TEST(Part, ZonesOpenedOnRetiredZonesListsCoverWhatFreshZonesCover) {
    // A retired zone's lists are kept for the next zone to open (no allocation once warm): the
    // next zones, of other seeds, kinds and levels, cover exactly their k-rings (the expansion
    // here is the reference), and a level change reuses them too.
    const auto model = buildPartModel(makeTorus2());
    Part part(model, zoneSettings());
    const ZoneId large = part.openZone(ZoneSeed::mass(77), 6);
    const ZoneId face = part.openZone(ZoneSeed::face(300), 4);
    part.retireZone(large);
    part.retireZone(face);
    ASSERT_TRUE(part.movingMasses().empty());
    const ZoneId small = part.openZone(ZoneSeed::mass(500), 2);
    const Face& f = model->mesh.faces[40];
    const ZoneId onFace = part.openZone(ZoneSeed::face(40), 3);
    std::set<Index> expected = ringByExpansion(*model, {500}, 1);
    for (Index m : ringByExpansion(*model, {f[0], f[1], f[2]}, 2)) expected.insert(m);
    EXPECT_EQ(asSet(part.movingMasses()), expected);
    EXPECT_EQ(asSet(part.computedSprings()), springsTouching(*model, expected));
    EXPECT_NE(small, onFace);
    EXPECT_GT(onFace, face);  // ids are never reused
    part.setZoneLevel(small, 5);
    expected = ringByExpansion(*model, {500}, 4);
    for (Index m : ringByExpansion(*model, {f[0], f[1], f[2]}, 2)) expected.insert(m);
    EXPECT_EQ(asSet(part.movingMasses()), expected);
    part.retireZone(small);
    part.retireZone(onFace);
    EXPECT_TRUE(part.movingMasses().empty());
    EXPECT_EQ(part.state().positions, model->restPositions);
}

TEST(Part, ZonesRetiringTogetherLeaveThePartAsRetiringThemOneByOne) {
    // retireRestingZones retires a step's resting zones as a batch (its region bookkeeping
    // deferred, or the region emptied at once when every zone goes); retireZone, one zone at a
    // time in the same order, is the reference. The lists, then the state after new zones and
    // loads, must be the same bit for bit: every zone at rest, or all but a loaded one.
    const auto model = buildPartModel(makeTorus2());
    const Index seeds[] = {77, 300, 301, 700, 1000, 1010, 1500};  // of 1,566 masses
    for (const bool keepOne : {false, true}) {
        PartSettings batch = zoneSettings(), reference = zoneSettings();
        batch.zones.retireCheckInterval = 1;
        reference.zones.retireCheckInterval = 1 << 30;
        Part x(model, batch), y(model, reference);
        std::vector<ZoneId> ids;
        for (std::size_t k = 0; k < std::size(seeds); ++k) {
            ids.push_back(x.openZone(ZoneSeed::mass(seeds[k]), 3 + int(k % 4)));
            y.openZone(ZoneSeed::mass(seeds[k]), 3 + int(k % 4));
        }
        if (keepOne) {
            x.applyForce(1000, Vec3(0, 0.3, 0));
            y.applyForce(1000, Vec3(0, 0.3, 0));
        }
        x.step();  // at rest, never loaded: every zone but the loaded one retires in the step
        y.step();
        for (std::size_t k = 0; k < ids.size(); ++k)
            if (!(keepOne && seeds[k] == 1000)) y.retireZone(ids[k]);
        ASSERT_EQ(x.zoneCount(), keepOne ? 1u : 0u);
        ASSERT_EQ(y.zoneCount(), x.zoneCount());
        auto sameList = [](const IndexSet& a, const IndexSet& b) { return std::equal(a.begin(), a.end(), b.begin(), b.end()); };
        const ActiveRegion &rx = x.region(), &ry = y.region();
        EXPECT_TRUE(sameList(rx.masses(), ry.masses()) && sameList(rx.springs(), ry.springs()) &&
                    sameList(rx.looseSprings(), ry.looseSprings()) && sameList(rx.vectorBlocks(), ry.vectorBlocks()) &&
                    sameList(rx.looseMasses(), ry.looseMasses()) && sameList(rx.vectorOctets(), ry.vectorOctets()))
            << "keep one " << keepOne;
        EXPECT_EQ(flexfit::stateHash(x.state()), flexfit::stateHash(y.state()));
        x.setSettings(reference);  // no more retirement: the zones left stay in both
        for (Part* p : {&x, &y}) {
            p->openZone(ZoneSeed::mass(310), 4);
            p->openZone(ZoneSeed::mass(710), 5);
            for (int i = 0; i < 40; ++i) {
                p->applyForce(310, Vec3(0.2, 0.1, 0));
                p->applyForce(710, Vec3(0, 0, 0.2));
                p->step();
            }
        }
        EXPECT_EQ(flexfit::stateHash(x.state()), flexfit::stateHash(y.state())) << "keep one " << keepOne;
        EXPECT_NE(x.state().positions[310], model->restPositions[310]);
    }
}

TEST(Part, GrowingAndShrinkingKeepsTheStateOfMassesThatStay) {
    const auto model = buildPartModel(makeTorus1());
    Part part(model, zoneSettings());
    const ZoneId zone = part.openZone(ZoneSeed::mass(50), 2);
    for (int i = 0; i < 50; ++i) {
        part.applyForce(50, Vec3(0, 1, 0));
        part.step();
    }
    const Vec3 seedPosition = part.state().positions[50];
    ASSERT_NE(seedPosition, model->restPositions[50]);
    part.setZoneLevel(zone, 5);
    EXPECT_EQ(asSet(part.movingMasses()), ringByExpansion(*model, {50}, 4));
    EXPECT_EQ(part.state().positions[50], seedPosition);
    part.setZoneLevel(zone, 1);
    EXPECT_EQ(asSet(part.movingMasses()), std::set<Index>({50}));
    EXPECT_EQ(part.state().positions[50], seedPosition);
    for (Index m = 0; m < model->massCount(); ++m)
        if (m != 50) {
            EXPECT_EQ(part.state().positions[m], model->restPositions[m]);
        }
}

TEST(Part, RigidMotionDoesNotDisturbAZone) {
    const auto model = buildPartModel(makeTorus1());
    Part still(model, zoneSettings()), moved(model, zoneSettings());
    still.openZone(ZoneSeed::mass(20), 3);
    moved.openZone(ZoneSeed::mass(20), 3);
    const Vec3 localForce(0.3, -0.2, 0.1);
    for (int i = 0; i < 500; ++i) {
        moved.rotate(Vec3(0.2, 1.0, -0.4), 0.01);
        moved.translate(Vec3(0.05, 0.0, -0.02));
        still.applyForce(20, localForce);
        moved.applyForce(20, moved.pose().rotate(localForce));  // the same force, in the moved frame
        still.step();
        moved.step();
    }
    EXPECT_LT(maxRelativeDifference(still.state().positions, moved.state().positions), 1e-12);
    // World read-out = pose applied to the part-frame state.
    std::vector<Vec3> world;
    moved.worldPositions(world);
    EXPECT_LT((world[20] - moved.pose().apply(moved.state().positions[20])).norm(), 1e-12);
    EXPECT_LT((world[300] - moved.pose().apply(model->restPositions[300])).norm(), 1e-9);
}

TEST(Part, WholeMeshZoneMatchesFullDeformableModel) {
    const auto model = buildPartModel(makeTorus1(), {Material::elastic(), 1.0, {}, {}, {}, {}});
    PartSettings zones = zoneSettings();
    zones.zones.fullSweepWhenComplete = false;  // exercise the compact-array path
    zones.simulation.gravity = Vec3(0, -0.5, 0);
    PartSettings full = zones;
    full.mode = PartMode::FullDeformable;
    Part a(model, zones), b(model, full);
    a.openZone(ZoneSeed::mass(0), 40);
    ASSERT_EQ(a.movingMasses().size(), model->massCount());
    for (int i = 0; i < 1000; ++i) {
        if (i < 300) {
            a.applyForce(0, Vec3(0.5, 0.2, 0));
            b.applyForce(0, Vec3(0.5, 0.2, 0));
        }
        a.step();
        b.step();
    }
    EXPECT_LT(maxRelativeDifference(a.state().positions, b.state().positions), 1e-5);
    EXPECT_LT(maxRelativeDifference(a.state().velocities, b.state().velocities), 1e-5);
    EXPECT_NE(a.state().positions, model->restPositions);
}

TEST(Part, ALargeRegionTakesTheCheaperFullStepWithTheSameTrajectory) {
    // Zones over most of the heart: the full step (spring blocks) with the other masses held
    // costs less than the region step, and gives its trajectory up to the summation order.
    const auto model = buildPartModel(makeHeart());
    PartSettings region = zoneSettings(), cheaper = zoneSettings();
    region.zones.fullStepWhenCheaper = false;
    Part a(model, region), b(model, cheaper);
    for (Part* p : {&a, &b})
        for (Index m : {Index(0), Index(1500), Index(3000), Index(4500), Index(6000)}) p->openZone(ZoneSeed::mass(m), 30);
    ASSERT_FALSE(b.region().coversEveryMass());
    ASSERT_TRUE(fullStepCostsLess(*model, RegionWork::of(b.region())));
    StepCounters first;
    b.step(&first);
    a.step();
    EXPECT_EQ(first.springsEvaluated, model->springCount());  // the whole model's step
    for (int i = 0; i < 300; ++i) {  // zones that are not loaded retire: the choice follows
        if (i < 100)
            for (Part* p : {&a, &b}) p->applyForce(3000, Vec3(0.5, 0.2, 0));
        a.step();
        b.step();
    }
    EXPECT_LT(maxRelativeDifference(a.state().positions, b.state().positions), 1e-12);
    EXPECT_LT(maxRelativeDifference(a.state().velocities, b.state().velocities), 1e-9);
    EXPECT_NE(a.state().positions, model->restPositions);
}

TEST(Part, PartialRegionMatchesFullModelWithPinnedMasses) {
    // Independent reference: the full model in which every mass outside the region is pinned
    // by an enormous mass. Region masses must follow the same trajectory.
    const TriMesh mesh = makeTorus1();
    const auto model = buildPartModel(mesh);
    Part part(model, zoneSettings());
    part.openZone(ZoneSeed::mass(100), 4);
    std::vector<double> masses(model->massCount(), 1e300);
    for (Index m : part.movingMasses()) masses[m] = 1.0;
    const auto pinned = buildPartModel(mesh, {Material::elastic(), 1.0, masses, {}, {}, {}});
    PartState reference = PartState::atRest(*pinned);
    SimulationSettings settings = zoneSettings().simulation;
    for (int i = 0; i < 1000; ++i) {
        part.applyForce(100, Vec3(0, 0, 0.4));
        const PointLoad load{100, Vec3(0, 0, 0.4)};
        stepFullModel(*pinned, settings, std::span(&load, 1), reference);
        part.step();
    }
    EXPECT_LT(maxRelativeDifference(part.state().positions, reference.positions), 1e-12);
}

TEST(Part, RigidModeNeverDeforms) {
    const auto model = buildPartModel(makeTorus1());
    PartSettings settings;
    settings.mode = PartMode::Rigid;
    Part part(model, settings);
    EXPECT_EQ(part.openZone(ZoneSeed::mass(1), 3), kNoZone);
    part.applyForce(1, Vec3(100, 0, 0));
    StepCounters counters;
    part.step(&counters);
    EXPECT_EQ(counters.springsEvaluated, 0u);
    EXPECT_EQ(part.state().positions, model->restPositions);
}

// A fully deformable part falls as masses (its frame stays): however far it falls together,
// the divergence check (masses beyond 1e6 times the part's size) must not stop it. Strong
// gravity takes it several bounds down in 2,000 steps.
TEST(Part, AFullDeformablePartFallsAnyDistanceWithoutADivergence) {
    const auto model = buildPartModel(makeTorus1());
    PartSettings settings;
    settings.mode = PartMode::FullDeformable;
    settings.simulation.restoration.method = RestorationMethod::None;
    settings.simulation.gravity = Vec3(0, -1e8, 0);
    Part part(model, settings);
    for (int step = 0; step < 2000; ++step) ASSERT_NO_THROW(part.step()) << "step " << step;
    const double fallen = model->restPositions[0].y() - part.state().positions[0].y();
    EXPECT_GT(fallen, 4.0 * model->positionBound);
    // Still the same shape: every mass fell alike (to 1e-4 of the part's size).
    const double size = Aabb::around(model->restPositions).size();
    for (Index i = 0; i < model->massCount(); ++i)
        ASSERT_NEAR(model->restPositions[i].y() - part.state().positions[i].y(), fallen, 1e-4 * size) << i;
}

// A kick is an impulse on one mass: with only internal forces (springs, no restoration, no
// gravity) the full-deformable part's momentum is m_i dv from then on, step after step. In a
// rigid-deformable part it opens a zone around the mass (whose edge is held, so momentum is
// not kept there).
TEST(Part, AKickGivesTheMassesMomentumThatTheSpringsConserve) {
    const auto model = buildPartModel(makeTorus1(), {Material::elastic(), 2.0, {}, {}, {}, {}});
    const Vec3 kick(0.3, -0.2, 0.1);
    PartSettings settings;
    settings.mode = PartMode::FullDeformable;
    settings.simulation.restoration.method = RestorationMethod::None;
    Part part(model, settings);
    part.rotate(Vec3(0, 0, 1), 0.7);  // the kick is world-frame
    part.kickMass(7, kick);
    for (int step = 0; step < 200; ++step) {
        part.step();
        Vec3 momentum = Vec3::Zero();
        for (Index i = 0; i < model->massCount(); ++i) momentum += model->mass[i] * part.state().velocities[i];
        ASSERT_LT((part.pose().rotate(momentum) - 2.0 * kick).norm(), 1e-12) << "step " << step;
    }

    settings.mode = PartMode::RigidDeformable;
    settings.zones.defaultLevel = 3;
    Part zoned(model, settings);
    zoned.kickMass(7, kick);
    EXPECT_EQ(zoned.zoneCount(), 1u);
    EXPECT_TRUE(zoned.region().moves(7));
    EXPECT_EQ(zoned.state().velocities[7], kick);

    PartSettings rigid;
    rigid.mode = PartMode::Rigid;
    Part still(model, rigid);
    still.kickMass(7, Vec3(1, 0, 0));
    still.step();
    EXPECT_EQ(still.state().positions, model->restPositions);
    EXPECT_THROW(still.kickMass(576, Vec3(1, 0, 0)), InputError);
    EXPECT_THROW(still.kickMass(0, Vec3(NAN, 0, 0)), InputError);
}

TEST(Part, BadInputIsRejected) {
    const auto model = buildPartModel(makeTorus1());
    Part part(model);
    EXPECT_THROW(part.openZone(ZoneSeed::mass(576), 1), InputError);
    EXPECT_THROW(part.openZone(ZoneSeed::face(1152), 1), InputError);
    EXPECT_THROW(part.openZone(ZoneSeed::mass(0), -1), InputError);
    EXPECT_THROW(part.applyForce(9999, Vec3::Zero()), InputError);
    EXPECT_THROW(part.applyForce(0, Vec3(NAN, 0, 0)), InputError);
    EXPECT_THROW(part.rotate(Vec3::Zero(), 1.0), InputError);
    PartSettings bad;
    bad.zones.retireCheckInterval = 0;
    EXPECT_THROW(Part(model, bad), InputError);
    PartSettings tooMany;
    tooMany.zones.reservedZones = 65536;
    EXPECT_THROW(Part(model, tooMany), InputError);
    tooMany.zones.reservedZones = -1;
    EXPECT_THROW(Part(model, tooMany), InputError);
    EXPECT_THROW(part.reserveZones(10, 256), InputError);
    EXPECT_THROW(part.reserveZones(65536, 2), InputError);
    EXPECT_TRUE(part.movingMasses().empty());  // nothing half-done by the failed calls
}

TEST(Part, ZoneDepthsReadOut) {
    const auto model = buildPartModel(makeTorus1());
    Part part(model, zoneSettings());
    part.openZone(ZoneSeed::mass(200), 3);
    std::vector<int> depth;
    part.zoneDepths(depth);
    EXPECT_EQ(depth[200], 0);
    for (Index n : model->topology.neighborsOf(200)) EXPECT_EQ(depth[n], 1);
    EXPECT_EQ(std::count(depth.begin(), depth.end(), -1), std::ptrdiff_t(model->massCount() - part.movingMasses().size()));
}

TEST(Part, DeterministicStateHash) {
    auto run = [] {
        const auto model = buildPartModel(makeTorus2());
        PartSettings settings = zoneSettings();
        settings.simulation.gravity = Vec3(0, -9.81, 0);
        Part part(model, settings);
        part.openZone(ZoneSeed::face(17), 4);
        for (int i = 0; i < 1500; ++i) {
            if (i < 400) part.applyForce(900, Vec3(0.2, 0.1, 0));
            part.rotate(Vec3::UnitY(), 1e-3);
            part.step();
        }
        return stateHash(part.state());
    };
    EXPECT_EQ(run(), run());
}

TEST(Part, ChangedMassesAreTheMovedOnesAndEveryMassWhenAllMove) {
    const auto model = buildPartModel(makeTorus1());
    Part part(model, zoneSettings());
    part.openZone(ZoneSeed::mass(5), 2);
    part.step();
    EXPECT_EQ(asSet(part.changedMasses()), asSet(part.movingMasses()));
    EXPECT_EQ(part.changedMasses().size(), part.movingMasses().size());  // each once
    part.clearChangedMasses();
    EXPECT_TRUE(part.changedMasses().empty());

    part.openZone(ZoneSeed::mass(0), 255);  // every mass moves
    ASSERT_EQ(part.movingMasses().size(), model->massCount());
    part.step();
    part.step();
    std::set<Index> all;
    for (Index m = 0; m < model->massCount(); ++m) all.insert(m);
    EXPECT_EQ(asSet(part.changedMasses()), all);
    EXPECT_EQ(part.changedMasses().size(), model->massCount());
    part.clearChangedMasses();
    EXPECT_TRUE(part.changedMasses().empty());
    part.step();
    EXPECT_EQ(part.changedMasses().size(), model->massCount());
}

// The region's masses join the changed list when it is read, not when they step: a read after
// the zone retired (its masses back at rest), from a copy, or after a clear still lists exactly
// what changed since the last clear.
TEST(Part, ChangedMassesReadLateStillListWhatMoved) {
    const auto model = buildPartModel(makeTorus1());
    Part part(model, zoneSettings());
    const ZoneId zone = part.openZone(ZoneSeed::mass(5), 3);
    part.step();
    const std::set<Index> moved = asSet(part.movingMasses());
    const Part copy = part;  // taken while the region's marks are pending
    part.retireZone(zone);   // every moved mass back at rest before anyone read the list
    EXPECT_TRUE(part.movingMasses().empty());
    EXPECT_EQ(asSet(part.changedMasses()), moved);
    EXPECT_EQ(asSet(copy.changedMasses()), moved);
    part.clearChangedMasses();
    part.openZone(ZoneSeed::mass(300), 2);  // a new zone, not stepped: nothing changed yet
    EXPECT_TRUE(part.changedMasses().empty());
    part.step();
    EXPECT_EQ(asSet(part.changedMasses()), asSet(part.movingMasses()));
}

// --- Pinned hashes (golden.hpp) ---

TEST(Part, GoldenHashUnderLoad) {
    // Zones opened by a face and by forces, grown, a rigid turn each step, the load released and
    // every zone retired by the end: the whole zone lifecycle in one hash.
    const auto model = buildPartModel(makeTorus2(), {Material::rigid(), 1.0, {}, {}, {}, {}});
    PartSettings settings = zoneSettings();
    settings.simulation.restoration = {RestorationMethod::AnchorSprings, 2.0, 0.5, 0.05};
    Part part(model, settings);
    const ZoneId zone = part.openZone(ZoneSeed::face(17), 3);
    for (int i = 0; i < 12000; ++i) {
        if (i < 400) part.applyForce(900, Vec3(0.2, 0.1, 0));
        if (i < 250) part.applyForce(1500, Vec3(0.0, -0.3, 0.1));
        if (i == 100) part.setZoneLevel(zone, 5);
        part.rotate(Vec3::UnitY(), 1e-3);
        part.step();
        if (i != 999) continue;
        EXPECT_GT(part.movingMasses().size(), 0u);
        EXPECT_EQ(flexfit::testing::hex(stateHash(part.state())), "36ace93eed162067") << "deformed, at 1 s";
    }
    EXPECT_EQ(part.zoneCount(), 0u);
    EXPECT_EQ(flexfit::testing::hex(stateHash(part.state())), "9c2a1c379137e0ff");
}

TEST(Part, GoldenHashOfAFullDeformablePartInEveryKernel) {
    const auto model = buildPartModel(makeHeart());
    PartSettings settings;
    settings.mode = PartMode::FullDeformable;
    for (const auto kernel : flexfit::testing::availableBlockKernels()) {
        const detail::ScopedBlockKernel chosen(kernel);
        Part part(model, settings);
        for (int i = 0; i < 200; ++i) {
            if (i < 80) part.applyForce(1234, Vec3(0.5, 0.0, -0.5));
            part.step();
        }
        EXPECT_EQ(flexfit::testing::hex(stateHash(part.state())), "b9cb3a0a89a8aa44") << detail::toString(kernel);
    }
}

TEST(Part, ACopyStepsOnItsOwnLikeTheOriginal) {
    const auto model = buildPartModel(makeTorus1());
    Part original(model, zoneSettings());
    original.openZone(ZoneSeed::mass(30), 3);
    for (int i = 0; i < 50; ++i) {
        original.applyForce(30, Vec3(0.3, 0, 0));
        original.step();
    }
    Part copy = original;
    for (int i = 0; i < 200; ++i) {
        original.applyForce(30, Vec3(0.3, 0, 0));
        copy.applyForce(30, Vec3(0.3, 0, 0));
        original.step();
        copy.step();
    }
    EXPECT_EQ(stateHash(copy.state()), stateHash(original.state()));
    EXPECT_EQ(copy.zoneIds(), original.zoneIds());
    copy.openZone(ZoneSeed::mass(200), 2);  // the copy's zones are its own
    EXPECT_EQ(copy.zoneCount(), original.zoneCount() + 1);
}

TEST(Part, AHugeForceOnAZoneDivergesAndThrowsNamingThePart) {
    // The region step does not check itself; Part::step checks the moving masses.
    const auto model = buildPartModel(makeTorus1());
    Part part(model, zoneSettings());
    double start = 0.0;
    try {
        for (int i = 0; i < 10; ++i) {
            start = part.time();
            part.applyForce(100, Vec3(0, 1e300, 0));
            part.step();
        }
        FAIL() << "a force of 1e300 did not diverge";
    } catch (const DivergenceError& e) {
        EXPECT_FALSE(e.body());
        EXPECT_EQ(e.time(), start);
        const std::string what = e.what();
        EXPECT_NE(what.find("part diverged at t = "), std::string::npos) << what;
        EXPECT_NE(what.find("likely cause: a force beyond what the model can take"), std::string::npos) << what;
    }
    EXPECT_LT(part.movingMasses().size(), model->massCount());  // it was a zone, not the whole part
}

// A part simulating on one mesh and drawn with another (surface_embedding.hpp): at rest it
// draws exactly the drawn mesh, in its frame and in the world (as a rigid part of that mesh
// would); deformed, the drawn vertices tied to faces no moving mass touches stay where they were.
TEST(Part, ADrawnMeshIsExactAtRestAndMovesOnlyOverTheZone) {
    const TriMesh drawn = makeIcoSphere(2.01, 4);
    PartModelSettings withDrawn;
    withDrawn.drawnMesh = drawn;
    const auto model = buildPartModel(makeIcoSphere(2.0, 2), withDrawn);
    ASSERT_TRUE(model->drawn);
    EXPECT_EQ(model->drawnMesh().faces, drawn.faces);
    Part part(model, zoneSettings());
    const Pose pose{Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Vec3::UnitZ())), Vec3(1, 2, 3)};
    part.setPose(pose);
    std::vector<Vec3> local, world, reference;
    part.drawnPositions(local);
    EXPECT_EQ(local, drawn.vertices);
    part.drawnWorldPositions(world);
    Part rigidDrawn(buildPartModel(drawn), zoneSettings());
    rigidDrawn.setPose(pose);
    rigidDrawn.worldPositions(reference);
    EXPECT_EQ(world, reference);

    for (int i = 0; i < 20; ++i) {
        part.applyForce(0, Vec3(0.0, 0.0, -5.0));
        part.step();
    }
    ASSERT_FALSE(part.movingMasses().empty());
    part.drawnPositions(local);
    std::size_t moved = 0;
    for (std::size_t v = 0; v < local.size(); ++v) {
        const Face& f = model->mesh.faces[model->drawn->triangle[v]];
        const bool overZone = part.isMoving(f[0]) || part.isMoving(f[1]) || part.isMoving(f[2]);
        if (!overZone) {
            EXPECT_EQ(local[v], drawn.vertices[v]) << "vertex " << v;
        }
        moved += local[v] != drawn.vertices[v];
    }
    EXPECT_GT(moved, 0u);
}

TEST(Part, AnInvalidDrawnMeshIsRejected) {
    PartModelSettings settings;
    settings.drawnMesh = makeIcoSphere(1.0, 1);
    settings.drawnMesh.faces[3][1] = 9999;
    try {
        buildPartModel(makeIcoSphere(1.0, 1), settings);
        FAIL() << "accepted a drawn mesh with a vertex index out of range";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("drawn mesh"), std::string::npos) << e.what();
    }
}

// --- A model renumbered for locality (VertexOrder::Locality): the same run as in the mesh's own
// order, read in that order through drawnPositions. ---

namespace {

// Loads the part's vertex `vertex` (the given mesh's index) for 40 steps, then lets it go for
// `steps` more; the drawn positions (the given mesh's order) at the end.
std::vector<Vec3> loadedRun(const std::shared_ptr<const PartModel>& model, Index vertex, PartMode mode, int steps) {
    PartSettings settings = zoneSettings();
    settings.mode = mode;
    Part part(model, settings);
    part.rotate(Vec3(0.3, 1, 0.2).normalized(), 0.7);
    for (int i = 0; i < 40 + steps; ++i) {
        if (i < 40) part.applyForce(model->massOf(vertex), Vec3(0.4, -0.2, 0.3));
        part.step();
    }
    std::vector<Vec3> drawn;
    part.drawnPositions(drawn);
    return drawn;
}

}  // namespace

TEST(PartVertexOrder, TheSameRunBitForBitAsTheMeshGivenInTheRenumberedOrder) {
    const TriMesh shuffled = flexfit::testing::shuffledVertices(makeTorus(3.0, 1.0, 24, 16), 11);
    PartModelSettings locality;
    locality.vertexOrder = VertexOrder::Locality;
    const auto renumbered = buildPartModel(shuffled, locality);
    ASSERT_TRUE(renumbered->renumbered());
    // The same masses in the same order, given as such: every sum runs in the same order.
    const std::vector<Index> order = detail::localityOrder(buildTopology(shuffled.faces, shuffled.vertices.size()), shuffled.faces);
    ASSERT_EQ(order, renumbered->massOfVertex);
    const auto inOrder = buildPartModel(detail::renumberVertices(shuffled, order));
    for (const PartMode mode : {PartMode::RigidDeformable, PartMode::FullDeformable}) {
        const std::vector<Vec3> a = loadedRun(renumbered, 100, mode, 60);
        const std::vector<Vec3> b = loadedRun(inOrder, order[100], mode, 60);
        ASSERT_EQ(a.size(), b.size());
        for (Index v = 0; v < a.size(); ++v) ASSERT_EQ(a[v], b[order[v]]) << "vertex " << v;
    }
}

TEST(PartVertexOrder, TheSameRunAsInTheGivenOrderUpToTheSummationOrder) {
    const TriMesh shuffled = flexfit::testing::shuffledVertices(makeTorus(3.0, 1.0, 24, 16), 11);
    PartModelSettings locality;
    locality.vertexOrder = VertexOrder::Locality;
    const auto renumbered = buildPartModel(shuffled, locality);
    const auto given = buildPartModel(shuffled);
    ASSERT_TRUE(renumbered->renumbered());
    for (const PartMode mode : {PartMode::RigidDeformable, PartMode::FullDeformable}) {
        const std::vector<Vec3> a = loadedRun(renumbered, 100, mode, 60);
        const std::vector<Vec3> b = loadedRun(given, 100, mode, 60);
        ASSERT_EQ(a.size(), shuffled.vertices.size());
        double largest = 0.0, moved = 0.0;
        for (std::size_t v = 0; v < a.size(); ++v) {
            largest = std::max(largest, (a[v] - b[v]).norm());
            moved = std::max(moved, (b[v] - given->restPositions[v]).norm());
        }
        EXPECT_GT(moved, 1e-3) << "the load moved the part";
        EXPECT_LT(largest, 1e-12 * 4.0) << "positions differ beyond rounding";
    }
}

TEST(Part, DisplaceMassesEqualsDisplaceMassOneByOne) {
    // The batch against the single call in a loop, bit for bit: a turned part with moving masses
    // (velocities both with and against their pushes), some masses that do not move, one out of
    // range, a repeat inside a group of 4 and a zero push; then the changed masses in the same order.
    if (!detail::lanesEnabled()) GTEST_SKIP() << "no AVX2 on this CPU: displaceMasses is displaceMass one by one";
    const auto model = buildPartModel(makeTorus1());
    Part original(model, zoneSettings());
    original.setPose(Pose{Eigen::Quaterniond(Eigen::AngleAxisd(0.8, Vec3(0.2, 1.0, 0.4).normalized())), Vec3(0.3, -1.0, 2.0)});
    original.openZone(ZoneSeed::mass(30), 4);
    original.openZone(ZoneSeed::mass(300), 3);
    for (int i = 0; i < 20; ++i) {
        original.applyForce(30, Vec3(0.3, -0.2, 0.1));
        original.step();
    }
    original.clearChangedMasses();
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-0.05, 0.05);
    const std::vector<Index> moving(original.movingMasses().begin(), original.movingMasses().end());
    ASSERT_GT(moving.size(), 30u);
    std::vector<Index> masses;
    for (std::size_t i = 0; i < 40; ++i) masses.push_back(moving[(i * 7) % moving.size()]);
    masses[5] = 0;                       // at rest: ignored
    masses[9] = Index(model->massCount());  // out of range: ignored
    masses[14] = masses[13];             // twice in one group of 4
    std::vector<Vec3> pushes;
    for (std::size_t i = 0; i < masses.size(); ++i) pushes.emplace_back(u(rng), u(rng), u(rng));
    pushes[21] = Vec3::Zero();
    ASSERT_FALSE(original.region().moves(0));
    Part batch = original, single = original;
    batch.displaceMasses(masses, pushes);
    for (std::size_t i = 0; i < masses.size(); ++i) single.displaceMass(masses[i], pushes[i]);
    for (Index m = 0; m < model->massCount(); ++m) {
        ASSERT_EQ(batch.state().positions[m], single.state().positions[m]) << "mass " << m;
        ASSERT_EQ(batch.state().velocities[m], single.state().velocities[m]) << "mass " << m;
    }
    EXPECT_NE(batch.state().positions[masses[0]], original.state().positions[masses[0]]);
    const auto changed = [](const Part& p) { return std::vector<Index>(p.changedMasses().begin(), p.changedMasses().end()); };
    EXPECT_EQ(changed(batch), changed(single));
    EXPECT_THROW(batch.displaceMasses(masses, std::span<const Vec3>(pushes).first(3)), InputError);
}

TEST(Part, BadArgumentsAreErrorsAndLeaveThePartAsItWas) {
    EXPECT_THROW(Part(nullptr), InputError);
    const auto model = buildPartModel(makeIcoSphere(1.0, 1));
    Part part(model, zoneSettings());
    const Index beyond = Index(model->massCount());
    EXPECT_THROW((void)part.worldPosition(beyond), InputError);
    EXPECT_THROW((void)part.isMoving(beyond), InputError);
    // Poses: a NaN or infinite translation, a quaternion that does not normalise; the pose
    // stays where it was.
    const Pose start{Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Vec3::UnitZ())), Vec3(1, 2, 3)};
    part.setPose(start);
    const Pose kept = part.pose();  // normalised
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    for (const Pose& bad : {Pose{Eigen::Quaterniond(0, 0, 0, 0), Vec3::Zero()}, Pose{Eigen::Quaterniond(1e200, 0, 0, 0), Vec3::Zero()},
                            Pose{Eigen::Quaterniond(nan, 0, 0, 0), Vec3::Zero()}, Pose{Eigen::Quaterniond::Identity(), Vec3(inf, 0, 0)}})
        EXPECT_THROW(part.setPose(bad), InputError);
    EXPECT_THROW(part.translate(Vec3(nan, 0, 0)), InputError);
    EXPECT_THROW(part.translate(Vec3(inf, 0, 0)), InputError);
    Part far(model, zoneSettings());
    far.translate(Vec3(1.7e308, 0, 0));
    EXPECT_THROW(far.translate(Vec3(1.7e308, 0, 0)), InputError);  // the position would overflow
    EXPECT_EQ(far.pose().translation.x(), 1.7e308);
    EXPECT_THROW(part.rotate(Vec3(1e308, 1e308, 0), 1.0), InputError);  // its norm overflows: no direction
    EXPECT_TRUE(samePose(part.pose(), kept));
    // A displacement that is not finite; then a moving mass displaced by a finite one.
    part.openZone(ZoneSeed::mass(0), 1);
    EXPECT_THROW(part.displaceMass(0, Vec3(nan, 0, 0)), InputError);
    EXPECT_TRUE(part.state().positions[0].allFinite());
    // displaceMasses checks every displacement before it moves any mass.
    const std::vector<Index> masses{0, 0, 0, 0, 0};
    const std::vector<Vec3> moves{Vec3(0.01, 0, 0), Vec3(0.01, 0, 0), Vec3(0.01, 0, 0), Vec3(0.01, 0, 0), Vec3(0, inf, 0)};
    const Vec3 before = part.state().positions[0];
    EXPECT_THROW(part.displaceMasses(masses, moves), InputError);
    EXPECT_EQ(part.state().positions[0], before);
    part.displaceMass(0, Vec3(0.01, 0, 0));
    EXPECT_NE(part.state().positions[0], model->restPositions[0]);
}

TEST(Part, AtMostKMaxOpenZonesAreOpenAtOnce) {
    // A mass counts the zones covering it in 16 bits: the 65,536th zone on it wrapped the
    // count to 0 and the mass stopped moving while listed as moving.
    const auto model = buildPartModel(makeIcoSphere(1.0, 0));
    Part part(model, zoneSettings());
    for (std::size_t k = 0; k < Part::kMaxOpenZones; ++k) (void)part.openZone(ZoneSeed::mass(0), 1);
    EXPECT_THROW((void)part.openZone(ZoneSeed::mass(0), 1), InputError);
    EXPECT_TRUE(part.isMoving(0));
    EXPECT_EQ(part.movingMasses().size(), 1u);
}
