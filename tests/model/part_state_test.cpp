// PartState construction and the determinism hash.
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <vector>

using namespace flexfit;

TEST(PartState, AtRestMatchesModel) {
    const auto model = buildPartModel(makeTorus1());
    const PartState state = PartState::atRest(*model);
    ASSERT_EQ(state.positions.size(), model->massCount());
    EXPECT_EQ(state.positions, model->restPositions);
    for (const Vec3& v : state.velocities) EXPECT_EQ(v, Vec3::Zero());
    for (const Vec3& f : state.forces) EXPECT_EQ(f, Vec3::Zero());
}

TEST(PartState, HashSeesEveryBit) {
    const auto model = buildPartModel(makeTorus1());
    const PartState a = PartState::atRest(*model);
    PartState b = a;
    EXPECT_EQ(stateHash(a), stateHash(b));
    // Flip the lowest mantissa bit of one velocity component.
    std::uint64_t bits;
    std::memcpy(&bits, &b.velocities[300].y(), sizeof bits);
    bits ^= 1u;
    std::memcpy(&b.velocities[300].y(), &bits, sizeof bits);
    EXPECT_NE(stateHash(a), stateHash(b));
    PartState c = a;
    c.time = 1e-3;
    EXPECT_NE(stateHash(a), stateHash(c));
}

// The step's vector kernels stream a part's state and its model's per-mass arrays 8 doubles
// (a cache line) at a time from their starts: every such array starts on 64 bytes, whatever its
// size, copied or grown. (malloc's 16-byte alignment puts 3 in 4 of them off a line: over the
// arrays below, chance alone would not pass.)
TEST(PartState, EveryArrayTheKernelsStreamStartsOnACacheLine) {
    const auto onLine = [](const void* p) { return reinterpret_cast<std::uintptr_t>(p) % 64 == 0; };
    std::vector<PartState> states;
    for (int level = 0; level <= 3; ++level)
        for (double radius : {0.5, 1.0, 2.0}) {
            const auto model = buildPartModel(makeIcoSphere(radius, level));
            EXPECT_TRUE(onLine(model->restPositions.data()) && onLine(model->mass.data()) && onLine(model->inverseMass.data())) << level;
            states.push_back(PartState::atRest(*model));
            states.push_back(states.back());  // a copy allocates its own
            states.back().positions.resize(states.back().positions.size() + 13);  // grown: reallocated
        }
    const Part part(buildPartModel(makeTorus1()));
    for (const PartState* s : {&part.state(), static_cast<const PartState*>(&states.front())})
        EXPECT_TRUE(onLine(s->positions.data()) && onLine(s->velocities.data()) && onLine(s->forces.data()));
    for (const PartState& s : states)
        EXPECT_TRUE(onLine(s.positions.data()) && onLine(s.velocities.data()) && onLine(s.forces.data()));
}
