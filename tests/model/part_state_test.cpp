// PartState construction and the determinism hash.
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <cstring>

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
