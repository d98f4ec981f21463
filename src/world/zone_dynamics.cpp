// The zone dynamics stage (zone_dynamics.hpp).
#include "zone_dynamics.hpp"

namespace flexfit::detail {

void advanceZones(const StepContext& step, Bodies& bodies) {
    StepContext zones = step;
    zones.gravity = Vec3::Zero();
    for (auto& part : bodies.parts) part->advance(zones);
}

}  // namespace flexfit::detail
