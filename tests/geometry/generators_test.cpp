// Tests the shape generators against the thesis's model sizes, Euler characteristics, half-edge orientation and analytic volumes (torus 2*pi^2*R*r^2, sphere 4/3*pi*r^3).
#include "flexfit/generators.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace flexfit {
namespace {

constexpr double kPi = std::numbers::pi;

// Signed volume by the divergence theorem: positive for an outward-oriented closed surface.
double signedVolume(const TriMesh& mesh) {
    double sum = 0.0;
    for (const Face& f : mesh.faces)
        sum += mesh.vertices[f[0]].dot(mesh.vertices[f[1]].cross(mesh.vertices[f[2]]));
    return sum / 6.0;
}

// Every directed edge appears exactly once and so does its reverse: a closed, consistently
// oriented 2-manifold (independent of validateMesh's undirected counts).
void expectConsistentlyOrientedClosed(const TriMesh& mesh) {
    std::map<std::pair<Index, Index>, int> directed;
    for (const Face& f : mesh.faces)
        for (int k = 0; k < 3; ++k) ++directed[{f[k], f[(k + 1) % 3]}];
    std::size_t bad = 0;
    for (const auto& [edge, count] : directed) {
        if (count != 1) ++bad;
        auto reverse = directed.find({edge.second, edge.first});
        if (reverse == directed.end() || reverse->second != 1) ++bad;
    }
    EXPECT_EQ(bad, 0u) << mesh.name;
}

long eulerCharacteristic(const TriMesh& mesh, std::size_t edges) {
    return long(mesh.vertices.size()) - long(edges) + long(mesh.faces.size());
}

// validateMesh passes with no warnings at all; returns the diagnostics.
MeshDiagnostics expectCleanClosed(const TriMesh& mesh) {
    MeshDiagnostics d;
    EXPECT_NO_THROW(d = validateMesh(mesh, mesh.name)) << mesh.name;
    EXPECT_TRUE(d.closed()) << mesh.name;
    EXPECT_EQ(d.boundaryEdges, 0u) << mesh.name;
    EXPECT_EQ(d.nonManifoldEdges, 0u) << mesh.name;
    EXPECT_EQ(d.unreferencedVertices, 0u) << mesh.name;
    EXPECT_TRUE(d.warnings.empty()) << mesh.name;
    return d;
}

bool bitIdentical(const TriMesh& a, const TriMesh& b) {
    if (a.name != b.name || a.vertices.size() != b.vertices.size() || a.faces != b.faces) return false;
    return std::memcmp(a.vertices.data(), b.vertices.data(), a.vertices.size() * sizeof(Vec3)) == 0;
}

double radialXZ(const Vec3& p) { return std::hypot(p.x(), p.z()); }

// ---------------------------------------------------------------------------------------------
// The thesis's models

TEST(Generators, MoreThan2048x2048VerticesAreRefusedBeforeAnyIsMade) {
    // gen torus --u 100000 --v 100000 had failed to allocate after 39 s.
    for (const auto& make : std::vector<std::function<TriMesh()>>{[] { return makeTorus(10, 2.5, 2049, 2048); },
                                                                  [] { return makeTorus(10, 2.5, 100000, 100000); },
                                                                  [] { return makeUvSphere(1, 2048, 2050); },
                                                                  [] { return makeHeart(20, 4096, 4096); }}) {
        try {
            make();
            ADD_FAILURE() << "accepted";
        } catch (const InputError& e) {
            EXPECT_NE(e.problem().find("at most 4194304 (2048 x 2048)"), std::string::npos) << e.problem();
        }
    }
    EXPECT_EQ(makeUvSphere(1, 2048, 2048).vertices.size(), 2048u * 2047u + 2u);  // at the limit, made
}

TEST(Generators, Torus1MatchesTheThesis) {
    const TriMesh mesh = makeTorus1();
    EXPECT_EQ(mesh.name, "torus1");
    EXPECT_EQ(mesh.vertices.size(), 576u);
    EXPECT_EQ(mesh.faces.size(), 1152u);
    const MeshDiagnostics d = expectCleanClosed(mesh);
    EXPECT_EQ(d.edgeCount, 1728u);
    EXPECT_EQ(eulerCharacteristic(mesh, d.edgeCount), 0);
}

TEST(Generators, Torus2) {
    const TriMesh mesh = makeTorus2();
    EXPECT_EQ(mesh.name, "torus2");
    EXPECT_EQ(mesh.vertices.size(), 1566u);  // thesis: 1,566 masses
    EXPECT_EQ(mesh.faces.size(), 2u * 54 * 29);
    const MeshDiagnostics d = expectCleanClosed(mesh);
    EXPECT_EQ(d.edgeCount, 4698u);  // 3UV (the thesis reports 4,600)
    EXPECT_EQ(eulerCharacteristic(mesh, d.edgeCount), 0);
}

TEST(Generators, HeartMatchesTheThesisMassCount) {
    const TriMesh mesh = makeHeart();
    EXPECT_EQ(mesh.name, "heart");
    EXPECT_EQ(mesh.vertices.size(), 7349u);
    EXPECT_EQ(mesh.faces.size(), 14694u);
    const MeshDiagnostics d = expectCleanClosed(mesh);
    EXPECT_EQ(d.edgeCount, 22041u);
    EXPECT_EQ(eulerCharacteristic(mesh, d.edgeCount), 2);
    expectConsistentlyOrientedClosed(mesh);
    EXPECT_GT(signedVolume(mesh), 0.0);
    // Scaled to `size` (20) along its height (y), centred on its bounding box.
    const Eigen::AlignedBox3d box = boundingBox(mesh);
    EXPECT_NEAR(box.sizes().y(), 20.0, 1e-9);
    EXPECT_NEAR(box.center().norm(), 0.0, 1e-9);
    // Heart-like: wider (x) than deep (z), and a real volume (between 20% and 80% of its box).
    EXPECT_GT(box.sizes().x(), box.sizes().z());
    const double boxVolume = box.sizes().prod();
    EXPECT_GT(signedVolume(mesh), 0.2 * boxVolume);
    EXPECT_LT(signedVolume(mesh), 0.8 * boxVolume);
}

TEST(Generators, HeartSizeAndResolution) {
    const TriMesh mesh = makeHeart(5.0, 24, 12);
    EXPECT_EQ(mesh.vertices.size(), 24u * 11 + 2);
    const MeshDiagnostics d = expectCleanClosed(mesh);
    EXPECT_EQ(eulerCharacteristic(mesh, d.edgeCount), 2);
    expectConsistentlyOrientedClosed(mesh);
    EXPECT_GT(signedVolume(mesh), 0.0);
    EXPECT_NEAR(boundingBox(mesh).sizes().y(), 5.0, 1e-12);
}

TEST(Generators, ContainerMouthDiameters) {
    const TriMesh mesh = makeContainerMouth();
    EXPECT_EQ(mesh.name, "container_mouth");
    EXPECT_EQ(mesh.vertices.size(), 64u * 24);
    expectCleanClosed(mesh);
    expectConsistentlyOrientedClosed(mesh);
    // Open along y: outer diameter 25 and inner diameter 15 in the xz plane, tube height 2r = 5.
    double minRadial = std::numeric_limits<double>::infinity(), maxRadial = 0.0;
    for (const Vec3& p : mesh.vertices) {
        minRadial = std::min(minRadial, radialXZ(p));
        maxRadial = std::max(maxRadial, radialXZ(p));
    }
    EXPECT_NEAR(2.0 * maxRadial, 25.0, 1e-9);
    EXPECT_NEAR(2.0 * minRadial, 15.0, 1e-9);
    const Eigen::AlignedBox3d box = boundingBox(mesh);
    EXPECT_NEAR(box.sizes().x(), 25.0, 1e-9);
    EXPECT_NEAR(box.sizes().z(), 25.0, 1e-9);
    EXPECT_NEAR(box.sizes().y(), 5.0, 1e-9);
    EXPECT_NEAR(box.center().norm(), 0.0, 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Topology, orientation and volume of every generator

struct VolumeCase {
    std::string label;
    std::function<TriMesh()> make;
    long euler;
    double analyticVolume;
    double relativeTolerance;  // |V - V_analytic| / V_analytic at this resolution (1: coarse, sign only)
};

std::vector<VolumeCase> volumeCases() {
    const double R = 10.0, r = 2.5;
    const double torusVolume = 2.0 * kPi * kPi * R * r * r;
    return {
        {"torus1", [] { return makeTorus1(); }, 0, torusVolume, 0.03},
        {"torus2", [] { return makeTorus2(); }, 0, torusVolume, 0.015},
        {"container_mouth", [] { return makeContainerMouth(); }, 0, torusVolume, 0.02},
        {"torus 3x3", [] { return makeTorus(3.0, 1.0, 3, 3); }, 0, 2.0 * kPi * kPi * 3.0, 1.0},
        {"torus 40x30", [] { return makeTorus(4.0, 1.5, 40, 30); }, 0, 2.0 * kPi * kPi * 4.0 * 1.5 * 1.5, 0.015},
        {"uv sphere 32x16", [] { return makeUvSphere(2.0, 32, 16); }, 2, 4.0 / 3.0 * kPi * 8.0, 0.02},
        {"uv sphere 3x2", [] { return makeUvSphere(1.0, 3, 2); }, 2, 4.0 / 3.0 * kPi, 1.0},
        {"icosphere 0", [] { return makeIcoSphere(1.0, 0); }, 2, 4.0 / 3.0 * kPi, 1.0},
        {"icosphere 3", [] { return makeIcoSphere(3.0, 3); }, 2, 4.0 / 3.0 * kPi * 27.0, 0.01},
    };
}

TEST(Generators, ClosedOrientedWithEulerCharacteristicAndVolume) {
    for (const VolumeCase& c : volumeCases()) {
        SCOPED_TRACE(c.label);
        const TriMesh mesh = c.make();
        const MeshDiagnostics d = expectCleanClosed(mesh);
        EXPECT_EQ(eulerCharacteristic(mesh, d.edgeCount), c.euler);
        expectConsistentlyOrientedClosed(mesh);
        const double volume = signedVolume(mesh);
        EXPECT_GT(volume, 0.0) << "inward oriented";
        // Inscribed polyhedra: slightly smaller than the smooth shape.
        EXPECT_LT(volume, c.analyticVolume);
        EXPECT_NEAR(volume / c.analyticVolume, 1.0, c.relativeTolerance);
    }
}

TEST(Generators, TorusFacesPointAwayFromTheTubeAxis) {
    const double R = 10.0;
    const TriMesh mesh = makeTorus1();
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
        const Vec3& a = mesh.vertices[mesh.faces[f][0]];
        const Vec3& b = mesh.vertices[mesh.faces[f][1]];
        const Vec3& c = mesh.vertices[mesh.faces[f][2]];
        const Vec3 centroid = (a + b + c) / 3.0;
        const Vec3 normal = (b - a).cross(c - a);
        // Nearest point on the tube's centre circle (radius R in the xz plane).
        const Vec3 axisPoint = R * Vec3(centroid.x(), 0.0, centroid.z()).normalized();
        EXPECT_GT(normal.dot(centroid - axisPoint), 0.0) << "face " << f;
    }
}

TEST(Generators, SphereFacesPointOutwardAndVerticesLieOnTheSphere) {
    for (const TriMesh& mesh : {makeUvSphere(2.0, 12, 7), makeIcoSphere(2.0, 2)}) {
        SCOPED_TRACE(mesh.name);
        for (const Vec3& v : mesh.vertices) EXPECT_NEAR(v.norm(), 2.0, 1e-12);
        for (const Face& f : mesh.faces) {
            const Vec3 &a = mesh.vertices[f[0]], &b = mesh.vertices[f[1]], &c = mesh.vertices[f[2]];
            EXPECT_GT((b - a).cross(c - a).dot(a + b + c), 0.0);
        }
    }
}

TEST(Generators, DocumentedCounts) {
    for (int u : {3, 4, 7, 24}) {
        for (int v : {3, 5, 24}) {
            const TriMesh t = makeTorus(5.0, 1.0, u, v);
            EXPECT_EQ(t.vertices.size(), std::size_t(u * v));
            EXPECT_EQ(t.faces.size(), std::size_t(2 * u * v));
            EXPECT_EQ(validateMesh(t, "torus").edgeCount, std::size_t(3 * u * v));
        }
    }
    for (int s : {3, 8, 17}) {
        for (int r : {2, 3, 9}) {
            const TriMesh sphere = makeUvSphere(1.0, s, r);
            EXPECT_EQ(sphere.vertices.size(), std::size_t(s * (r - 1) + 2));
            EXPECT_EQ(eulerCharacteristic(sphere, validateMesh(sphere, "uv").edgeCount), 2);
        }
    }
    for (int sub = 0; sub <= 4; ++sub) {
        const TriMesh ico = makeIcoSphere(1.0, sub);
        EXPECT_EQ(ico.vertices.size(), std::size_t(10 * (1 << (2 * sub)) + 2));
        EXPECT_EQ(ico.faces.size(), std::size_t(20 * (1 << (2 * sub))));
    }
}

TEST(Generators, DeterministicBitForBit) {
    EXPECT_TRUE(bitIdentical(makeTorus1(), makeTorus1()));
    EXPECT_TRUE(bitIdentical(makeTorus2(), makeTorus2()));
    EXPECT_TRUE(bitIdentical(makeContainerMouth(), makeContainerMouth()));
    EXPECT_TRUE(bitIdentical(makeTorus(7.0, 3.0, 11, 13), makeTorus(7.0, 3.0, 11, 13)));
    EXPECT_TRUE(bitIdentical(makeUvSphere(1.5, 20, 10), makeUvSphere(1.5, 20, 10)));
    EXPECT_TRUE(bitIdentical(makeIcoSphere(1.5, 3), makeIcoSphere(1.5, 3)));
    EXPECT_TRUE(bitIdentical(makeHeart(), makeHeart()));
}

TEST(Generators, BadArgumentsThrowInputError) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const std::vector<std::pair<std::string, std::function<void()>>> bad = {
        {"torus major == minor", [] { makeTorus(2.0, 2.0, 8, 8); }},
        {"torus major < minor", [] { makeTorus(1.0, 2.0, 8, 8); }},
        {"torus minor 0", [] { makeTorus(1.0, 0.0, 8, 8); }},
        {"torus minor < 0", [] { makeTorus(1.0, -0.5, 8, 8); }},
        {"torus NaN major", [nan] { makeTorus(nan, 1.0, 8, 8); }},
        {"torus NaN minor", [nan] { makeTorus(3.0, nan, 8, 8); }},
        {"torus U 2", [] { makeTorus(3.0, 1.0, 2, 8); }},
        {"torus V 2", [] { makeTorus(3.0, 1.0, 8, 2); }},
        {"torus U negative", [] { makeTorus(3.0, 1.0, -8, 8); }},
        {"uv sphere radius 0", [] { makeUvSphere(0.0, 8, 4); }},
        {"uv sphere radius < 0", [] { makeUvSphere(-1.0, 8, 4); }},
        {"uv sphere NaN radius", [nan] { makeUvSphere(nan, 8, 4); }},
        {"uv sphere segments 2", [] { makeUvSphere(1.0, 2, 4); }},
        {"uv sphere rings 1", [] { makeUvSphere(1.0, 8, 1); }},
        {"icosphere radius 0", [] { makeIcoSphere(0.0, 1); }},
        {"icosphere NaN radius", [nan] { makeIcoSphere(nan, 1); }},
        {"icosphere subdivisions -1", [] { makeIcoSphere(1.0, -1); }},
        {"icosphere subdivisions 9", [] { makeIcoSphere(1.0, 9); }},
        {"heart size 0", [] { makeHeart(0.0); }},
        {"heart size < 0", [] { makeHeart(-3.0); }},
        {"heart NaN size", [nan] { makeHeart(nan); }},
        {"heart segments 2", [] { makeHeart(20.0, 2, 10); }},
        {"heart rings 1", [] { makeHeart(20.0, 10, 1); }},
    };
    for (const auto& [label, call] : bad) {
        try {
            call();
            ADD_FAILURE() << label << ": no exception";
        } catch (const InputError& e) {
            EXPECT_EQ(e.source(), "generator") << label;
            EXPECT_FALSE(e.problem().empty()) << label;
        } catch (...) {
            ADD_FAILURE() << label << ": not an InputError";
        }
    }
}

// Infinite sizes pass the "> 0" checks; the header promises every generator output passes
// validateMesh, so they must be rejected as bad arguments too.
TEST(Generators, InfiniteSizesThrowInputError) {
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<std::pair<std::string, std::function<TriMesh()>>> bad = {
        {"torus infinite major", [inf] { return makeTorus(inf, 1.0, 8, 8); }},
        {"uv sphere infinite radius", [inf] { return makeUvSphere(inf, 8, 4); }},
        {"icosphere infinite radius", [inf] { return makeIcoSphere(inf, 1); }},
        {"heart infinite size", [inf] { return makeHeart(inf, 8, 4); }},
    };
    for (const auto& [label, call] : bad) {
        try {
            const TriMesh mesh = call();
            ADD_FAILURE() << label << ": no exception; the mesh "
                          << (mesh.vertices.empty() || mesh.vertices[0].allFinite() ? "is finite" : "has non-finite vertices");
        } catch (const InputError&) {
        } catch (...) {
            ADD_FAILURE() << label << ": not an InputError";
        }
    }
}

}  // namespace

