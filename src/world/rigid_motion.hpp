// Internal to src/world: the rigid motion stage (world.hpp, "Contacts"). Dynamic bodies take
// their forces, torques and gravity (semi-implicit Euler, once per step); kinematic bodies
// with a target this step take the velocity that reaches it. Then every moving body advances
// in the same sub-steps, short enough that no point of any travels more than
// maxTravelFraction of the thinnest body per sub-step. Each sub-step:
//   1. the dynamic bodies' contacts with parts that do not deform (NarrowPhase);
//   2. the contact solver's first pass, which also separates penetrating points (ContactSolver);
//   3. every moving body advances by conservative advancement: all go to the end of their
//      move, then each in turn (kinematic ones first) cuts its own move back to the last
//      fraction (bisection) at which no pair with a part that stops it is deeper than the
//      contact slop, or than that pair was at the sub-step's start. Contact normals and depths
//      come from shallow configurations, so no load, speed or time step gets a body through a
//      rigid part; bodies moving together do not hold each other back;
//   4. the solver's relax pass and restitution;
//   5. a kinematic body that has sub-steps left presses the deformable parts it meets, so it
//      deforms them along its way instead of jumping through.
// A kinematic body is not stopped by dynamic bodies (it pushes them) but is by static and
// kinematic rigid parts; it reaches its target exactly unless one stopped it.
#pragma once

#include "bodies.hpp"
#include "contact_response.hpp"
#include "contact_solver.hpp"
#include "flexfit/collision_world.hpp"
#include "flexfit/world_settings.hpp"
#include "step_profiler.hpp"

namespace flexfit::detail {

// Scratch of the stage, kept between steps.
struct RigidMotionScratch {
    ContactSolver solver;
    std::vector<BodyId> moving;         // kinematic bodies with a target, then dynamic ones
    // Each moving body's stopping pairs and their deepest contact at the sub-step's start: body
    // id's are startDepths[startOffset[id] .. + startCount[id]).
    std::vector<std::pair<BodyId, double>> startDepths;
    std::vector<std::size_t> startOffset, startCount;  // (nbody)
    std::vector<double> loadSpeed;      // (nbody) speed the loads and gravity give a dynamic body in a step
    double gravitySpeed = 0.0;          // gravity's alone, this step
    std::vector<Pose> subStart;         // (nbody) pose at the sub-step's start
    std::vector<Pose> stepStart;        // (nbody) pose at the step's start (kinematic bodies)
    std::vector<char> stopped;          // (nbody) a sub-step of this step was cut short
    std::vector<BodyId> cut;            // this sub-step's movers whose move is cut short so far
    std::vector<Contact> cached;        // contacts of `cachedBody` at its current pose
    std::vector<Contact> unseen;        // a body's contacts not added by a lower id's query
    std::optional<BodyId> cachedBody;
    std::uint64_t cacheEpoch = 0;       // Bodies::poseEpoch when the cache was kept
    std::uint64_t queries = 0;          // this step's, for the profile
    CollisionWorld::KnownContacts known;  // knownContacts()'s answer
};

// The last mover's contacts with rigid parts, when they still hold at the current poses (for the
// world's narrow phase, which then does not query those pairs again); null otherwise.
const CollisionWorld::KnownContacts* knownContacts(RigidMotionScratch& scratch, const Bodies& bodies);

// Charges its own work to Stage::RigidMotion, queries to NarrowPhase, the solver to
// ContactSolver and kinematic pushes to ContactResponse. Adds the sub-steps to profile.substeps.
void moveRigidBodies(const StepContext& step, const WorldSettings& settings, Bodies& bodies, CollisionWorld& collision,
                     ContactResponse& response, RigidMotionScratch& scratch, StepProfiler& profiler, Profile& profile);

}  // namespace flexfit::detail
