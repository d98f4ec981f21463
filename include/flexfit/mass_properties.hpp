// Volume, centre of mass and inertia tensor of a closed triangle mesh of uniform density.
//
// Exact for the polyhedron (divergence theorem over the faces; D. Eberly, "Polyhedral Mass
// Properties (Revisited)"): no voxels, no sampling. The mesh must be closed and oriented
// outwards (every Flexfit generator is; validateMesh reports open meshes).
#pragma once

#include "flexfit/mesh.hpp"

namespace flexfit {

struct MassProperties {
    double volume = 0.0;
    Vec3 centroid = Vec3::Zero();                        // centre of mass, mesh frame
    Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();   // about the centroid, for density 1
};

// Throws InputError (naming `source`) when the enclosed volume is not positive (open,
// inside-out or flat mesh).
MassProperties computeMassProperties(const TriMesh& mesh, const std::string& source = "mesh");

}  // namespace flexfit
