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

// The corners left, as a ring of positions into the polygon, each with whether it was an ear
// when last checked. Clipping an ear only removes a corner, so an ear elsewhere stays one
// (its triangle is the same and nothing can newly block it); only the two neighbours of a clipped
// corner are checked again. A corner can become an ear unnoticed (its blocker clipped), so a lap
// without an ear checks every corner again before giving up. Linear in the corners per check:
// O(n^2) on polygons whose ears are few (a zigzag band: its two ends), where restarting the scan
// at the first corner after each clip was O(n^3) (10,000 corners: a minute).
class EarRing {
public:
    EarRing(std::span<const Index> corners, const std::vector<Eigen::Vector2d>& p)
        : corners_(corners), p_(p), prev_(corners.size()), next_(corners.size()), ear_(corners.size()), left_(corners.size()) {
        for (std::size_t i = 0; i < left_; ++i) {
            prev_[i] = (i + left_ - 1) % left_;
            next_[i] = (i + 1) % left_;
        }
        checkAll(0);
    }

    // Clips ears until a triangle is left; false when none is left to clip.
    bool clip(std::vector<Face>& out) {
        std::size_t i = 0, sinceClip = 0;
        bool fresh = true;  // every corner checked since the last clip
        while (left_ > 3) {
            if (ear_[i]) {
                const std::size_t a = prev_[i], c = next_[i];
                out.push_back({corners_[a], corners_[i], corners_[c]});
                next_[a] = c;
                prev_[c] = a;
                --left_;
                ear_[a] = isEar(a);
                ear_[c] = isEar(c);
                i = c;
                sinceClip = 0;
                fresh = false;
                continue;
            }
            i = next_[i];
            if (++sinceClip < left_) continue;
            if (fresh) return false;
            checkAll(i);
            sinceClip = 0;
            fresh = true;
        }
        out.push_back({corners_[prev_[i]], corners_[i], corners_[next_[i]]});
        return true;
    }

private:
    // Every corner left, around the ring from `start` (one of them).
    void checkAll(std::size_t start) {
        for (std::size_t i = start, k = 0; k < left_; i = next_[i], ++k) ear_[i] = isEar(i);
    }

    // Convex, and no other corner in or on its triangle (a corner met twice, a bridged hole,
    // does not block its own ear).
    bool isEar(std::size_t b) const {
        const std::size_t a = prev_[b], c = next_[b];
        if (turn(p_[a], p_[b], p_[c]) <= 0.0) return false;  // reflex or flat
        for (std::size_t j = next_[c]; j != a; j = next_[j]) {
            const Index v = corners_[j];
            if (v != corners_[a] && v != corners_[b] && v != corners_[c] && inTriangle(p_[j], p_[a], p_[b], p_[c])) return false;
        }
        return true;
    }

    std::span<const Index> corners_;
    const std::vector<Eigen::Vector2d>& p_;
    std::vector<std::size_t> prev_, next_;
    std::vector<char> ear_;
    std::size_t left_;
};

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
    if (EarRing(corners, p).clip(out)) return true;
    out.resize(before);
    fan();
    return false;
}


}  // namespace flexfit::detail
