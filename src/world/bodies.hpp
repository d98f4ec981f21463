// Internal to src/world: the one registry of a world's bodies. Body `id` is parts[id] with
// rigid[id]; the collision world registers the same ids (collision_world.hpp).
#pragma once

#include "flexfit/body.hpp"
#include "flexfit/collision_world.hpp"
#include "flexfit/part.hpp"

#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

namespace flexfit::detail {

struct Bodies {
    std::vector<std::unique_ptr<Part>> parts;           // (nbody) owned here, stable addresses
    std::vector<RigidBody> rigid;                       // (nbody)
    std::vector<std::optional<Pose>> kinematicTargets;  // (nbody) pose to reach in the next step
    // (nbody + 1) the world's mass numbering: body b's masses are massAdr[b] .. massAdr[b+1]-1,
    // so per-mass scratch of the contact response spans every body.
    std::vector<Index> massAdr{0};
    // Bumped whenever a body is added or a stage other than rigid motion moves one (a snap):
    // contacts the rigid motion kept from an earlier step are stale then.
    std::uint64_t poseEpoch = 0;

    std::size_t size() const { return parts.size(); }
    bool dynamic(BodyId id) const { return rigid[id].motion == MotionType::Dynamic; }
    Index massCount() const { return massAdr.back(); }
    Index worldMass(BodyId body, Index mass) const { return massAdr[body] + mass; }

    // Registers a body; does not throw once reserve(size() + 1) has been called.
    BodyId add(std::unique_ptr<Part> part, const RigidBody& body);
    void reserve(std::size_t count);  // grown geometrically (reserveGrowing)
    // World position of a body's centre of mass.
    Vec3 centreOfMass(BodyId id) const { return parts[id]->pose().apply(rigid[id].centreOfMass); }
    // The thinnest body's thickness (the no-tunnelling bound's scale). Flat parts (thickness 0:
    // a quad floor) do not count: a body moving less than its own thickness per sub-step
    // cannot cross them unseen. Infinity when every part is flat. Kept by add(): thicknesses
    // are fixed when a body is added.
    double minimumThickness() const { return thinnest_; }
    // The body of that thickness (the first added of it), when any is not flat.
    std::optional<BodyId> thinnestBody() const { return thinnestBody_; }

private:
    double thinnest_ = std::numeric_limits<double>::infinity();
    std::optional<BodyId> thinnestBody_;
};

// The rotation as axis and angle in (-pi, pi]: the short way round.
inline Eigen::AngleAxisd shortestTurn(const Eigen::Quaterniond& q) {
    Eigen::AngleAxisd turn(q);
    if (turn.angle() > M_PI) turn.angle() -= 2.0 * M_PI;
    return turn;
}

// After a collision query: the parts whose hierarchy it refitted forget the changes it used.
void clearRefittedChanges(const CollisionWorld& collision, Bodies& bodies);

}  // namespace flexfit::detail
