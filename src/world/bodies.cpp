// Bodies and their mass properties (body.hpp, bodies.hpp).
#include "bodies.hpp"

#include "core/reserve.hpp"
#include "flexfit/mass_properties.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace flexfit {
RigidBody makeRigidBody(const PartModel& model, const BodySettings& settings) {
    const std::string source = "world";
    requireNamedValue<InputError>(settings.motion, source, "body motion");
    requireNamedValue<InputError>(settings.boundingVolume, source, "bounding volume");
    if (!(settings.density > 0.0) || !std::isfinite(settings.density))
        throw InputError(source, 0, "body density must be finite and > 0");
    if (!(settings.thickness >= 0.0) || !std::isfinite(settings.thickness) || !settings.linearVelocity.allFinite() ||
        !settings.angularVelocity.allFinite())
        throw InputError(source, 0, "body thickness and velocities must be finite");
    if (!(settings.kineticFriction >= 0.0) || !(settings.staticFriction >= settings.kineticFriction) || !std::isfinite(settings.staticFriction))
        throw InputError(source, 0, "friction must be finite and >= 0, with kinetic friction <= static friction");
    if (!(settings.restitution >= 0.0 && settings.restitution <= 1.0)) throw InputError(source, 0, "restitution must be in [0, 1]");
    RigidBody body;
    body.motion = settings.motion;
    const Eigen::AlignedBox3d box = boundingBox(model.mesh);
    body.thickness = settings.thickness > 0.0 ? settings.thickness : 0.5 * box.sizes().minCoeff();
    body.centreOfMass = box.center();
    if (settings.motion == MotionType::Dynamic) {
        if (const SolidDefect defect = solidDefect(model.mesh.vertices, model.mesh.faces, model.topology); defect != SolidDefect::None)
            throw InputError(source, 0, "a dynamic body needs a closed, consistently oriented mesh (its mass comes from the volume): '" +
                                            model.name + "' " +
                                            (defect == SolidDefect::Open           ? "is open or not manifold (an edge not on two faces)"
                                             : defect == SolidDefect::Inconsistent ? "has faces wound inconsistently"
                                                                                   : "is inside out (negative volume)"));
        const MassProperties mp = computeMassProperties(model.mesh, model.name);
        body.mass = settings.density * mp.volume;
        body.inverseMass = 1.0 / body.mass;
        body.centreOfMass = mp.centroid;
        body.inverseInertia = (settings.density * mp.inertia).inverse();
        // A density far beyond the mesh's scale overflows the mass or underflows it to 0 (and
        // the step would turn every contact into NaN): refused here, not found diverged later.
        if (!(std::isfinite(body.mass) && body.mass > 0.0 && std::isfinite(body.inverseMass) && body.inverseInertia.allFinite())) {
            std::ostringstream text;
            text << "density " << settings.density << " x the volume " << mp.volume << " of '" << model.name
                 << "' gives no finite, positive mass and inertia: a density far beyond the mesh's scale";
            throw InputError(source, 0, text.str());
        }
    }
    for (const Vec3& p : model.restPositions) body.boundingRadius = std::max(body.boundingRadius, (p - body.centreOfMass).norm());
    body.linearVelocity = settings.linearVelocity;
    body.angularVelocity = settings.angularVelocity;
    body.staticFriction = settings.staticFriction;
    body.kineticFriction = settings.kineticFriction;
    body.restitution = settings.restitution;
    return body;
}

namespace detail {

BodyId Bodies::add(std::unique_ptr<Part> part, const RigidBody& body) {
    massAdr.push_back(massAdr.back() + Index(part->model().massCount()));
    parts.push_back(std::move(part));
    rigid.push_back(body);
    kinematicTargets.emplace_back();
    if (body.thickness > 0.0 && body.thickness < thinnest_) {
        thinnest_ = body.thickness;
        thinnestBody_ = BodyId(parts.size() - 1);
    }
    ++poseEpoch;
    return BodyId(parts.size() - 1);
}

void Bodies::reserve(std::size_t count) {
    reserveGrowing(parts, count);
    reserveGrowing(rigid, count);
    reserveGrowing(kinematicTargets, count);
    reserveGrowing(massAdr, count + 1);
}

void clearRefittedChanges(const CollisionWorld& collision, Bodies& bodies) {
    for (BodyId id : collision.refittedBodies()) bodies.parts[id]->clearChangedMasses();
}

}  // namespace detail
}  // namespace flexfit