TEST(Generators, BoxAndPlateAreClosedWithTheirExactVolumes) {
    // Flat faces: the volumes are exact (a box 8abc; a plate less its hole), the counts those
    // documented, and every face points out of the solid.
    for (int d : {1, 2, 5}) {
        SCOPED_TRACE(d);
        const TriMesh box = makeBox(Vec3(1.0, 2.0, 0.5), d);
        const MeshDiagnostics diagnostics = expectCleanClosed(box);
        EXPECT_EQ(eulerCharacteristic(box, diagnostics.edgeCount), 2);
        expectConsistentlyOrientedClosed(box);
        EXPECT_EQ(box.vertices.size(), std::size_t(6 * d * d + 2));
        EXPECT_NEAR(signedVolume(box), 8.0, 1e-12);
    }
    const TriMesh plate = makePlateWithHole(Vec3(3.0, 0.5, 2.0), 1.0, 0.75);
    const MeshDiagnostics diagnostics = expectCleanClosed(plate);
    EXPECT_EQ(eulerCharacteristic(plate, diagnostics.edgeCount), 0);  // genus 1
    expectConsistentlyOrientedClosed(plate);
    EXPECT_EQ(plate.vertices.size(), 16u);
    EXPECT_EQ(plate.faces.size(), 32u);
    EXPECT_NEAR(signedVolume(plate), 8.0 * 3.0 * 0.5 * 2.0 - 8.0 * 1.0 * 0.5 * 0.75, 1e-12);
    EXPECT_THROW(makeBox(Vec3(1, 0, 1)), InputError);
    EXPECT_THROW(makePlateWithHole(Vec3(1, 1, 1), 1.0, 0.5), InputError);
}

}  // namespace flexfit
