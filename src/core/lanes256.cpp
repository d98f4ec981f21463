// The switch of the lane paths (lanes256.hpp).
#include "core/lanes256.hpp"

#include <atomic>

namespace flexfit::detail {
namespace {
std::atomic<int> scalarLaneScopes{0};  // ScopedScalarLanes alive, nested or on other threads
}  // namespace

bool lanesEnabled() {
#if defined(FLEXFIT_LANES256)
    static const bool avx2 = __builtin_cpu_supports("avx2");
    return avx2 && scalarLaneScopes.load(std::memory_order_relaxed) == 0;
#else
    return false;
#endif
}

ScopedScalarLanes::ScopedScalarLanes() { scalarLaneScopes.fetch_add(1, std::memory_order_relaxed); }
ScopedScalarLanes::~ScopedScalarLanes() { scalarLaneScopes.fetch_sub(1, std::memory_order_relaxed); }

}  // namespace flexfit::detail
