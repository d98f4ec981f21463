// The zone retirement stage (zone_dynamics.hpp).
#include "zone_dynamics.hpp"

namespace flexfit::detail {

void retireZones(Bodies& bodies) {
    for (auto& part : bodies.parts) part->retireRestingZones();
}

}  // namespace flexfit::detail
