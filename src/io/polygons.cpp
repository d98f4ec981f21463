// Polygons split into triangles (polygons.hpp).
#include "polygons.hpp"

#include <Eigen/Core>

namespace flexfit::detail {
namespace {

// The polygon in 2D: its plane's dominant axis dropped, oriented so that its own turning
// direction is counter-clockwise.
std::vector<Eigen::Vector2d> projected(const std::vector<Vec3>& vertices, std::span<const Index> corners) {
    Vec3 normal = Vec3::Zero();  // Newell's
    for (std::size_t i = 0; i < corners.size(); ++i) normal += vertices[corners[i]].cross(vertices[corners[(i + 1) % corners.size()]]);
    int axis = 0;
    normal.cwiseAbs().maxCoeff(&axis);
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    const double flip = normal[axis] < 0.0 ? -1.0 : 1.0;
    std::vector<Eigen::Vector2d> out;
    for (Index v : corners) out.emplace_back(vertices[v][a], flip * vertices[v][b]);
    return out;
}

double turn(const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    const Eigen::Vector2d u = q - p, w = r - q;
    return u.x() * w.y() - u.y() * w.x();
}

bool inTriangle(const Eigen::Vector2d& x, const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    return turn(p, q, x) >= 0.0 && turn(q, r, x) >= 0.0 && turn(r, p, x) >= 0.0;
}

// Ear clipping; false when no ear is left (a self-intersecting or degenerate polygon).
bool clipEars(std::span<const Index> corners, const std::vector<Eigen::Vector2d>& p, std::vector<Face>& out) {
    std::vector<std::size_t> left(corners.size());
    for (std::size_t i = 0; i < left.size(); ++i) left[i] = i;
    while (left.size() > 3) {
        const std::size_t m = left.size();
        bool clipped = false;
        for (std::size_t i = 0; i < m && !clipped; ++i) {
            const std::size_t a = left[(i + m - 1) % m], b = left[i], c = left[(i + 1) % m];
            if (turn(p[a], p[b], p[c]) <= 0.0) continue;  // reflex or flat: not an ear
            bool blocked = false;
            for (std::size_t j : left) {  // a corner met twice (a bridged hole) does not block its own ear
                const Index v = corners[j];
                if (v != corners[a] && v != corners[b] && v != corners[c] && inTriangle(p[j], p[a], p[b], p[c])) blocked = true;
            }
            if (blocked) continue;
            out.push_back({corners[a], corners[b], corners[c]});
            left.erase(left.begin() + std::ptrdiff_t(i));
            clipped = true;
        }
        if (!clipped) return false;
    }
    out.push_back({corners[left[0]], corners[left[1]], corners[left[2]]});
    return true;
}

}  // namespace

bool triangulatePolygon(const std::vector<Vec3>& vertices, std::span<const Index> corners, std::vector<Face>& out) {
    const auto fan = [&] {
        for (std::size_t k = 1; k + 1 < corners.size(); ++k) out.push_back({corners[0], corners[k], corners[k + 1]});
        return true;
    };
    if (corners.size() == 3) return fan();
    const std::vector<Eigen::Vector2d> p = projected(vertices, corners);
    bool convex = true;
    // Strictly convex: a corner on a straight edge (a T-junction) would give the fan a flat triangle.
    for (std::size_t i = 0; i < p.size() && convex; ++i) convex = turn(p[i], p[(i + 1) % p.size()], p[(i + 2) % p.size()]) > 0.0;
    if (convex) return fan();
    const std::size_t before = out.size();
    if (clipEars(corners, p, out)) return true;
    out.resize(before);
    fan();
    return false;
}


}  // namespace flexfit::detail
