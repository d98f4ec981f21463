// Deterministic generators for the thesis's test shapes.
//
// All return closed, consistently oriented (outward counter-clockwise) manifold meshes that
// pass validateMesh. Same arguments, same mesh, bit for bit.
#pragma once

#include "flexfit/mesh.hpp"

#include <array>
#include <optional>
#include <string>

namespace flexfit {

// The most vertices a generator makes: 2048 x 2048 (about 20 s and 6 GB as a part here); more
// is refused (InputError) rather than failing to allocate after minutes.
inline constexpr long long kMaxGeneratedVertices = 2048LL * 2048LL;
// "N vertices: at most 4194304 (2048 x 2048)" when `count` is beyond it; nullopt otherwise.
std::optional<std::string> generatedVertexCountProblem(long long count);

// Torus around the y axis (the thesis's container mouth is open along y), centred at the
// origin. U segments around the axis, V around the tube: U*V vertices, 2UV faces, 3UV edges.
// Requires majorRadius > minorRadius > 0, U >= 3, V >= 3.
TriMesh makeTorus(double majorRadius, double minorRadius, int segmentsU, int segmentsV);

// UV sphere: `segments` around the y axis, `rings` from pole to pole (>= 3 and >= 2):
// segments*(rings-1) + 2 vertices.
TriMesh makeUvSphere(double radius, int segments, int rings);

// Icosphere: an icosahedron subdivided `subdivisions` times: 10*4^s + 2 vertices.
TriMesh makeIcoSphere(double radius, int subdivisions);

// A closed organic heart-shaped surface: a UV sphere (segments x rings) whose rays are cut by
// the implicit heart (x^2 + 9/4 z^2 + y^2 - 1)^3 - x^2 y^3 - 9/80 z^2 y^3 = 0 (y up), scaled to
// `size` along its height. The defaults give 7,349 vertices, 14,694 faces, 22,041 springs
// (the thesis's heart: 7,349 masses, 22,087 springs).
TriMesh makeHeart(double size = 20.0, int segments = 93, int rings = 80);

// Box centred at the origin with the given half extents, each face a divisions x divisions
// grid of quads (so that contacts find points across a face, not only at its corners):
// 6 d^2 + 2 vertices. Requires positive half extents and 1 <= divisions <= 256.
TriMesh makeBox(const Vec3& halfExtents, int divisions = 1);
// The same with a number of divisions per axis (x, y, z), e.g. a long strip of near-square cells.
TriMesh makeBox(const Vec3& halfExtents, const std::array<int, 3>& divisions);

// Plate centred at the origin (half extents along x, y, z) with a rectangular hole through it
// along y (half widths holeX, holeZ, smaller than the plate's): a peg's hole. 16 vertices, 32
// faces, genus 1.
TriMesh makePlateWithHole(const Vec3& halfExtents, double holeX, double holeZ);

// The thesis's models as Flexfit ships them in examples/.
TriMesh makeTorus1();          // 24 x 24: 576 masses, 1,728 springs (R = 10, r = 2.5)
TriMesh makeTorus2();          // 54 x 29: 1,566 masses, 4,698 springs (R = 10, r = 2.5)
TriMesh makeContainerMouth();  // outer diameter 25, inner 15 (R = 10, r = 2.5), 64 x 24

}  // namespace flexfit
