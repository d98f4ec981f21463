// The point shell's sharp features (collision.hpp): the faces of a rigid part that must be
// tested as faces, because the deformable part's masses alone could let them through.
#include "collision/pair_query.hpp"
#include "collision/triangle_queries.hpp"

#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace flexfit {
using namespace detail;
namespace {

constexpr std::size_t kMaxNeighbourhood = 512;

std::vector<Vec3> unitFaceNormals(const TriMesh& mesh) {
    std::vector<Vec3> normals(mesh.faces.size());
    for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
        const Face& g = mesh.faces[f];
        normals[f] = (mesh.vertices[g[1]] - mesh.vertices[g[0]]).cross(mesh.vertices[g[2]] - mesh.vertices[g[0]]).normalized();
    }
    return normals;
}

// Area-weighted: the cross products summed before normalising.
Vec3 vertexNormal(const TriMesh& mesh, const Topology& topology, Index v) {
    Vec3 sum = Vec3::Zero();
    for (Index f : topology.facesOf(v)) {
        const Face& g = mesh.faces[f];
        sum += (mesh.vertices[g[1]] - mesh.vertices[g[0]]).cross(mesh.vertices[g[2]] - mesh.vertices[g[0]]);
    }
    return sum.normalized();
}

// Whether A's surface near vertex v could cross a plane (B's surface) deeper than the bound
// of collision.hpp while covering no disc of radius rho (`radius`) of it. v would be the
// deepest point along the pressing direction d, so d lies in v's normal cone: v's faces must
// lie within `angle` (theta) of its normal n, which keeps d within theta of n, or v is sharp.
// The faces over the disc of radius R = rho cos(theta) / cos(2 theta) around v in n's plane,
// connected to v through such faces, must turn less than 60 degrees from n (a height field over
// the disc) and lie at most rho tan(theta) behind v along n there; otherwise v is sharp. Then
// a surface point over that disc lies at most rho tan(theta) + R sin(theta) behind v along d:
// a crossing deeper than that is crossing all over it. Seen along d, the patch's rim lies at least
// R cos(theta) - R tan(theta) sin(theta) = rho from v (its height in front of v is at most
// R tan(theta), or v would not be deepest), so the patch covers the disc of radius rho of B's
// plane, which holds a mass.
class SharpnessProbe {
public:
    SharpnessProbe(const TriMesh& mesh, const Topology& topology, const std::vector<Vec3>& normals, double radius, double angle)
        : mesh_(mesh), topology_(topology), normals_(normals), disc_(radius * std::cos(angle) / std::cos(2.0 * angle)),
          tolerance_(radius * std::tan(angle)), cosAngle_(std::cos(angle)), seen_(mesh.vertices.size(), kNoMass),
          faceSeen_(mesh.faces.size(), kNoMass) {}

    bool sharp(Index v) {
        const Vec3 n = vertexNormal(mesh_, topology_, v);
        if (!n.allFinite()) return true;  // the faces around v cancel out: a fold
        for (Index f : topology_.facesOf(v))
            if (!(normals_[f].dot(n) >= cosAngle_)) return true;  // NaN (a sliver) counts as sharp
        queue_.assign(1, v);
        seen_[v] = v;
        for (std::size_t k = 0; k < queue_.size(); ++k) {
            const Index u = queue_[k];
            for (Index f : topology_.facesOf(u)) {
                if (faceSeen_[f] == v) continue;  // met through another of its corners
                faceSeen_[f] = v;
                const std::optional<double> height = heightOverDisc(v, n, mesh_.faces[f]);
                if (!height) continue;
                if (!(normals_[f].dot(n) >= 0.5)) return true;  // steeper than 60 degrees: no height field
                if (*height > tolerance_) return true;
                // A face over the disc leads on to its corners, however far they are (a long
                // thin face can cross the disc with every corner far outside it).
                for (Index w : mesh_.faces[f])
                    if (!visit(v, w)) return true;
            }
        }
        return false;
    }

private:
    // Queues w for v's probe unless it was already; false when the neighbourhood outgrows the
    // cap (far finer than the scale: counted sharp).
    bool visit(Index v, Index w) {
        if (seen_[w] == v) return true;
        if (queue_.size() == kMaxNeighbourhood) return false;
        seen_[w] = v;
        queue_.push_back(w);
        return true;
    }

