// Surface embedding: a drawn mesh carried by a simulation surface, checked against motions whose
// effect on a point is known in closed form (identity, rigid motions, stretches).
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

using namespace flexfit;

namespace {

void expectNear(const std::vector<Vec3>& got, const std::vector<Vec3>& want, double tolerance) {
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < got.size(); ++i) EXPECT_LT((got[i] - want[i]).norm(), tolerance) << "vertex " << i;
}

// One drawn vertex per face of `simulation`, strictly inside it (weights 0.2..0.6) and `lift`
// along its normal; the drawn mesh's faces are consecutive triples of these vertices.
TriMesh pointsOver(const TriMesh& simulation, double lift, std::mt19937& rng) {
    std::uniform_real_distribution<double> share(0.2, 0.4);
    TriMesh drawn;
    for (const Face& f : simulation.faces) {
        const Vec3 &a = simulation.vertices[f[0]], &b = simulation.vertices[f[1]], &c = simulation.vertices[f[2]];
        const double wb = share(rng), wc = share(rng);
        drawn.vertices.push_back((1.0 - wb - wc) * a + wb * b + wc * c + lift * (b - a).cross(c - a).normalized());
    }
    for (Index i = 0; i + 2 < drawn.vertices.size(); i += 3) drawn.faces.push_back({i, i + 1, i + 2});
    return drawn;
}

std::vector<Vec3> transformed(const std::vector<Vec3>& points, const Eigen::Matrix3d& m, const Vec3& t) {
    std::vector<Vec3> out;
    for (const Vec3& p : points) out.push_back(m * p + t);
    return out;
}

}  // namespace

// Bit for bit, -0.0 included (== would take it for +0.0).
bool sameBits(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3)) == 0;
}

TEST(SurfaceEmbedding, AtRestTheDrawnMeshIsExactlyItself) {
    const TriMesh simulation = makeIcoSphere(1.0, 2);
    TriMesh drawn = makeIcoSphere(1.003, 3);
    for (Vec3& p : drawn.vertices)
        for (int c = 0; c < 3; ++c)
            if (p[c] == 0.0) p[c] = -0.0;  // as exporters write "-0.000000"
    const SurfaceEmbedding e = embedSurface(drawn, simulation, "test");
    EXPECT_GT(e.maxDistance, 0.0);
    std::vector<Vec3> out;
    embeddedPositions(e, simulation.faces, simulation.vertices, out);
    EXPECT_TRUE(sameBits(out, drawn.vertices));
    EXPECT_EQ(e.mesh.faces, drawn.faces);
}

TEST(SurfaceEmbedding, TheSimulationMeshItselfFollowsEveryDeformation) {
    const TriMesh simulation = makeTorus1();
    const SurfaceEmbedding e = embedSurface(simulation, simulation, "test");
    EXPECT_EQ(e.maxDistance, 0.0);
    std::mt19937 rng(7);
    std::normal_distribution<double> jitter(0.0, 0.3);
    std::vector<Vec3> x = simulation.vertices;
    for (Vec3& p : x) p += Vec3(jitter(rng), jitter(rng), jitter(rng));
    std::vector<Vec3> out;
    embeddedPositions(e, simulation.faces, x, out);
    expectNear(out, x, 1e-12);
    for (std::size_t i = 0; i < e.vertexCount(); ++i) EXPECT_EQ(e.nearestMass[i], Index(i));
}

TEST(SurfaceEmbedding, PointsOverFacesFollowRigidMotionsAndStretches) {
    const TriMesh simulation = makeIcoSphere(2.0, 2);
    std::mt19937 rng(11);
    for (const double lift : {0.0, 0.01, -0.01}) {
        const TriMesh drawn = pointsOver(simulation, lift, rng);
        const SurfaceEmbedding e = embedSurface(drawn, simulation, "test");
        for (std::size_t i = 0; i < e.vertexCount(); ++i) {
            EXPECT_EQ(e.triangle[i], Index(i)) << "vertex " << i << ", lift " << lift;
            EXPECT_NEAR(e.offset[i], lift, 1e-12);
        }
        const Eigen::Matrix3d r = Eigen::AngleAxisd(0.7, Vec3(1, 2, -0.5).normalized()).toRotationMatrix();
        const Vec3 t(0.3, -4.0, 2.5);
        std::vector<Vec3> out;
        embeddedPositions(e, simulation.faces, transformed(simulation.vertices, r, t), out);
        expectNear(out, transformed(drawn.vertices, r, t), 1e-12);
        if (lift != 0.0) continue;  // a stretch turns normals: only points on the faces map linearly
        const Eigen::Matrix3d stretch = Vec3(1.5, 1.0, 0.8).asDiagonal();
        embeddedPositions(e, simulation.faces, transformed(simulation.vertices, stretch, t), out);
        expectNear(out, transformed(drawn.vertices, stretch, t), 1e-12);
    }
}

TEST(SurfaceEmbedding, MeshesWithoutFacesAreRejected) {
    const TriMesh simulation = makeIcoSphere(1.0, 1);
    TriMesh empty;
    empty.vertices = simulation.vertices;
    EXPECT_THROW(embedSurface(empty, simulation, "test"), InputError);
    EXPECT_THROW(embedSurface(simulation, empty, "test"), InputError);
}

TEST(SurfaceEmbedding, PositionsOrFacesOfAnotherMeshAreAnError) {
    // Positions of another mesh read past their end (found under AddressSanitizer).
    const TriMesh simulation = makeIcoSphere(1.0, 1);
    const SurfaceEmbedding e = embedSurface(makeIcoSphere(1.05, 2), simulation, "test");
    std::vector<Vec3> out;
    const std::vector<Vec3> two(2, Vec3::Zero());
    EXPECT_THROW(embeddedPositions(e, simulation.faces, two, out), InputError);
    const std::span<const Face> fewer(simulation.faces.data(), simulation.faces.size() - 1);
    EXPECT_THROW(embeddedPositions(e, fewer, simulation.vertices, out), InputError);
    embeddedPositions(e, simulation.faces, simulation.vertices, out);
    EXPECT_EQ(out, e.mesh.vertices);
}

TEST(SurfaceEmbedding, ADrawnVertexThatIsNotFiniteIsAnError) {
    TriMesh drawn = makeIcoSphere(1.05, 1);
    drawn.vertices[3].y() = std::nan("");
    EXPECT_THROW((void)embedSurface(drawn, makeIcoSphere(1.0, 1), "test"), InputError);
}
