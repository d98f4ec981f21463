#include "flexfit/mass_properties.hpp"

#include <array>
#include <cmath>

namespace flexfit {
namespace {

struct Subexpressions {
    double f1, f2, f3, g0, g1, g2;
};

Subexpressions subexpressions(double w0, double w1, double w2) {
    const double temp0 = w0 + w1, temp1 = w0 * w0, temp2 = temp1 + w1 * temp0;
    Subexpressions s;
    s.f1 = temp0 + w2;
    s.f2 = temp2 + w2 * s.f1;
    s.f3 = w0 * temp1 + w1 * temp2 + w2 * s.f2;
    s.g0 = s.f2 + w0 * (s.f1 + w0);
    s.g1 = s.f2 + w1 * (s.f1 + w1);
    s.g2 = s.f2 + w2 * (s.f1 + w2);
    return s;
}

}  // namespace

MassProperties computeMassProperties(const TriMesh& mesh, const std::string& source) {
    // Integrals of 1, x, y, z, x^2, y^2, z^2, xy, yz, zx over the enclosed volume.
    std::array<double, 10> integral{};
    for (const Face& face : mesh.faces) {
        const Vec3& p0 = mesh.vertices[face[0]];
        const Vec3& p1 = mesh.vertices[face[1]];
        const Vec3& p2 = mesh.vertices[face[2]];
        const Vec3 d = (p1 - p0).cross(p2 - p0);  // twice the area times the outward normal
        const Subexpressions x = subexpressions(p0.x(), p1.x(), p2.x());
        const Subexpressions y = subexpressions(p0.y(), p1.y(), p2.y());
        const Subexpressions z = subexpressions(p0.z(), p1.z(), p2.z());
        integral[0] += d.x() * x.f1;
        integral[1] += d.x() * x.f2;
        integral[2] += d.y() * y.f2;
        integral[3] += d.z() * z.f2;
        integral[4] += d.x() * x.f3;
        integral[5] += d.y() * y.f3;
        integral[6] += d.z() * z.f3;
        integral[7] += d.x() * (p0.y() * x.g0 + p1.y() * x.g1 + p2.y() * x.g2);
        integral[8] += d.y() * (p0.z() * y.g0 + p1.z() * y.g1 + p2.z() * y.g2);
        integral[9] += d.z() * (p0.x() * z.g0 + p1.x() * z.g1 + p2.x() * z.g2);
    }
    constexpr std::array<double, 10> scale{1.0 / 6, 1.0 / 24, 1.0 / 24, 1.0 / 24, 1.0 / 60,
                                           1.0 / 60, 1.0 / 60, 1.0 / 120, 1.0 / 120, 1.0 / 120};
    for (std::size_t i = 0; i < integral.size(); ++i) integral[i] *= scale[i];

    MassProperties out;
    out.volume = integral[0];
    if (!(out.volume > 0.0) || !std::isfinite(out.volume))
        throw InputError(source, 0, "the mesh encloses no positive volume (open, inside-out or flat): no mass properties");
    const Vec3 c(integral[1] / out.volume, integral[2] / out.volume, integral[3] / out.volume);
    out.centroid = c;
    const double m = out.volume;
    Eigen::Matrix3d& I = out.inertia;
    I(0, 0) = integral[5] + integral[6] - m * (c.y() * c.y() + c.z() * c.z());
    I(1, 1) = integral[4] + integral[6] - m * (c.z() * c.z() + c.x() * c.x());
    I(2, 2) = integral[4] + integral[5] - m * (c.x() * c.x() + c.y() * c.y());
    I(0, 1) = I(1, 0) = -(integral[7] - m * c.x() * c.y());
    I(1, 2) = I(2, 1) = -(integral[8] - m * c.y() * c.z());
    I(0, 2) = I(2, 0) = -(integral[9] - m * c.z() * c.x());
    return out;
}

}  // namespace flexfit
