// Pinned state hashes, as Box2D's test_determinism.c: a test runs a fixed scenario and compares
// the 64-bit state hash with a number written in the test. Any change of trajectory (a refactor
// that reorders a sum, another compiler, another CPU) fails it; a change that moves a hash on
// purpose says why in its commit. Scenarios that take the full step run with every block kernel
// this CPU has, since all of them must give the same bits.
#pragma once

#include "dynamics/full_step.hpp"

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace flexfit::testing {

// The block kernels of the full step that this CPU can run, scalar first.
inline std::vector<detail::BlockKernel> availableBlockKernels() {
    std::vector<detail::BlockKernel> kernels;
    for (auto k : {detail::BlockKernel::Scalar, detail::BlockKernel::Avx2, detail::BlockKernel::Avx512})
        if (detail::blockKernelAvailable(k)) kernels.push_back(k);
    return kernels;
}

inline std::string hex(std::uint64_t hash) {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
    return text;
}

}  // namespace flexfit::testing