    // How far behind v (along n) the face reaches over the disc around v in n's plane: at most
    // its deepest corner, and at most its plane's height at v plus its slope times the disc's
    // radius. Nothing for a face whose projection misses the disc.
    std::optional<double> heightOverDisc(Index v, const Vec3& n, const Face& face) const {
        std::array<Vec3, 3> lateral;
        std::array<double, 3> height;
        for (int i = 0; i < 3; ++i) {
            const Vec3 d = mesh_.vertices[face[i]] - mesh_.vertices[v];
            height[i] = -d.dot(n);
            lateral[i] = d + height[i] * n;
        }
        const Vec3 closest = closestPointOnTriangle(Vec3::Zero(), {lateral[0], lateral[1], lateral[2]});
        if (closest.norm() > disc_) return std::nullopt;
        double bound = std::max({height[0], height[1], height[2]});
        // The plane's height as a linear function of the lateral position.
        const Vec3 e1 = lateral[1] - lateral[0], e2 = lateral[2] - lateral[0];
        const Vec3 normal2d = e1.cross(e2);
        const double area2 = normal2d.norm();
        if (area2 > 1e-300) {
            // grad h solves grad.e1 = h1 - h0, grad.e2 = h2 - h0 within the plane.
            const Vec3 unit = normal2d / area2;
            const Vec3 gradient = ((height[1] - height[0]) * e2.cross(unit) + (height[2] - height[0]) * unit.cross(e1)) / area2;
            const double atV = height[0] - gradient.dot(lateral[0]);
            bound = std::min(bound, atV + gradient.norm() * disc_);
        }
        return bound;
    }

    const TriMesh& mesh_;
    const Topology& topology_;
    const std::vector<Vec3>& normals_;
    double disc_, tolerance_, cosAngle_;
    std::vector<Index> seen_;      // the vertex whose probe last reached each
    std::vector<Index> faceSeen_;  // the vertex whose probe last tested each face
    std::vector<Index> queue_;
};

}  // namespace

SharpFeatures findSharpFeatures(const Part& rigid, double radius, ExactTest test, double angle) {
    if (!(radius >= 0.0) || !std::isfinite(radius) || !(angle > 0.0) || !(angle < M_PI / 4.0))
        throw std::invalid_argument("findSharpFeatures: radius must be finite and >= 0, angle in (0, pi/4)");
    const TriMesh& mesh = rigid.model().mesh;
    const Topology& topology = rigid.model().topology;
    const std::vector<Vec3> normals = unitFaceNormals(mesh);
    SharpnessProbe probe(mesh, topology, normals, radius, angle);
    std::vector<bool> sharpFace(mesh.faces.size(), false);
    for (Index v = 0; v < mesh.vertices.size(); ++v) {
        if (topology.facesOf(v).empty() || !probe.sharp(v)) continue;
        for (Index f : topology.facesOf(v)) sharpFace[f] = true;
    }
    SharpFeatures features;
    features.radius = radius;
    features.angle = angle;
    features.test = test;
    std::vector<Aabb> boxes;
    for (Index f = 0; f < mesh.faces.size(); ++f) {
        if (!sharpFace[f]) continue;
        features.faces.push_back(f);
        // The leaves A's own hierarchy would have for the test (the face sphere reaches beyond
        // the triangle).
        boxes.push_back(test == ExactTest::SphereTriangle ? faceSphereBox(mesh.vertices, mesh.faces[f]) : faceBox(mesh.vertices, mesh.faces[f]));
    }
    features.tree.build(boxes);
    return features;
}

double restResolution(const Part& part) {
    const TriMesh& mesh = part.model().mesh;
    double longest2 = 0.0;
    for (const Face& f : mesh.faces)
        for (int i = 0; i < 3; ++i) longest2 = std::max(longest2, (mesh.vertices[f[i]] - mesh.vertices[f[(i + 1) % 3]]).squaredNorm());
    return std::sqrt(longest2 / 3.0);
}

void querySharpFeatures(std::uint32_t idA, const Part& a, const PartCollider& colliderA, const SharpFeatures& features,
                        std::uint32_t idB, const Part& b, const PartCollider& colliderB, ExactTest test,
                        std::vector<Contact>& contacts, QueryStats& stats) {
    if (a.deforms()) throw std::invalid_argument("querySharpFeatures: part A must be rigid");
    if (features.empty()) return;
    if (features.test != test) throw std::invalid_argument("querySharpFeatures: the features were found for another exact test");
    requireBuiltFor(colliderA, colliderB, test);
    const RelativePose bInA = relativePose(a, b);
    const std::size_t first = contacts.size();
    LeafPairTester tester(idA, a, colliderA, idB, b, colliderB, test, bInA, contacts, stats);
    auto leafPair = [&](Index k, Index fb) { tester(features.faces[k], fb); };
    auto prune = [&](Index k, const auto& volumeB) { return tester.prunes(features.faces[k], volumeB); };
    if (const Bvh<Sphere>* spheres = colliderB.spheres())
        traverse(features.tree, *spheres, bInA, stats, leafPair, prune, 0.0);
    else
        traverse(features.tree, *colliderB.boxes(), bInA, stats, leafPair, prune, 0.0);
    sortContacts(contacts, first);
}

}  // namespace flexfit
