// Tests remeshForSimulation and measureQuality against analytic shapes: a box made of slivers
// comes out without them, every vertex on the box (the analytic distance to its surface), the
// corners and edges kept; an open square keeps its rim; the reported Hausdorff distance is at
// least a brute-force lower bound (output vertices against the input's triangles) and within
// the target edge, and agrees with dense brute-force sampling on a fan of needles, whose
// samples cover every face by its area; a chamfer narrower than half the edge is rounded (the rest kept, every vertex
// on the input's planes) and ThinFeatures::Auto chooses as its rule says; bad options are errors.
#include "flexfit/generators.hpp"
#include "flexfit/remesh.hpp"
#include "geometry/remesh_samples.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <vector>

#include "one_core.hpp"

namespace flexfit {
namespace {

// A box of half extents h whose six sides are fans of slivers: each side's quad (a b c d, two
// triangles over the diagonal a-c) gets `n` points along that diagonal, fanned from b and
// from d. The box's own edges are untouched, so the surface stays closed.
TriMesh sliverBox(const Vec3& h, int n) {
    const TriMesh box = makeBox(h, 1);
    TriMesh out;
    out.name = "slivers";
    out.vertices = box.vertices;
    for (std::size_t f = 0; f + 1 < box.faces.size(); f += 2) {
        const Index a = box.faces[f][0], b = box.faces[f][1], c = box.faces[f][2], d = box.faces[f + 1][2];
        std::vector<Index> diagonal{a};
        for (int i = 1; i <= n; ++i) {
            diagonal.push_back(Index(out.vertices.size()));
            out.vertices.push_back(box.vertices[a] + (double(i) / double(n + 1)) * (box.vertices[c] - box.vertices[a]));
        }
        diagonal.push_back(c);
        for (std::size_t i = 0; i + 1 < diagonal.size(); ++i) {
            out.faces.push_back({diagonal[i], b, diagonal[i + 1]});  // within (a b c)
            out.faces.push_back({diagonal[i], diagonal[i + 1], d});  // within (a c d)
        }
    }
    return out;
}

double distanceToBoxSurface(const Vec3& p, const Vec3& h) {
    const Vec3 q = p.cwiseAbs() - h;
    const double outside = q.cwiseMax(0.0).norm();
    return outside > 0.0 ? outside : -q.maxCoeff();
}

// Distance from p to triangle abc: to its projection on the plane when that lies inside, else
// to the nearest of its three sides (independent of the library's closest-point code).
double distanceBySides(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 normal = (b - a).cross(c - a).normalized();
    const Vec3 q = p - (p - a).dot(normal) * normal;
    if ((b - a).cross(q - a).dot(normal) >= 0 && (c - b).cross(q - b).dot(normal) >= 0 && (a - c).cross(q - c).dot(normal) >= 0)
        return (p - q).norm();
    auto toSide = [&p](const Vec3& u, const Vec3& v) {
        const double t = std::clamp((p - u).dot(v - u) / (v - u).squaredNorm(), 0.0, 1.0);
        return (u + t * (v - u) - p).norm();
    };
    return std::min({toSide(a, b), toSide(b, c), toSide(c, a)});
}

TEST(Remesh, SliversBecomeNearUniformTrianglesOnTheSameBox) {
    const Vec3 h(1.0, 0.5, 0.75);
    const TriMesh input = sliverBox(h, 12);
    ASSERT_NO_THROW(validateMesh(input, "input"));
    const RemeshResult r = remeshForSimulation(input, {.targetEdge = 0.15, .iterations = 5, .featureAngle = 40.0}, "box");
    EXPECT_GT(r.before.slivers, 0.9);  // the fans are nearly all slivers
    EXPECT_LT(r.before.minAngle, 3.0);
    EXPECT_LT(r.after.slivers, 0.01);
    EXPECT_GT(r.after.faces, 500u);
    EXPECT_LT(r.after.edgeSpread, 0.3);
    EXPECT_NEAR(r.after.meanEdge, 0.15, 0.045);
    EXPECT_EQ(r.featureEdges, 12u);  // the box's edges; the diagonals are flat
    // Every vertex on the box's surface; its 8 corners kept exactly where they were.
    for (const Vec3& v : r.mesh.vertices) EXPECT_NEAR(distanceToBoxSurface(v, h), 0.0, 1e-9) << v.transpose();
    for (const Vec3& corner : makeBox(h, 1).vertices) {
        const bool kept = std::any_of(r.mesh.vertices.begin(), r.mesh.vertices.end(), [&](const Vec3& v) { return (v - corner).norm() < 1e-9; });
        EXPECT_TRUE(kept) << corner.transpose();
    }
    // A box's surface is exact under remeshing with its edges kept: no distance.
    EXPECT_LT(r.hausdorffShare(), 1e-9);
    EXPECT_NO_THROW(validateMesh(r.mesh, "output"));
}

TEST(Remesh, HausdorffDistanceIsAtLeastTheFarthestVertexAndWithinTheEdge) {
    // A coarse icosphere remeshed finer: the output lies on the input polyhedron (projection),
    // so the reported distance is small; a brute-force lower bound must not exceed it.
    const TriMesh input = makeIcoSphere(1.0, 1);
    const RemeshResult r = remeshForSimulation(input, {.targetEdge = 0.15}, "sphere");
    double lower = 0.0;
    for (std::size_t i = 0; i < r.mesh.vertices.size(); i += 25) {
        const Vec3& p = r.mesh.vertices[i];
        double nearest = std::numeric_limits<double>::infinity();
        for (const Face& f : input.faces)
            nearest = std::min(nearest, distanceBySides(p, input.vertices[f[0]], input.vertices[f[1]], input.vertices[f[2]]));
        lower = std::max(lower, nearest);
    }
    EXPECT_GE(r.hausdorff + 1e-9, lower);  // the samples include the output's vertices
    EXPECT_LT(r.hausdorff, 0.15);
    EXPECT_LT(r.after.slivers, 0.01);
}

// Points of every face at most about `spacing` apart: each triangle cut into n^2 (barycentric
// grid), n from its longest edge. Dense on needles, unlike the remesher's own sampling.
std::vector<Vec3> denseSamples(const TriMesh& mesh, double spacing) {
    std::vector<Vec3> out;
    for (const Face& f : mesh.faces) {
        const Vec3 &a = mesh.vertices[f[0]], &b = mesh.vertices[f[1]], &c = mesh.vertices[f[2]];
        const int n = std::max(1, int(std::ceil(std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()}) / spacing)));
        for (int i = 0; i <= n; ++i)
            for (int j = 0; i + j <= n; ++j) out.push_back(a + (double(i) / n) * (b - a) + (double(j) / n) * (c - a));
    }
    return out;
}

