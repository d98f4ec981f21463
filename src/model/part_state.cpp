#include "flexfit/part_state.hpp"

#include "core/fnv1a.hpp"

namespace flexfit {

PartState PartState::atRest(const PartModel& model) {
    PartState state;
    state.positions.assign(model.restPositions.begin(), model.restPositions.end());
    state.velocities.assign(model.massCount(), Vec3::Zero());
    state.forces.assign(model.massCount(), Vec3::Zero());
    return state;
}

std::uint64_t stateHash(const PartState& state) {
    detail::Fnv1a h;
    h.mix(&state.time, sizeof state.time);
    h.mix(&state.stepCount, sizeof state.stepCount);
    for (const Vec3& p : state.positions) h.mix(p.data(), 3 * sizeof(double));
    for (const Vec3& v : state.velocities) h.mix(v.data(), 3 * sizeof(double));
    return h.value();
}

}  // namespace flexfit
