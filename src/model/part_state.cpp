#include "flexfit/part_state.hpp"

#include <cstring>

namespace flexfit {
namespace {

constexpr std::uint64_t kFnvOffset = 14695981039346656037ull;  // the FNV-1a 64-bit offset basis
constexpr std::uint64_t kFnvPrime = 1099511628211ull;

void hashBytes(std::uint64_t& h, const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
        h ^= bytes[i];
        h *= kFnvPrime;
    }
}

}  // namespace

PartState PartState::atRest(const PartModel& model) {
    PartState state;
    state.positions = model.restPositions;
    state.velocities.assign(model.massCount(), Vec3::Zero());
    state.forces.assign(model.massCount(), Vec3::Zero());
    return state;
}

std::uint64_t stateHash(const PartState& state) {
    std::uint64_t h = kFnvOffset;
    hashBytes(h, &state.time, sizeof state.time);
    hashBytes(h, &state.stepCount, sizeof state.stepCount);
    for (const Vec3& p : state.positions) hashBytes(h, p.data(), 3 * sizeof(double));
    for (const Vec3& v : state.velocities) hashBytes(h, v.data(), 3 * sizeof(double));
    return h;
}

}  // namespace flexfit