double farthestBruteForce(const TriMesh& from, const TriMesh& to, double spacing) {
    double farthest = 0.0;
    for (const Vec3& p : denseSamples(from, spacing)) {
        double nearest = std::numeric_limits<double>::infinity();
        for (const Face& f : to.faces) nearest = std::min(nearest, distanceBySides(p, to.vertices[f[0]], to.vertices[f[1]], to.vertices[f[2]]));
        farthest = std::max(farthest, nearest);
    }
    return farthest;
}

// A target edge far beyond the part (a unit mistaken) leaves a handful of faces; the distance
// reported must still be measured at the part's scale. Both it and a brute force over samples
// 1 % of the diagonal apart are lower bounds of the true distance, each short of it by about
// its samples' spacing (the remesher's: a quarter of the edge, at most 2.5 % of the diagonal;
// they were once spaced by the edge alone, and read 5.8 where the distance is 7.5).
TEST(Remesh, TheHausdorffDistanceOfACoarseRemeshIsMeasuredAtThePartsScale) {
    const TriMesh input = makeTorus(10.0, 2.5, 32, 12);
    for (const double edge : {50.0, 1e6}) {
        const RemeshResult r = remeshForSimulation(input, {.targetEdge = edge}, "torus");
        const double spacing = 0.01 * r.diagonal;
        const double lower = std::max(farthestBruteForce(input, r.mesh, spacing), farthestBruteForce(r.mesh, input, spacing));
        EXPECT_GE(r.hausdorff, lower - 0.025 * r.diagonal) << "edge " << edge;
        EXPECT_LE(r.hausdorff, lower + 0.02 * r.diagonal) << "edge " << edge;
    }
}

