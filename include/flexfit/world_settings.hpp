// What a world is made with: its step, the no-tunnelling bound, its collision queries, and the
// operator's coupling (world.hpp says what each does). Plain settings, so that a scene
// description (scene.hpp) can hold them without the world.
#pragma once

#include "flexfit/collision_world.hpp"
#include "flexfit/simulation.hpp"

#include <cmath>
#include <string>

namespace flexfit {

struct WorldSettings {
    double timeStep = 1e-3;
    Vec3 gravity = Vec3(0.0, -9.81, 0.0);
    CollisionSettings collision;
    double maxTravelFraction = 0.25;  // of the thinnest body, per sub-step
    int maxSubsteps = 4096;
    int contactIterations = 8;        // contact solver iterations per sub-step (velocity passes)
    // The deepest a sub-step may take a body into a part that does not deform, as a fraction of
    // the thinnest body: a move that would go deeper is cut short (conservative advancement).
    double contactSlop = 0.01;
    // Damping of the reaction a deformable part opposes to a dynamic body, as a ratio of the
    // critical damping of the body's mass on the contact's stiffness (contact_response).
    double contactDamping = 1.0;
};

// The most sub-steps and contact iterations a step may take (a step of 2^31 solver passes never
// ends); scenes read the same bounds.
inline constexpr int kMostSubsteps = 1 << 20, kMostContactIterations = 1000;

// Throws InputError (source "world") for a time step that is not finite, positive and normal,
// non-finite gravity, a travel fraction or contact slop outside (0, 1], sub-steps or
// iterations outside [1, kMostSubsteps] / [1, kMostContactIterations], a negative or
// non-finite contact damping, or a collision enum holding none of its values.
inline void validateSettings(const WorldSettings& settings) {
    const std::string source = "world";
    if (const std::optional<std::string> problem = timeStepProblem(settings.timeStep)) throw InputError(source, 0, *problem);
    if (!settings.gravity.allFinite()) throw InputError(source, 0, "gravity must be finite");
    requireNamedValue<InputError>(settings.collision.exactTest, source, "exact test");
    requireNamedValue<InputError>(settings.collision.broadPhase, source, "broad-phase update");
    requireNamedValue<InputError>(settings.collision.rigidDeformable, source, "rigid-deformable query");
    if (!(settings.maxTravelFraction > 0.0 && settings.maxTravelFraction <= 1.0))
        throw InputError(source, 0, "max travel fraction must be in (0, 1]");
    if (settings.maxSubsteps < 1 || settings.maxSubsteps > kMostSubsteps || settings.contactIterations < 1 ||
        settings.contactIterations > kMostContactIterations)
        throw InputError(source, 0, "max substeps must be in [1, " + std::to_string(kMostSubsteps) + "] and contact iterations in [1, " +
                                        std::to_string(kMostContactIterations) + "]");
    if (!(settings.contactSlop > 0.0 && settings.contactSlop <= 1.0)) throw InputError(source, 0, "contact slop must be in (0, 1]");
    if (!(settings.contactDamping >= 0.0) || !std::isfinite(settings.contactDamping))
        throw InputError(source, 0, "contact damping must be finite and >= 0");
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
