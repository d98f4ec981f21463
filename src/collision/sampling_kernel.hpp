// Internal to src/collision (and the tests and benchmarks): which path
// SignedDistanceField::sampleMany takes. Both give the same bits (tested); the switch exists to
// test the scalar path on CPUs with AVX2 and to measure the vector path beside it in one run.
#pragma once

namespace flexfit::detail {

// True when sampleMany uses its AVX2 path: compiled in, the CPU has AVX2, and no
// ScopedScalarSampling is alive.
bool vectorSamplingEnabled();

// Every sampleMany (on any thread) samples point by point while at least one scope is alive.
class ScopedScalarSampling {
public:
    ScopedScalarSampling();
    ~ScopedScalarSampling();
    ScopedScalarSampling(const ScopedScalarSampling&) = delete;
    ScopedScalarSampling& operator=(const ScopedScalarSampling&) = delete;
};

}  // namespace flexfit::detail
