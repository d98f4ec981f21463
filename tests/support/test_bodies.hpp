// Bodies the world tests share: rigid parts, dynamic bodies, and a ball over the thesis's
// container mouth (outer diameter 25, opening 15).
#pragma once

#include "flexfit/world.hpp"
#include "flexfit/generators.hpp"

#include <algorithm>
#include <vector>

namespace flexfit::testing {

inline PartSettings rigidPart() {
    PartSettings s;
    s.mode = PartMode::Rigid;
    return s;
}

inline BodySettings dynamicBody(Vec3 velocity = Vec3::Zero()) {
    BodySettings b;
    b.motion = MotionType::Dynamic;
    b.linearVelocity = velocity;
    return b;
}

inline Pose at(const Vec3& p) { return Pose{Eigen::Quaterniond::Identity(), p}; }
// Turned by `angle` radians about `axis`.
inline Pose at(const Vec3& p, double angle, const Vec3& axis = Vec3::UnitY()) {
    return Pose{Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis)), p};
}

struct BallTorus {
    World world;
    BodyId torus = 0, ball = 0;
    BallTorus(double diameter, double dt, Vec3 velocity, double startHeight = 12.0)
        : world(WorldSettings{dt, Vec3(0, -9.81, 0), {}, 0.25, 4096, 4}) {
        torus = world.add(buildPartModel(makeContainerMouth()), rigidPart(), BodySettings{}, Pose{});
        ball = world.add(buildPartModel(makeIcoSphere(diameter / 2, 3)), rigidPart(), dynamicBody(velocity), at(Vec3(0, startHeight, 0)));
    }
    double ballHeight() const { return world.centreOfMass(ball).y(); }
};

// How far some bodies stray from the poses they had when it was made: the largest translation
// and rotation (radians) seen by record().
struct PoseDrift {
    std::vector<BodyId> bodies;
    std::vector<Pose> rest;
    double translation = 0.0, rotation = 0.0;
    PoseDrift(const World& world, std::vector<BodyId> ids) : bodies(std::move(ids)) {
        for (BodyId id : bodies) rest.push_back(world.part(id).pose());
    }
    void record(const World& world) {
        for (std::size_t k = 0; k < bodies.size(); ++k) {
            const Pose& pose = world.part(bodies[k]).pose();
            translation = std::max(translation, (pose.translation - rest[k].translation).norm());
            rotation = std::max(rotation, pose.rotation.angularDistance(rest[k].rotation));
        }
    }
};

}  // namespace flexfit::testing
