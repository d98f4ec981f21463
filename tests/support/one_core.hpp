// Runs a callable with the process pinned to one of its usable cores, then restores the
// affinity: for tests that work split over the cores (core/parallel.hpp) gives the same bits
// on one core as on all. Linux only (sched_setaffinity).
#pragma once

#if defined(__linux__)
#include <sched.h>

#include <gtest/gtest.h>

namespace flexfit::testing {

template <class Body>
auto onOneCore(Body body) {
    cpu_set_t before, one;
    EXPECT_EQ(sched_getaffinity(0, sizeof before, &before), 0);
    CPU_ZERO(&one);
    for (int c = 0; c < CPU_SETSIZE; ++c)
        if (CPU_ISSET(c, &before)) {
            CPU_SET(c, &one);
            break;
        }
    EXPECT_EQ(sched_setaffinity(0, sizeof one, &one), 0);
    struct Restore {
        cpu_set_t& mask;
        ~Restore() { sched_setaffinity(0, sizeof mask, &mask); }
    } restore{before};
    return body();
}

}  // namespace flexfit::testing
#endif
