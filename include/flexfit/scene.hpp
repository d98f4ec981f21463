// A scene (SPEC 7-8): a world described as data, its parts, assembly rules and scripted
// actions. scene_file.hpp reads it from TOML; scene_run.hpp runs it in a World.
//
// Why TOML (toml++ from Debian's libtomlplusplus-dev): a scene is a handful of flat tables
// ([world], [[part]], [[assembly]], [[action]], [output]) that engineers write by hand. TOML
// has no indentation rules to get wrong and no implicit typing surprises (YAML's "no" is a
// boolean), and toml++ keeps the line of every key, so each error names file, line and key.
//
// Schema (every key is checked: an unknown key is an error, as is a value of the wrong type
// or out of range; see examples/*.toml and the README for a complete table):
//   [world]      time_step, gravity, duration, max_travel_fraction, max_substeps,
//                contact_iterations, contact_slop, contact_damping,
//                exact_test = "triangle" | "sphere", rigid_deformable_query,
//                coherent_collision (true/false)
//   [[part]]     name, mesh (path relative to the scene) or generator ("torus1", "torus2",
//                "heart", "container-mouth", or a table {type = "torus" | "sphere" | "box" |
//                "plate", ...}); with a mesh file: repair, remesh, draw, vertex_order
//                ("locality", the default: masses renumbered for memory locality, while the
//                scene's mass indices, frames and outputs stay in the file's order; or "as_given"),
//                mode, motion, material (preset, {stiffness, damping} or a physical material
//                {youngs_modulus, thickness, density, poisson_ratio, damping_ratio,
//                bending_springs}), vertex_mass (not with a physical material), position,
//                rotation (degrees about x, then y, then z, world axes), density, velocity,
//                angular_velocity (rad/s), thickness, bounding_volume, static_friction,
//                kinetic_friction (default: static_friction), restitution, restoration,
//                constraint_fraction or constraint_rate (1/s), anchor_stiffness, anchor_damping,
//                global_damping, integrator, implicit_iterations, implicit_tolerance, default_level, contact_level, activity_threshold, rest_speed
//   [[assembly]] name, primary, secondary (part names), technique, final_position,
//                final_rotation, snap_duration, distance_tolerance, angle_tolerance (degrees),
//                primary_vector / secondary_vector = {origin, end}, vector_tolerance,
//                area = {shape, position, rotation, half_extents, radius, half_height}
//   [[action]]   time, type = "grab" | "move" | "release" | "push" | "force" | "velocity" | "kick",
//                part, and per type: grab {frequency, stiffness, damping, angular_stiffness,
//                angular_damping}; move {position, rotation, duration}; push {force,
//                duration}; force {force, masses or faces, duration}; velocity {linear,
//                angular}; kick {masses, velocity (each mass's velocity change, at once)}
//   [output]     obj_every, vtk_every, glb_every (s between OBJ, VTK and glTF frames; 0 = none)
//
// Loading builds every mesh and model up front: a scene either loads whole or throws
// InputError, never half-built.
//
// Names (mode, motion, restoration, ...) are those of names.hpp.
#pragma once

#include "flexfit/assembly.hpp"
#include "flexfit/body.hpp"
#include "flexfit/names.hpp"
#include "flexfit/part.hpp"
#include "flexfit/world_settings.hpp"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace flexfit {

struct ScenePart {
    std::string name;
    std::size_t line = 0;     // of its [[part]] table in the scene file
    std::shared_ptr<const PartModel> model;
    PartSettings part;
    BodySettings body;
    Pose pose;
};

struct SceneAction {
    enum class Kind { Grab, Move, Release, Push, Force, Velocity, Kick } kind = Kind::Push;
    std::size_t line = 0;     // in the scene file
    double time = 0.0;        // s
    double duration = 0.0;    // s (move, push, force; 0: one step)
    BodyId body = 0;
    GrabSettings grab;
    Pose target;              // move: the grab target reached at time + duration
    Vec3 force = Vec3::Zero();
    std::vector<Index> masses, faces;
    Vec3 linear = Vec3::Zero(), angular = Vec3::Zero();  // velocity; kick: linear is the masses' change
};
// Its names (names.hpp).
inline constexpr EnumName<SceneAction::Kind> kActionKindNames[] = {
    {SceneAction::Kind::Grab, "grab", "grab"}, {SceneAction::Kind::Move, "move", "move"},
    {SceneAction::Kind::Release, "release", "release"}, {SceneAction::Kind::Push, "push", "push"},
    {SceneAction::Kind::Force, "force", "force"}, {SceneAction::Kind::Velocity, "velocity", "velocity"},
    {SceneAction::Kind::Kick, "kick", "kick"},
};
template <> inline constexpr std::span<const EnumName<SceneAction::Kind>> kEnumNames<SceneAction::Kind> = kActionKindNames;

// Something the reader accepted but the user should change (an old spelling, for now).
struct SceneWarning {
    std::size_t line = 0;
    std::string message;
};

struct Scene {
    std::string source;       // the file, for messages
    std::string linesFile;    // the file the parts' and actions' lines are in, when not `source` (a sweep run's base scene)
    WorldSettings world;
    double duration = 1.0;    // s
    std::vector<ScenePart> parts;
    std::vector<AssemblyRule> assemblies;
    std::vector<SceneAction> actions;  // by time (stable: file order among equal times)
    double objEvery = 0.0;    // s between OBJ frames; 0: none
    double vtkEvery = 0.0;    // s between VTK frames (frame_export.hpp); 0: none
    double glbEvery = 0.0;    // s between glTF binary frames; 0: none
    std::vector<SceneWarning> warnings;

    // The part named `name`, or nullopt.
    std::optional<BodyId> find(std::string_view name) const;
};

// The most steps a run may take: 1e10 steps (hours at the fastest step) come from a time step or
// duration in the wrong unit, not from a run someone waits for.
inline constexpr double kMaxRunSteps = 1e10;

// Why `duration` run at `timeStep` is no run (both finite and > 0): shorter than half a step (no
// step at all), or more than kMaxRunSteps steps. nullopt when it is one.
std::optional<std::string> stepCountProblem(double duration, double timeStep);

}  // namespace flexfit
