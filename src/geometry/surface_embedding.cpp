#include "flexfit/surface_embedding.hpp"

#include "flexfit/bvh.hpp"
#include "flexfit/collision.hpp"
#include "collision/triangle_queries.hpp"

#include <algorithm>
#include <cmath>

namespace flexfit {
namespace {

// Barycentric weights of q, a point of the triangle (a, b, c); a degenerate triangle gives its
// corner nearest to q all the weight.
Vec3 barycentric(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 e1 = b - a, e2 = c - a, r = q - a;
    const double d11 = e1.dot(e1), d12 = e1.dot(e2), d22 = e2.dot(e2);
    const double det = d11 * d22 - d12 * d12;
    if (!(det > 1e-24 * d11 * d22)) {
        const double da = (q - a).squaredNorm(), db = (q - b).squaredNorm(), dc = (q - c).squaredNorm();
        if (da <= db && da <= dc) return {1.0, 0.0, 0.0};
        return db <= dc ? Vec3(0.0, 1.0, 0.0) : Vec3(0.0, 0.0, 1.0);
    }
    const double wb = (d22 * r.dot(e1) - d12 * r.dot(e2)) / det;
    const double wc = (d11 * r.dot(e2) - d12 * r.dot(e1)) / det;
    return {1.0 - wb - wc, wb, wc};
}

// Unit normal of the face on x; zero for a face folded flat (the offset then drops out).
Vec3 unitNormal(std::span<const Vec3> x, const Face& f) {
    const Vec3 n = (x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]);
    const double length = n.norm();
    return length > 0.0 ? Vec3(n / length) : Vec3(Vec3::Zero());
}

// One function for the rest and the deformed anchors: at rest both are the same operations on
// the same numbers, so their difference is exactly zero.
Vec3 anchorOf(std::span<const Vec3> x, const Face& f, const Vec3& w, double offset) {
    return w[0] * x[f[0]] + w[1] * x[f[1]] + w[2] * x[f[2]] + offset * unitNormal(x, f);
}

}  // namespace

SurfaceEmbedding embedSurface(TriMesh drawn, const TriMesh& simulation, const std::string& source) {
    if (drawn.faces.empty()) throw InputError(source, 0, "the drawn mesh has no faces");
    for (std::size_t v = 0; v < drawn.vertices.size(); ++v)
        if (!drawn.vertices[v].allFinite()) throw InputError(source, 0, "drawn vertex " + std::to_string(v) + " is not finite");
    if (simulation.faces.empty()) throw InputError(source, 0, "the simulation mesh has no faces");
    std::vector<Aabb> boxes(simulation.faces.size());
    for (std::size_t f = 0; f < boxes.size(); ++f) boxes[f] = faceBox(simulation.vertices, simulation.faces[f]);
    Bvh<Aabb> tree;
    tree.build(boxes);

    SurfaceEmbedding e;
    const std::size_t n = drawn.vertices.size();
    e.simulationVertexCount = simulation.vertices.size();
    e.simulationFaceCount = simulation.faces.size();
    e.triangle.resize(n);
    e.weights.resize(n);
    e.offset.resize(n);
    e.restAnchor.resize(n);
    e.nearestMass.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3& p = drawn.vertices[i];
        const ClosestFace near = closestFace(tree, simulation.vertices, simulation.faces, p);
        const Face& f = simulation.faces[near.face];
        const Vec3 w = barycentric(near.point, simulation.vertices[f[0]], simulation.vertices[f[1]], simulation.vertices[f[2]]);
        e.triangle[i] = near.face;
        e.weights[i] = w;
        e.offset[i] = (p - near.point).dot(unitNormal(simulation.vertices, f));
        e.restAnchor[i] = anchorOf(simulation.vertices, f, w, e.offset[i]);
        Eigen::Index corner = 0;
        w.maxCoeff(&corner);
        e.nearestMass[i] = f[std::size_t(corner)];
        e.maxDistance = std::max(e.maxDistance, std::sqrt(near.squaredDistance));
    }
    e.mesh = std::move(drawn);
    return e;
}

void embeddedPositions(const SurfaceEmbedding& e, std::span<const Face> simulationFaces, std::span<const Vec3> x,
                       std::vector<Vec3>& out) {
    if (x.size() != e.simulationVertexCount || simulationFaces.size() != e.simulationFaceCount)
        throw InputError("surface embedding", 0, "embeddedPositions: " + std::to_string(x.size()) + " positions and " +
                                                     std::to_string(simulationFaces.size()) + " faces for a simulation mesh of " +
                                                     std::to_string(e.simulationVertexCount) + " and " + std::to_string(e.simulationFaceCount));
    out.resize(e.vertexCount());
    for (std::size_t i = 0; i < out.size(); ++i) {
        const Vec3 moved = anchorOf(x, simulationFaces[e.triangle[i]], e.weights[i], e.offset[i]) - e.restAnchor[i];
        // A coordinate that did not move is copied, not added to: p + 0 would turn -0.0 into +0.0.
        for (int c = 0; c < 3; ++c) out[i][c] = moved[c] == 0.0 ? e.mesh.vertices[i][c] : e.mesh.vertices[i][c] + moved[c];
    }
}

}  // namespace flexfit