// An open cone of height 1 and radius 1: a fan of n needles from its apex.
TriMesh needleCone(int n) {
    TriMesh cone;
    cone.name = "needles";
    cone.vertices.push_back(Vec3(0, 1, 0));
    for (int i = 0; i < n; ++i) cone.vertices.push_back(Vec3(std::cos(2 * M_PI * i / n), 0, std::sin(2 * M_PI * i / n)));
    for (int i = 0; i < n; ++i) cone.faces.push_back({0, Index(1 + (i + 1) % n), Index(1 + i)});
    return cone;
}

TEST(Remesh, HausdorffSamplesCoverEachFaceByItsArea) {
    // Every dense point of the surface (brute force) lies within 0.75 spacing of a sample (rows
    // and points at most a spacing apart), and the samples number about area / spacing^2: on
    // needles too, where a grid along two edges of each face would make (length / spacing)^2 / 2.
    const double spacing = 0.0625;
    for (const TriMesh& mesh : {needleCone(24), makeIcoSphere(1.0, 1)}) {
        SCOPED_TRACE(mesh.name);
        const std::vector<Vec3> samples = detail::hausdorffSamples(mesh, spacing);
        double area = 0.0, edgeLength = 0.0;
        for (const Face& f : mesh.faces) {
            const Vec3 &a = mesh.vertices[f[0]], &b = mesh.vertices[f[1]], &c = mesh.vertices[f[2]];
            area += 0.5 * (b - a).cross(c - a).norm();
            edgeLength += (b - a).norm() + (c - b).norm() + (a - c).norm();  // each edge about twice
        }
        EXPECT_LE(double(samples.size()), 2.0 * area / (spacing * spacing) + edgeLength / spacing + double(mesh.vertices.size()));
        double farthest = 0.0;
        for (const Vec3& p : denseSamples(mesh, 0.4 * spacing)) {
            double nearest = std::numeric_limits<double>::infinity();
            for (const Vec3& q : samples) nearest = std::min(nearest, (q - p).squaredNorm());
            farthest = std::max(farthest, nearest);
        }
        EXPECT_LE(std::sqrt(farthest), 0.75 * spacing);
    }
}

TEST(Remesh, HausdorffDistanceOfAFanOfNeedlesAgreesWithDenseSampling) {
    // An open cone made of 24 needles (apex angle 10.6 degrees, 1.4 long), remeshed at 0.25:
    // the reported distance samples each face by its area, not along its long edges. Dense
    // brute force over both surfaces (0.04 apart) is a lower bound of the true distance, short
    // of it by at most 0.04; the reported one, from samples a quarter of the edge apart
    // (0.0625), is short of the truth by at most about 0.71 of that.
    const TriMesh cone = needleCone(24);
    const double edge = 0.25;
    const RemeshResult r = remeshForSimulation(cone, {.targetEdge = edge}, "cone");
    ASSERT_GT(r.before.slivers, 0.99);
    const double dense = 0.04;
    const double lower = std::max(farthestBruteForce(cone, r.mesh, dense), farthestBruteForce(r.mesh, cone, dense));
    EXPECT_GT(lower, 0.0);
    EXPECT_LE(r.hausdorff, lower + dense + 1e-9);
    EXPECT_GE(r.hausdorff, lower - 0.71 * 0.25 * edge - 1e-9);
}

