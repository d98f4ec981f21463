// Core types shared by every Flexfit module.
//
// Vec3 is Eigen's 3-vector in double precision: simulations of stiff materials over long runs
// need the headroom, and the thesis's float code lost shape over time. Indices are 32-bit:
// 4 billion masses is far beyond any interactive model, and half the size doubles the cache
// reach of the CSR arrays.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace flexfit {

using Vec3 = Eigen::Vector3d;
using Index = std::uint32_t;
using Face = std::array<Index, 3>;
// A body's id in a world: its index, 0, 1, 2, ... in the order added (body.hpp).
using BodyId = std::uint32_t;

// Error in user input (a file, a scene description, a parameter). Names the source, the line
// when there is one (1-based; 0 = none) and the problem. Thrown before anything is built, so
// a caller never holds a half-built object.
class InputError : public std::runtime_error {
public:
    InputError(std::string source, std::size_t line, const std::string& problem);

    const std::string& source() const { return source_; }
    std::size_t line() const { return line_; }
    const std::string& problem() const { return problem_; }

private:
    std::string source_;
    std::size_t line_;
    std::string problem_;
};

}  // namespace flexfit
