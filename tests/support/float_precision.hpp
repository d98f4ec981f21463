// A point as a file of 32-bit floats stores it.
#pragma once

#include "flexfit/core.hpp"

namespace flexfit::testing {

// Rounds each coordinate to the nearest float. Written per scalar: GCC 12 at -O2 was seen to drop
// the rounding in `v.cast<float>().cast<double>()` inside a loop over Eigen vectors.
inline Vec3 toFloatPrecision(const Vec3& v) {
    volatile float x = float(v.x()), y = float(v.y()), z = float(v.z());
    return Vec3(double(x), double(y), double(z));
}

}  // namespace flexfit::testing