#if defined(__linux__)
TEST(Remesh, OneCoreMakesTheSameSurfaceAsAll) {
    // The projection and the Hausdorff sampling run in fixed chunks on the usable cores: pinned to
    // one core, the surface and the distance must come out bit for bit the same.
    const TriMesh input = sliverBox(Vec3(1.0, 0.7, 0.5), 8);
    const RemeshOptions options{.targetEdge = 0.1};
    const RemeshResult all = remeshForSimulation(input, options, "box");
    const RemeshResult single = flexfit::testing::onOneCore([&] { return remeshForSimulation(input, options, "box"); });
    EXPECT_GT(all.mesh.vertices.size(), 1024u);  // more than one chunk of vertices, and of samples
    EXPECT_EQ(single.mesh.vertices, all.mesh.vertices);
    EXPECT_EQ(single.mesh.faces, all.mesh.faces);
    EXPECT_EQ(single.hausdorff, all.hausdorff);
}
#endif

TEST(Remesh, AnOpenSurfaceKeepsItsRim) {
    TriMesh square;
    square.vertices = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
    square.faces = {{0, 2, 1}, {0, 3, 2}};
    const RemeshResult r = remeshForSimulation(square, {.targetEdge = 0.1}, "square");
    EXPECT_EQ(r.featureEdges, 4u);  // the border
    EXPECT_GT(r.after.faces, 150u);
    std::size_t onRim = 0;
    for (const Vec3& v : r.mesh.vertices) {
        EXPECT_NEAR(v.y(), 0.0, 1e-12);
        EXPECT_GE(v.x(), -1e-12);
        EXPECT_LE(v.x(), 1 + 1e-12);
        EXPECT_GE(v.z(), -1e-12);
        EXPECT_LE(v.z(), 1 + 1e-12);
        onRim += (std::min({v.x(), 1 - v.x(), v.z(), 1 - v.z()}) < 1e-12) ? 1 : 0;
    }
    EXPECT_GE(onRim, 32u);  // the rim split into edges of at most 4/3 of the target: 8 or more a side
    for (const Vec3& corner : square.vertices) {
        const bool kept = std::any_of(r.mesh.vertices.begin(), r.mesh.vertices.end(), [&](const Vec3& v) { return (v - corner).norm() < 1e-12; });
        EXPECT_TRUE(kept) << corner.transpose();
    }
}

TEST(Remesh, MeasuredQualityMatchesHandCountedTriangles) {
    TriMesh mesh;
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {10, 0.5, 0}};
    mesh.faces = {{0, 1, 2}, {1, 3, 2}};
    const MeshQuality q = measureQuality(mesh);
    EXPECT_EQ(q.faces, 2u);
    EXPECT_DOUBLE_EQ(q.slivers, 0.5);  // the long triangle has an angle of ~5.7 degrees
    // The long triangle's angle at (10, 0.5, 0), between the directions to (0, 1, 0) and (1, 0, 0).
    const Vec3 tip(10, 0.5, 0);
    const double sliverAngle = std::acos((Vec3(0, 1, 0) - tip).normalized().dot((Vec3(1, 0, 0) - tip).normalized())) * 180 / M_PI;
    EXPECT_NEAR(q.minAngle, sliverAngle, 1e-9);
    EXPECT_DOUBLE_EQ(q.minEdge, 1.0);
    EXPECT_DOUBLE_EQ(q.maxEdge, (tip - Vec3(0, 1, 0)).norm());
}

TEST(Remesh, ANonManifoldInputIsSplitIntoASurfaceFirst) {
    // Two tetrahedra sharing one edge (0 1): an edge of four faces. CGAL's soup orientation
    // duplicates the shared vertices, and each tetrahedron is remeshed on its own.
    TriMesh mesh;
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, 0.3, 1}, {0.5, -1, 0}, {0.5, -0.3, -1}};
    mesh.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}, {0, 1, 4}, {0, 5, 1}, {0, 4, 5}, {1, 5, 4}};
    const RemeshResult r = remeshForSimulation(mesh, {.targetEdge = 0.1}, "bowtie");
    EXPECT_GT(r.after.faces, 200u);
    EXPECT_NO_THROW(validateMesh(r.mesh, "output"));
    EXPECT_LT(r.hausdorffShare(), 0.05);
}

