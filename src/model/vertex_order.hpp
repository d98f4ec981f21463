// A vertex order with memory locality for meshes that come in none (files as exporters write
// them, scans, remeshers' output): the order a model build applies on request
// (PartModelSettings::vertexOrder, part_model.hpp).
//
// Breadth-first by fronts: from a pseudo-peripheral vertex (the last one a breadth-first search
// reaches, searched twice) each front is the set of vertices one edge farther out, and each
// vertex adds its unvisited neighbours in the turning order of its one-ring, starting after its
// visited ones. With consistent windings the fronts then run in one direction, so a vertex's
// neighbour on the next front sits at a near-constant index offset along the front: the
// springs fall in spring blocks (spring_blocks.hpp) as on a generated mesh's rows. Measured
// (bench/results/msd_step.csv): a shuffled heart gets 91 % of its springs in blocks (97 % in
// the generator's order; reverse Cuthill-McKee gives 43 %), the third-party Wuson 34 % (7 %
// as its file orders it) in whole blocks, 71 % (31 %) in blocks of at least 5 springs
// (spring_blocks.hpp). Each connected component is ordered in turn, in the order of its
// lowest vertex.
//
// Known limit: on Wuson (open, 51 pieces) the springs left out mostly have no 4 others of
// their offset within 8 first masses: its fronts are short and their offsets drift, which a
// block rule cannot recover (blocks spanning two adjacent offsets would take 75 % instead of
// 71 %, counted in a scratch program); a better order would.
//
// Known limit: a non-manifold vertex's one-ring is not one cycle; its neighbours then follow
// the cycle found first and the rest in index order (still a valid, if less regular, order).
#pragma once

#include "flexfit/mesh.hpp"
#include "flexfit/topology.hpp"

#include <vector>

namespace flexfit::detail {

// newIndex[v]: the position of vertex v in the locality order (a permutation of 0 .. V-1).
std::vector<Index> localityOrder(const Topology& topology, std::span<const Face> faces);

// The mesh with vertex v renumbered newIndex[v] (faces keep their order).
TriMesh renumberVertices(const TriMesh& mesh, std::span<const Index> newIndex);

}  // namespace flexfit::detail
