// Internal to src/geometry (and its tests): the points the remesher's Hausdorff distance
// measures from, exposed so that their coverage and count can be checked against brute force;
// and the remesher's fingerprint, which the remesh cache (remesh_cache.hpp) keys its files by.
#pragma once

#include "flexfit/mesh.hpp"

#include <string_view>
#include <vector>

namespace flexfit::detail {

// Every point of the mesh's surface lies within about `spacing` of one of these: its vertices,
// points along its edges, and rows across its faces parallel to each one's longest edge; about
// area / spacing^2 points however long and thin the faces are. Deterministic.
std::vector<Vec3> hausdorffSamples(const TriMesh& mesh, double spacing);

// CGAL's version and a hash of the remeshing sources (remesh.cpp and what it calls in
// src/geometry), taken when the build is configured: it changes whenever their output may.
std::string_view remesherFingerprint();

}  // namespace flexfit::detail
