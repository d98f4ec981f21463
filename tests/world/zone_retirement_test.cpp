// The zone retirement stage (src/world/zone_retirement.cpp): zones at rest retire at the
// parts' check interval and not before, their masses exactly back at rest; loaded zones stay.
#include "flexfit/flexfit.hpp"
#include "world/zone_dynamics.hpp"

#include <gtest/gtest.h>

using namespace flexfit;

TEST(ZoneRetirement, ZonesAtRestRetireAtTheCheckIntervalAndLoadedOnesStay) {
    const auto model = buildPartModel(makeTorus1());
    PartSettings settings;
    settings.zones.retireCheckInterval = 8;
    detail::Bodies bodies;
    for (int i = 0; i < 2; ++i) bodies.add(std::make_unique<Part>(model, settings), makeRigidBody(*model, BodySettings{}));
    Part& idle = *bodies.parts[0];
    Part& loaded = *bodies.parts[1];
    idle.openZone(ZoneSeed::mass(10), 3);  // nothing ever loads it: at rest from the start
    loaded.openZone(ZoneSeed::mass(10), 3);
    const StepContext step{1e-3, Vec3::Zero(), 0, 0.0};
    std::vector<std::uint8_t> checked;
    for (int i = 1; i <= 8; ++i) {
        loaded.applyForce(10, Vec3(0.1, 0, 0));
        detail::advanceZones(step, bodies, checked);
        detail::retireZones(bodies);
        ASSERT_EQ(idle.zoneCount(), i < 8 ? 1u : 0u) << "after step " << i;
        EXPECT_EQ(loaded.zoneCount(), 1u);
    }
    EXPECT_TRUE(idle.movingMasses().empty());
    EXPECT_EQ(idle.state().positions, model->restPositions);
    EXPECT_FALSE(loaded.movingMasses().empty());
}
