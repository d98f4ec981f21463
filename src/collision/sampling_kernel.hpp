// Internal to src/collision (and the tests and benchmarks): which path
// SignedDistanceField::sampleMany takes: 8 points a vector (AVX-512), 4 (AVX2) or one at a time.
// All give the same bits (tested); the switches exist to test the narrower paths on CPUs with
// the wider ones and to measure the paths beside each other in one run.
#pragma once

namespace flexfit::detail {

// True when sampleMany uses its AVX2 path: compiled in, the CPU has AVX2, and no
// ScopedScalarSampling is alive.
bool vectorSamplingEnabled();

// True when sampleMany takes 8 points a vector: the vector path is enabled, the CPU has
// AVX-512 and no ScopedFourLaneSampling is alive (the last points then go 4 at a time).
bool eightLaneSamplingEnabled();

// Every sampleMany (on any thread) samples point by point while at least one scope is alive.
class ScopedScalarSampling {
public:
    ScopedScalarSampling();
    ~ScopedScalarSampling();
    ScopedScalarSampling(const ScopedScalarSampling&) = delete;
    ScopedScalarSampling& operator=(const ScopedScalarSampling&) = delete;
};

// Every sampleMany (on any thread) samples at most 4 points a vector while one is alive.
class ScopedFourLaneSampling {
public:
    ScopedFourLaneSampling();
    ~ScopedFourLaneSampling();
    ScopedFourLaneSampling(const ScopedFourLaneSampling&) = delete;
    ScopedFourLaneSampling& operator=(const ScopedFourLaneSampling&) = delete;
};

}  // namespace flexfit::detail