// A plate (y = 0) and a fin (x from 0 to 1, y from 0 up to 0.5) joined along z = 0.5 through
// nine irregularly spaced vertices: eight non-manifold edges, each used by both plate halves
// and the fin.
TriMesh plateAndFin() {
    TriMesh m;
    m.name = "tee";
    const std::vector<double> xs{0, 0.13, 0.21, 0.26, 0.5, 0.55, 0.8, 0.87, 1.0};
    for (double x : xs) m.vertices.push_back({x, 0, 0.5});
    const Index front0 = 9, front1 = 10, back0 = 11, back1 = 12, top0 = 13, top1 = 14;
    m.vertices.insert(m.vertices.end(), {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {1, 0, 1}, {0, 0.5, 0.5}, {1, 0.5, 0.5}});
    for (Index i = 0; i + 1 < 9; ++i) {
        m.faces.push_back({front0, i, Index(i + 1)});
        m.faces.push_back({back1, Index(i + 1), i});
        m.faces.push_back({i == 0 ? top0 : top1, Index(i + 1), i});
    }
    m.faces.push_back({front0, 8, front1});
    m.faces.push_back({back1, 0, back0});
    m.faces.push_back({top0, top1, 1});
    return m;
}

TEST(Remesh, ANonManifoldJunctionStaysJoined) {
    const TriMesh tee = plateAndFin();
    ASSERT_EQ(validateMesh(tee, "tee").nonManifoldEdges, 8u);
    for (double edge : {0.1, 0.15, 0.2}) {
        const RemeshResult r = remeshForSimulation(tee, {.targetEdge = edge}, "tee");
        EXPECT_GT(r.seamVertices, 0u);
        // The output's edges along the junction: each used by three faces (plate, plate, fin),
        // none by one (a crack), and they cover the junction from x = 0 to 1.
        std::map<std::pair<Index, Index>, int> uses;
        for (const Face& f : r.mesh.faces)
            for (int k = 0; k < 3; ++k) ++uses[std::minmax(f[k], f[(k + 1) % 3])];
        auto onJunction = [&](Index v) { return r.mesh.vertices[v].y() == 0.0 && r.mesh.vertices[v].z() == 0.5; };
        double covered = 0.0;
        for (const auto& [e, n] : uses) {
            if (!onJunction(e.first) || !onJunction(e.second)) continue;
            EXPECT_EQ(n, 3) << "edge " << r.mesh.vertices[e.first].transpose() << " - " << r.mesh.vertices[e.second].transpose() << " at " << edge;
            covered += (r.mesh.vertices[e.first] - r.mesh.vertices[e.second]).norm();
        }
        EXPECT_NEAR(covered, 1.0, 1e-12) << edge;
        EXPECT_EQ(validateMesh(r.mesh, "output").nonManifoldEdges, std::size_t(std::count_if(uses.begin(), uses.end(), [](const auto& u) { return u.second > 2; })));
    }
}

TEST(Remesh, BadOptionsAreErrors) {
    const TriMesh mesh = makeIcoSphere(1.0, 1);
    for (double edge : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(), 1e-5}) {
        try {
            remeshForSimulation(mesh, {.targetEdge = edge}, "part.obj");
            ADD_FAILURE() << "accepted edge " << edge;
        } catch (const InputError& e) {
            EXPECT_EQ(e.source(), "part.obj");
            EXPECT_NE(e.problem().find("target edge"), std::string::npos) << e.problem();
        }
    }
    EXPECT_THROW(remeshForSimulation(mesh, {.targetEdge = 0.1, .iterations = 0}, "part.obj"), InputError);
    EXPECT_THROW(remeshForSimulation(mesh, {.targetEdge = 0.1, .featureAngle = 180.0}, "part.obj"), InputError);
}

