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
#include <cstddef>
#include <cstdint>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace flexfit {

using Vec3 = Eigen::Vector3d;
using Index = std::uint32_t;

// Allocates on 64-byte boundaries (a cache line, an AVX-512 vector). The step's vector kernels
// load and store 8 doubles at a time from the start of a part's state arrays; from malloc's
// 16-byte alignment one vector in every such access straddled two cache lines, and the same
// step of the same model ran up to 11 % slower in one part than in another whose arrays
// happened to sit on 64 bytes (2026-12-07, AMD Zen 5, the heart's full step).
template <class T>
struct CacheAlignedAllocator {
    using value_type = T;
    static constexpr std::align_val_t kAlignment{64};
    CacheAlignedAllocator() = default;
    template <class U>
    CacheAlignedAllocator(const CacheAlignedAllocator<U>&) noexcept {}
    T* allocate(std::size_t n) { return static_cast<T*>(::operator new(n * sizeof(T), kAlignment)); }
    void deallocate(T* p, std::size_t n) noexcept { ::operator delete(p, n * sizeof(T), kAlignment); }
    template <class U>
    bool operator==(const CacheAlignedAllocator<U>&) const noexcept { return true; }
};
// Per-mass arrays the kernels stream (PartState, PartModel's masses), each starting on a cache line.
using Vec3Array = std::vector<Vec3, CacheAlignedAllocator<Vec3>>;
using DoubleArray = std::vector<double, CacheAlignedAllocator<double>>;
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

// A simulation that diverged: a position, velocity or force of a body or of a part's mass is
// no longer finite. Names the body (its id in a world, with its name when a scene gives one;
// "part" for a part stepped alone), the simulated time at the start of the failing step, and
// the problem: what went non-finite and its likely cause (a time step above the material's
// stability bound, or a force beyond what the model can take). Thrown by World::step(),
// Part::step() and stepFullModel() at the end of the failing step: the world or part then
// holds that step's non-finite state and must not be stepped again.
class DivergenceError : public std::runtime_error {
public:
    DivergenceError(std::optional<BodyId> body, double time, const std::string& problem, std::string name = {});

    std::optional<BodyId> body() const { return body_; }  // none for a part stepped alone
    const std::string& name() const { return name_; }      // the body's name, when known
    double time() const { return time_; }                  // s, at the start of the failing step
    const std::string& problem() const { return problem_; }

private:
    std::optional<BodyId> body_;
    std::string name_;
    double time_;
    std::string problem_;
};

}  // namespace flexfit
