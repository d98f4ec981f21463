// Internal to src/dynamics: flushes denormal floats to zero for the duration of a step.
//
// A load on one mass sends a wave through the mesh that decays, far away, into denormal
// numbers; arithmetic on them costs ~100x (measured: the heart's full step 3x slower). Like
// Jolt's FPFlushDenormals, the step sets FTZ/DAZ in MXCSR and restores the caller's mode on
// exit, so nothing leaks into the application. Values below 2.2e-308 become 0: far below any
// length, speed or force the model can resolve.
#pragma once

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace flexfit::detail {

class FlushDenormals {
public:
#if defined(__SSE2__)
    FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | kFlushToZero | kDenormalsAreZero); }
    ~FlushDenormals() { _mm_setcsr(saved_); }
#endif
    FlushDenormals(const FlushDenormals&) = delete;
    FlushDenormals& operator=(const FlushDenormals&) = delete;

private:
#if defined(__SSE2__)
    static constexpr unsigned kFlushToZero = 0x8000;
    static constexpr unsigned kDenormalsAreZero = 0x0040;
    unsigned saved_;
#endif
};

}  // namespace flexfit::detail