TEST(Remesh, EdgesThatWouldMakeMillionsOfTrianglesOrThatTheCoordinatesCannotResolveAreRefused) {
    // A unit sphere (area about 4 pi): 2e6 equilateral triangles of edge L cover
    // 2e6 sqrt(3) / 4 L^2, so L = 0.003 would make about 2.8 million; 0.0036 about 1.9 million.
    const TriMesh sphere = makeIcoSphere(1.0, 3);
    double area = 0.0;
    for (const Face& f : sphere.faces)
        area += 0.5 * (sphere.vertices[f[1]] - sphere.vertices[f[0]]).cross(sphere.vertices[f[2]] - sphere.vertices[f[0]]).norm();
    const double limitEdge = std::sqrt(area / (2e6 * std::sqrt(3.0) / 4.0));
    try {
        remeshForSimulation(sphere, {.targetEdge = 0.9 * limitEdge}, "ball.obj");
        ADD_FAILURE() << "accepted an edge for ~2.5 million triangles";
    } catch (const InputError& e) {
        EXPECT_NE(e.problem().find("triangles"), std::string::npos) << e.problem();
        EXPECT_NE(e.problem().find("use a longer edge"), std::string::npos) << e.problem();
    }
    // A tiny part far from the origin: edges of 1e-10 at x = 1e6 are below what doubles resolve
    // there (about 1.2e-10); CGAL had split them without end, until memory ran out.
    TriMesh far = makeIcoSphere(1e-9, 1);
    for (Vec3& p : far.vertices) p.x() += 1e6;
    try {
        remeshForSimulation(far, {.targetEdge = 1e-10}, "far.obj");
        ADD_FAILURE() << "accepted an edge the coordinates cannot resolve";
    } catch (const InputError& e) {
        EXPECT_NE(e.problem().find("cannot resolve"), std::string::npos) << e.problem();
    }
}

// The box [-1, 1]^3 with its edge at x = y = 1 cut by the plane x + y = 2 - c: a chamfer
// c sqrt(2) wide between two sharp edges of 45 degrees. Its faces are fans of its polygons.
struct ChamferedBox {
    double c;
    TriMesh mesh() const {
        TriMesh out;
        out.name = "chamfered";
        for (double z : {-1.0, 1.0}) out.vertices.insert(out.vertices.end(), {{-1, -1, z}, {1, -1, z}, {1, 1 - c, z}, {1 - c, 1, z}, {-1, 1, z}});
        const std::vector<std::vector<Index>> polygons{{0, 4, 3, 2, 1}, {5, 6, 7, 8, 9}, {0, 1, 6, 5}, {1, 2, 7, 6}, {2, 3, 8, 7}, {3, 4, 9, 8}, {4, 0, 5, 9}};
        for (const std::vector<Index>& p : polygons)
            for (std::size_t k = 1; k + 1 < p.size(); ++k) out.faces.push_back({p[0], p[k], p[k + 1]});
        return out;
    }
    // Signed distance to the nearest of its planes: 0 on its surface (it is convex).
    double planeDistance(const Vec3& p) const {
        return std::max({p.cwiseAbs().maxCoeff() - 1.0, (p.x() + p.y() - (2.0 - c)) / std::sqrt(2.0)});
    }
};

bool samePoint(const std::vector<Vec3>& points, const Vec3& p) {
    return std::any_of(points.begin(), points.end(), [&](const Vec3& v) { return (v - p).norm() < 1e-12; });
}

// ThinFeatures::Auto against the two outright choices on the same input: it tries rounding when
// 1 % or more of the kept surface's triangles are slivers, and returns the rounded surface when
// it has fewer slivers, lies within the target edge of the input (or no farther than the kept
// one) and is closed if the kept one is; otherwise the kept surface, bit for bit.
void expectAutoFollowsItsRule(const TriMesh& input, double edge, const RemeshResult& kept, const RemeshResult& rounded) {
    const RemeshResult chosen = remeshForSimulation(input, {.targetEdge = edge}, "auto");
    const bool tried = kept.after.slivers >= 0.01;
    const bool staysClosed = validateMesh(rounded.mesh, "rounded").closed() || !validateMesh(kept.mesh, "kept").closed();
    const bool round = tried && rounded.after.slivers < kept.after.slivers && rounded.hausdorff <= std::max(kept.hausdorff, edge) && staysClosed;
    EXPECT_EQ(chosen.rounded, round);
    EXPECT_EQ(chosen.releasedEdges, tried ? rounded.releasedEdges : 0u);
    const RemeshResult& expected = round ? rounded : kept;
    EXPECT_EQ(chosen.mesh.vertices, expected.mesh.vertices);
    EXPECT_EQ(chosen.mesh.faces, expected.mesh.faces);
    EXPECT_EQ(chosen.hausdorff, expected.hausdorff);
}

