#include "flexfit/generators.hpp"

#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>

namespace flexfit {
namespace {

constexpr double kPi = std::numbers::pi;

bool positiveFinite(double x) { return std::isfinite(x) && x > 0.0; }

void require(bool ok, const char* what) {
    if (!ok) throw InputError("generator", 0, what);
}

void requireVertexCount(long long count, const char* shape) {
    if (const std::optional<std::string> problem = generatedVertexCountProblem(count))
        throw InputError("generator", 0, std::string(shape) + " of " + *problem);
}

}  // namespace

std::optional<std::string> generatedVertexCountProblem(long long count) {
    if (count <= kMaxGeneratedVertices) return std::nullopt;
    return std::to_string(count) + " vertices: at most " + std::to_string(kMaxGeneratedVertices) + " (2048 x 2048)";
}

namespace {

// Quad (a, b, c, d) counter-clockwise from outside -> two triangles.
void addQuad(std::vector<Face>& faces, Index a, Index b, Index c, Index d) {
    faces.push_back({a, b, c});
    faces.push_back({a, c, d});
}

// Sphere-topology grid: a pole at +y, (rings-1) latitude rows of `segments`, a pole at -y.
// `point(theta, phi)` gives the vertex for polar angle theta in (0, pi) and azimuth phi.
template <class PointFn>
TriMesh makePolarGrid(int segments, int rings, PointFn point) {
    TriMesh mesh;
    mesh.vertices.push_back(point(0.0, 0.0));
    for (int r = 1; r < rings; ++r)
        for (int s = 0; s < segments; ++s)
            mesh.vertices.push_back(point(kPi * r / rings, 2.0 * kPi * s / segments));
    mesh.vertices.push_back(point(kPi, 0.0));
    const Index south = Index(mesh.vertices.size() - 1);
    auto at = [&](int r, int s) { return Index(1 + (r - 1) * segments + (s % segments)); };
    for (int s = 0; s < segments; ++s) mesh.faces.push_back({0, at(1, s), at(1, s + 1)});
    for (int r = 1; r + 1 < rings; ++r)
        for (int s = 0; s < segments; ++s) addQuad(mesh.faces, at(r, s), at(r + 1, s), at(r + 1, s + 1), at(r, s + 1));
    for (int s = 0; s < segments; ++s) mesh.faces.push_back({south, at(rings - 1, s + 1), at(rings - 1, s)});
    return mesh;
}

Vec3 unitDirection(double theta, double phi) {
    return {std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
}

// The classic implicit heart with y up; negative inside.
double heartField(const Vec3& p) {
    const double x = p.x(), y = p.y(), z = p.z();
    const double a = x * x + 2.25 * z * z + y * y - 1.0;
    return a * a * a - x * x * y * y * y - 0.1125 * z * z * y * y * y;
}

// Distance along `dir` from the origin to the first crossing of the heart surface.
double heartRadius(const Vec3& dir) {
    double inside = 0.0, outside = 0.05;
    while (heartField(outside * dir) < 0.0) {
        inside = outside;
        outside += 0.05;
    }
    for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (inside + outside);
        (heartField(mid * dir) < 0.0 ? inside : outside) = mid;
    }
    return 0.5 * (inside + outside);
}

}  // namespace

TriMesh makeTorus(double majorRadius, double minorRadius, int segmentsU, int segmentsV) {
    require(positiveFinite(minorRadius) && positiveFinite(majorRadius) && majorRadius > minorRadius,
            "torus needs finite radii with major > minor > 0");
    require(segmentsU >= 3 && segmentsV >= 3, "torus needs at least 3 x 3 segments");
    requireVertexCount(static_cast<long long>(segmentsU) * segmentsV, "torus");
    TriMesh mesh;
    mesh.name = "torus";
    for (int u = 0; u < segmentsU; ++u) {
        const double phi = 2.0 * kPi * u / segmentsU;
        for (int v = 0; v < segmentsV; ++v) {
            const double theta = 2.0 * kPi * v / segmentsV;
            const double ring = majorRadius + minorRadius * std::cos(theta);
            mesh.vertices.emplace_back(ring * std::cos(phi), minorRadius * std::sin(theta), -ring * std::sin(phi));
        }
    }
    auto at = [&](int u, int v) { return Index((u % segmentsU) * segmentsV + (v % segmentsV)); };
    for (int u = 0; u < segmentsU; ++u)
        for (int v = 0; v < segmentsV; ++v) addQuad(mesh.faces, at(u, v), at(u + 1, v), at(u + 1, v + 1), at(u, v + 1));
    return mesh;
}

TriMesh makeUvSphere(double radius, int segments, int rings) {
    require(positiveFinite(radius), "sphere needs a finite radius > 0");
    require(segments >= 3 && rings >= 2, "sphere needs segments >= 3 and rings >= 2");
    requireVertexCount(static_cast<long long>(segments) * (rings - 1) + 2, "sphere");
    TriMesh mesh = makePolarGrid(segments, rings, [&](double t, double p) { return Vec3(radius * unitDirection(t, p)); });
    mesh.name = "sphere";
    return mesh;
}

TriMesh makeIcoSphere(double radius, int subdivisions) {
    require(positiveFinite(radius), "icosphere needs a finite radius > 0");
    require(subdivisions >= 0 && subdivisions <= 8, "icosphere needs 0 <= subdivisions <= 8");
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    TriMesh mesh;
    mesh.name = "icosphere";
    mesh.vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                     {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    mesh.faces = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                  {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                  {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    for (Vec3& v : mesh.vertices) v.normalize();
    for (int s = 0; s < subdivisions; ++s) {
        std::map<std::pair<Index, Index>, Index> midpoints;
        auto midpoint = [&](Index a, Index b) {
            const auto key = std::minmax(a, b);
            auto [it, inserted] = midpoints.try_emplace({key.first, key.second}, Index(mesh.vertices.size()));
            if (inserted) mesh.vertices.push_back((mesh.vertices[a] + mesh.vertices[b]).normalized());
            return it->second;
        };
        std::vector<Face> faces;
        for (const Face& f : mesh.faces) {
            const Index ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
            faces.insert(faces.end(), {{f[0], ab, ca}, {f[1], bc, ab}, {f[2], ca, bc}, {ab, bc, ca}});
        }
        mesh.faces = std::move(faces);
    }
    for (Vec3& v : mesh.vertices) v *= radius;
    return mesh;
}

TriMesh makeBox(const Vec3& halfExtents, int divisions) { return makeBox(halfExtents, {divisions, divisions, divisions}); }

TriMesh makeBox(const Vec3& halfExtents, const std::array<int, 3>& divisions) {
    require(halfExtents.allFinite() && halfExtents.minCoeff() > 0.0, "box needs finite half extents > 0");
    for (int d : divisions) require(d >= 1 && d <= 256, "box needs 1 <= divisions <= 256");
    const std::array<int, 3>& d = divisions;
    TriMesh mesh;
    mesh.name = "box";
    // Vertices on the surface lattice (i, j, k) in [0, d_x] x [0, d_y] x [0, d_z], each once.
    std::map<std::array<int, 3>, Index> index;
    auto vertex = [&](std::array<int, 3> g) {
        auto [it, inserted] = index.try_emplace(g, Index(mesh.vertices.size()));
        if (inserted)
            mesh.vertices.push_back(Vec3(halfExtents.x() * (2.0 * g[0] / d[0] - 1.0), halfExtents.y() * (2.0 * g[1] / d[1] - 1.0),
                                         halfExtents.z() * (2.0 * g[2] / d[2] - 1.0)));
        return it->second;
    };
    // Each face: the lattice point at (a, b) of the face's grid; quads counter-clockwise seen
    // from outside (u x v along the outward normal).
    for (std::size_t axis = 0; axis < 3; ++axis)
        for (int side : {0, d[axis]}) {
            const std::size_t u = (axis + 1) % 3, v = (axis + 2) % 3;
            auto at = [&](int a, int b) {
                std::array<int, 3> g{};
                g[axis] = side;
                g[u] = a;
                g[v] = b;
                return vertex(g);
            };
            for (int a = 0; a < d[u]; ++a)
                for (int b = 0; b < d[v]; ++b) {
                    if (side == d[axis]) addQuad(mesh.faces, at(a, b), at(a + 1, b), at(a + 1, b + 1), at(a, b + 1));
                    else addQuad(mesh.faces, at(a, b), at(a, b + 1), at(a + 1, b + 1), at(a + 1, b));
                }
        }
    return mesh;
}

TriMesh makePlateWithHole(const Vec3& halfExtents, double holeX, double holeZ) {
    require(halfExtents.allFinite() && halfExtents.minCoeff() > 0.0, "plate needs finite half extents > 0");
    require(std::isfinite(holeX) && std::isfinite(holeZ) && holeX > 0.0 && holeZ > 0.0 && holeX < halfExtents.x() &&
                holeZ < halfExtents.z(),
            "plate's hole needs half widths > 0 and smaller than the plate's");
    TriMesh mesh;
    mesh.name = "plate";
    // Corners counter-clockwise seen from +y: outer top 0-3, inner top 4-7, outer bottom 8-11,
    // inner bottom 12-15.
    const double corner[4][2] = {{1, 1}, {1, -1}, {-1, -1}, {-1, 1}};
    for (double y : {halfExtents.y(), -halfExtents.y()})
        for (const auto& [x, z] : {std::pair{halfExtents.x(), halfExtents.z()}, std::pair{holeX, holeZ}})
            for (const auto& c : corner) mesh.vertices.push_back(Vec3(c[0] * x, y, c[1] * z));
    for (Index i = 0; i < 4; ++i) {
        const Index j = (i + 1) % 4;
        addQuad(mesh.faces, i, j, 4 + j, 4 + i);          // top ring, facing +y
        addQuad(mesh.faces, 8 + i, 12 + i, 12 + j, 8 + j);  // bottom ring, facing -y
        addQuad(mesh.faces, i, 8 + i, 8 + j, j);          // outer wall, facing out
        addQuad(mesh.faces, 4 + i, 4 + j, 12 + j, 12 + i);  // hole wall, facing the hole
    }
    return mesh;
}

TriMesh makeHeart(double size, int segments, int rings) {
    require(positiveFinite(size), "heart needs a finite size > 0");
    require(segments >= 3 && rings >= 2, "heart needs segments >= 3 and rings >= 2");
    requireVertexCount(static_cast<long long>(segments) * (rings - 1) + 2, "heart");
    // The implicit heart spans y in about [-1, 1.1]; centre it and scale its height to `size`.
    TriMesh unit = makePolarGrid(segments, rings, [](double t, double p) {
        const Vec3 dir = unitDirection(t, p);
        return Vec3(heartRadius(dir) * dir);
    });
    const Eigen::AlignedBox3d box = boundingBox(unit);
    const double scale = size / box.sizes().y();
    const Vec3 centre = box.center();
    for (Vec3& v : unit.vertices) v = (v - centre) * scale;
    unit.name = "heart";
    return unit;
}

namespace {
// The thesis's tori all share R = 10, r = 2.5 (the container mouth: outer 25, inner 15).
TriMesh namedTorus(const char* name, int segmentsU, int segmentsV) {
    TriMesh mesh = makeTorus(10.0, 2.5, segmentsU, segmentsV);
    mesh.name = name;
    return mesh;
}
}  // namespace

TriMesh makeTorus1() { return namedTorus("torus1", 24, 24); }
TriMesh makeTorus2() { return namedTorus("torus2", 54, 29); }
TriMesh makeContainerMouth() { return namedTorus("container_mouth", 64, 24); }

}  // namespace flexfit
