// Points as mesh files store them: rounded to 32-bit floats, compared bit for bit.
#pragma once

#include "flexfit/core.hpp"

#include <cstring>
#include <vector>

namespace flexfit::testing {

// Rounds each coordinate to the nearest float. Written per scalar: GCC 12 at -O2 was seen to drop
// the rounding in `v.cast<float>().cast<double>()` inside a loop over Eigen vectors.
inline Vec3 toFloatPrecision(const Vec3& v) {
    volatile float x = float(v.x()), y = float(v.y()), z = float(v.z());
    return Vec3(double(x), double(y), double(z));
}

inline bool bitIdentical(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

}  // namespace flexfit::testing