TEST(Remesh, AChamferNarrowerThanHalfTheEdgeIsRoundedAndTheRestKept) {
    const ChamferedBox box{0.02};  // the chamfer 0.028 wide: 0.11 of the edge
    const double edge = 0.25;
    const TriMesh input = box.mesh();
    const RemeshResult kept = remeshForSimulation(input, {.targetEdge = edge, .thinFeatures = ThinFeatures::Keep}, "box");
    const RemeshResult rounded = remeshForSimulation(input, {.targetEdge = edge, .thinFeatures = ThinFeatures::Round}, "box");
    // Kept: the surface exact, the chamfer's corners kept, slivers along it.
    EXPECT_LT(kept.hausdorff, 1e-9);
    EXPECT_GT(kept.after.slivers, 0.01);
    EXPECT_EQ(kept.releasedEdges, 0u);
    for (const Vec3& corner : input.vertices) EXPECT_TRUE(samePoint(kept.mesh.vertices, corner)) << corner.transpose();
    // Rounded: no sliver; every vertex still on the input's surface (its planes, analytically);
    // the box's corners away from the chamfer kept; the chamfer cut by less than half the edge.
    EXPECT_TRUE(rounded.rounded);
    EXPECT_GT(rounded.releasedEdges, 0u);
    EXPECT_EQ(rounded.after.slivers, 0.0);
    EXPECT_GT(rounded.after.minAngle, 25.0);
    for (const Vec3& v : rounded.mesh.vertices) EXPECT_NEAR(box.planeDistance(v), 0.0, 1e-9) << v.transpose();
    for (const Vec3& corner : input.vertices) {
        const bool onTheChamfer = corner.x() + corner.y() > 1.5;
        EXPECT_TRUE(onTheChamfer || samePoint(rounded.mesh.vertices, corner)) << corner.transpose();
    }
    EXPECT_GT(rounded.hausdorff, 0.0);
    EXPECT_LT(rounded.hausdorff, 0.5 * edge);
    EXPECT_EQ(rounded.roundedHausdorff, rounded.hausdorff);
    EXPECT_TRUE(validateMesh(kept.mesh, "kept").closed());
    EXPECT_TRUE(validateMesh(rounded.mesh, "rounded").closed());
    expectAutoFollowsItsRule(input, edge, kept, rounded);
}

TEST(Remesh, AutoKeepsTheSharpEdgesWhereRoundingLeavesNoFewerSlivers) {
    // A bar 0.04 thick remeshed at 0.2: its long sides are slivers however they are cut, and
    // rounding its edges leaves more of them.
    const TriMesh bar = makeBox(Vec3(0.02, 0.02, 1.0), 1);
    const double edge = 0.2;
    const RemeshResult kept = remeshForSimulation(bar, {.targetEdge = edge, .thinFeatures = ThinFeatures::Keep}, "bar");
    const RemeshResult rounded = remeshForSimulation(bar, {.targetEdge = edge, .thinFeatures = ThinFeatures::Round}, "bar");
    EXPECT_GT(kept.after.slivers, 0.5);
    EXPECT_GE(rounded.after.slivers, kept.after.slivers);
    EXPECT_GT(rounded.releasedEdges, 0u);
    expectAutoFollowsItsRule(bar, edge, kept, rounded);
}

}  // namespace
}  // namespace flexfit
