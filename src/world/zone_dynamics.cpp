// The zone dynamics stage (zone_dynamics.hpp).
#include "zone_dynamics.hpp"

namespace flexfit::detail {

void advanceZones(const StepContext& step, Bodies& bodies) {
    StepContext zones = step;
    zones.gravity = Vec3::Zero();
    for (BodyId id = 0; id < bodies.size(); ++id) {
        try {
            bodies.parts[id]->advance(zones);
        } catch (const DivergenceError& e) {  // from the full step, which knows no body: name it
            throw DivergenceError(id, step.time, e.problem());
        }
    }
}

}  // namespace flexfit::detail
