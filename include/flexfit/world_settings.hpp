// What a world is made with: its step, the no-tunnelling bound, its collision queries, and the
// operator's coupling (world.hpp says what each does). Plain settings, so that a scene
// description (scene.hpp) can hold them without the world.
#pragma once

#include "flexfit/collision_world.hpp"

#include <cmath>
#include <string>

namespace flexfit {

struct WorldSettings {
    double timeStep = 1e-3;
    Vec3 gravity = Vec3(0.0, -9.81, 0.0);
    CollisionSettings collision;
    double maxTravelFraction = 0.25;  // of the thinnest body, per sub-step
    int maxSubsteps = 4096;
    int contactIterations = 4;        // projection passes per sub-step
};

// Throws InputError (source "world") for a time step that is not finite and positive,
// non-finite gravity, a travel fraction outside (0, 1], or sub-steps or iterations below 1.
inline void validateSettings(const WorldSettings& settings) {
    const std::string source = "world";
    if (!std::isfinite(settings.timeStep) || settings.timeStep <= 0.0) throw InputError(source, 0, "time step must be finite and > 0");
    if (!settings.gravity.allFinite()) throw InputError(source, 0, "gravity must be finite");
    if (!(settings.maxTravelFraction > 0.0 && settings.maxTravelFraction <= 1.0))
        throw InputError(source, 0, "max travel fraction must be in (0, 1]");
    if (settings.maxSubsteps < 1 || settings.contactIterations < 1)
        throw InputError(source, 0, "max substeps and contact iterations must be >= 1");
}

// The operator's spring-damper coupling. Zero stiffness: the body's mass (and smallest
// principal inertia) times w^2, w = min(2 pi frequency, 0.4 / dt), so the explicit coupling is
// stable at any time step; negative damping: critical (2 sqrt(k m)).
struct GrabSettings {
    double frequency = 10.0;          // Hz, for the default stiffnesses
    double stiffness = 0.0;           // N/m
    double damping = -1.0;            // N s/m
    double angularStiffness = 0.0;    // N m/rad
    double angularDamping = -1.0;     // N m s/rad
};

}  // namespace flexfit
