// Internal: work split over the cores this process may use, in fixed chunks, so that a result
// never depends on how many cores there are (each chunk's work must not depend on the thread
// that runs it). Used where a load's work is many independent queries: the remesher's
// projections and distance samples (remesh.cpp), a distance field's nodes (distance_field.cpp).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#if defined(__linux__)
#include <sched.h>
#endif

namespace flexfit::detail {

// The cores this process may run on (its affinity mask on Linux: a container or `taskset`
// limits it below the machine's count).
inline unsigned usableCores() {
#if defined(__linux__)
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0) return unsigned(std::max(1, CPU_COUNT(&set)));
#endif
    return std::max(1u, std::thread::hardware_concurrency());
}

// Runs body(begin, end) over [0, n) in chunks of `chunk` on the usable cores. A chunk's
// result must not depend on which thread runs it, so the outcome is the same on any machine.
// The first exception a chunk throws is rethrown here once every thread has stopped.
template <class Body>
void forChunks(std::size_t n, std::size_t chunk, Body body) {
    const std::size_t chunks = (n + chunk - 1) / chunk;
    const std::size_t threads = std::min<std::size_t>(chunks, usableCores());
    std::atomic<std::size_t> next{0};
    std::exception_ptr failure;
    std::mutex failureLock;
    auto work = [&] {
        try {
            for (std::size_t c; (c = next.fetch_add(1)) < chunks;) body(c * chunk, std::min(n, (c + 1) * chunk));
        } catch (...) {
            next = chunks;  // the others stop after their chunk
            const std::lock_guard lock(failureLock);
            if (!failure) failure = std::current_exception();
        }
    };
    {
        std::vector<std::jthread> helpers;
        for (std::size_t t = 1; t < threads; ++t) helpers.emplace_back(work);
        work();
    }
    if (failure) std::rethrow_exception(failure);
}

}  // namespace flexfit::detail
