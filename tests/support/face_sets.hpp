// Comparing two readers' meshes of one file: faces as sets of corners, each vertex of the other
// reader's mesh named by the nearest vertex of ours (they may number and round the vertices
// differently: assimp renumbers by first use and reads single precision).
#pragma once

#include "flexfit/mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <map>
#include <utility>
#include <vector>

namespace flexfit::testing {

// The faces only one of the two meshes has (corners rotated to start at the least), once every
// vertex of `theirs` is named by the nearest vertex of `ours`; a vertex of theirs farther than
// `tolerance` from all of ours fails the test.
inline int facesOnlyOneHas(const TriMesh& ours, const TriMesh& theirs, double tolerance = 1e-5) {
    std::vector<std::pair<Vec3, Index>> byX;
    for (Index v = 0; v < ours.vertices.size(); ++v) byX.emplace_back(ours.vertices[v], v);
    std::sort(byX.begin(), byX.end(), [](const auto& a, const auto& b) { return a.first.x() < b.first.x(); });
    auto nearest = [&](const Vec3& p) {
        auto it = std::lower_bound(byX.begin(), byX.end(), p.x() - tolerance, [](const auto& e, double x) { return e.first.x() < x; });
        Index best = 0;
        double bestDistance = std::numeric_limits<double>::infinity();
        for (; it != byX.end() && it->first.x() <= p.x() + tolerance; ++it)
            if (const double d = (it->first - p).norm(); d < bestDistance) bestDistance = d, best = it->second;
        EXPECT_LE(bestDistance, tolerance) << "a vertex far from every vertex of ours";
        return best;
    };
    auto rotated = [](Face f) {
        std::rotate(f.begin(), std::min_element(f.begin(), f.end()), f.end());
        return f;
    };
    std::map<Face, int> faces;
    for (const Face& f : ours.faces) ++faces[rotated(f)];
    for (const Face& f : theirs.faces) --faces[rotated({nearest(theirs.vertices[f[0]]), nearest(theirs.vertices[f[1]]), nearest(theirs.vertices[f[2]])})];
    int differing = 0;
    for (const auto& entry : faces) differing += entry.second != 0 ? 1 : 0;
    return differing;
}

}  // namespace flexfit::testing
