// Two queries' contacts compared field for field, bit for bit, in order, and their face pairs.
#pragma once

#include "flexfit/collision.hpp"

#include <gtest/gtest.h>

#include <set>
#include <utility>
#include <vector>

namespace flexfit::testing {

// The face pairs of a query's contacts.
inline std::set<std::pair<Index, Index>> pairsOf(const std::vector<Contact>& contacts) {
    std::set<std::pair<Index, Index>> out;
    for (const Contact& c : contacts) out.insert({c.faceA, c.faceB});
    return out;
}

inline void expectSameContacts(const std::vector<Contact>& got, const std::vector<Contact>& want, int step) {
    ASSERT_EQ(got.size(), want.size()) << "step " << step;
    for (std::size_t i = 0; i < got.size(); ++i) {
        EXPECT_EQ(got[i].faceA, want[i].faceA) << "step " << step << " contact " << i;
        EXPECT_EQ(got[i].faceB, want[i].faceB) << "step " << step << " contact " << i;
        EXPECT_EQ(got[i].massB, want[i].massB) << "step " << step << " contact " << i;
        EXPECT_EQ(got[i].point, want[i].point) << "step " << step << " contact " << i;
        EXPECT_EQ(got[i].normal, want[i].normal) << "step " << step << " contact " << i;
        EXPECT_EQ(got[i].depth, want[i].depth) << "step " << step << " contact " << i;
    }
}

}  // namespace flexfit::testing
