// A scene's world, driven by its scripted actions: the same run for `flexfit run`, the
// experiments and the viewer.
#pragma once

#include "flexfit/scene.hpp"
#include "flexfit/world.hpp"

#include <memory>
#include <utility>
#include <vector>

namespace flexfit {

class SceneRun {
public:
    explicit SceneRun(const Scene& scene);
    World& world() { return *world_; }
    const World& world() const { return *world_; }
    const Scene& scene() const { return scene_; }
    // Applies the actions due in this step, then steps the world. A DivergenceError from the
    // world (world.hpp) comes out with the diverging part's name.
    void step();
    bool finished() const;
    // Operator actions that the scene did not script (the viewer's mouse) go to world() directly.

private:
    void start(const SceneAction& action);
    void apply(const SceneAction& action, const Pose& moveStart, double t);
    Scene scene_;
    std::unique_ptr<World> world_;
    std::size_t next_ = 0;                               // first action not yet started
    std::vector<std::pair<SceneAction, Pose>> running_;  // actions with a duration, and a move's start target
};

}  // namespace flexfit
