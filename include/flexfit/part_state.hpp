// The mutable state of a simulated part: positions, velocities and accumulated forces of its
// masses, in the part frame. Struct-of-arrays, sized by the model's mass count.
#pragma once

#include "flexfit/part_model.hpp"

#include <cstdint>
#include <vector>

namespace flexfit {

struct PartState {
    Vec3Array positions;   // (V) part frame
    Vec3Array velocities;  // (V)
    // (V) external forces pending for the next step: add to them (or pass PointLoads) before a
    // step; the step consumes them and leaves them zero.
    Vec3Array forces;
    double time = 0.0;             // s
    std::uint64_t stepCount = 0;

    // All masses at their rest positions, at rest.
    static PartState atRest(const PartModel& model);
};

// 64-bit FNV-1a hash of time, positions and velocities, bit for bit: equal hashes mean the
// same state (determinism tests).
std::uint64_t stateHash(const PartState& state);

}  // namespace flexfit
