// The naive reference (naive_msd.hpp) built from a flexfit mesh: the only place the two meet,
// as plain coordinate and index arrays, so the reference itself stays free of library code.
#pragma once

#include "flexfit/mesh.hpp"
#include "naive_msd.hpp"

#include <memory>
#include <vector>

namespace naive {

inline std::unique_ptr<Model> modelFromMesh(const flexfit::TriMesh& mesh, double massValue, double k, double b) {
    std::vector<double> vertices;
    std::vector<unsigned> faces;
    for (const flexfit::Vec3& v : mesh.vertices) vertices.insert(vertices.end(), {v.x(), v.y(), v.z()});
    for (const flexfit::Face& f : mesh.faces) faces.insert(faces.end(), {f[0], f[1], f[2]});
    return std::make_unique<Model>(vertices, faces, massValue, k, b);
}

}  // namespace naive
