// The zone dynamics stage (zone_dynamics.hpp).
#include "zone_dynamics.hpp"

namespace flexfit::detail {

void advanceZones(const StepContext& step, Bodies& bodies, std::vector<std::uint8_t>& checked) {
    StepContext zones = step;
    zones.gravity = Vec3::Zero();
    checked.resize(bodies.size());
    for (BodyId id = 0; id < bodies.size(); ++id) {
        try {
            checked[id] = bodies.parts[id]->advance(zones);
        } catch (const DivergenceError& e) {  // from the full step, which knows no body: name it
            throw DivergenceError(id, step.time, e.problem());
        }
    }
}

}  // namespace flexfit::detail
