// The scripted run of a scene (scene.hpp).
#include "flexfit/scene_run.hpp"

#include <algorithm>

namespace flexfit {

namespace {

// What the world refuses (a part's mass properties, the operator's coupling) named as the scene
// file's line it comes from.
template <class Call>
void atLine(const Scene& scene, std::size_t line, const std::string& what, Call call) {
    try {
        call();
    } catch (const InputError& e) {
        if (scene.source.empty() || e.line() != 0) throw;
        if (scene.linesFile.empty()) throw InputError(scene.source, line, what + ": " + e.problem());
        throw InputError(scene.linesFile, line, what + " (in " + scene.source + "): " + e.problem());
    }
}

}  // namespace

SceneRun::SceneRun(const Scene& scene) : scene_(scene), world_(std::make_unique<World>(scene.world)) {
    for (const ScenePart& p : scene_.parts)
        atLine(scene_, p.line, "part '" + p.name + "'", [&] { world_->add(p.model, p.part, p.body, p.pose); });
    for (const AssemblyRule& r : scene_.assemblies) world_->addAssembly(r);
    world_->prepare();
}

bool SceneRun::finished() const { return world_->time() >= scene_.duration - 0.5 * scene_.world.timeStep; }

// Actions start at the first step whose start time reaches theirs; an action with a duration
// acts in every step that starts in [time, time + duration), and at least once.
void SceneRun::step() {
    const double t = world_->time(), h = scene_.world.timeStep;
    while (next_ < scene_.actions.size() && scene_.actions[next_].time <= t + 0.5 * h) start(scene_.actions[next_++]);
    for (auto it = running_.begin(); it != running_.end();) {
        apply(it->first, it->second, t);
        const double end = it->first.time + it->first.duration;
        it = t + 1.5 * h > end ? running_.erase(it) : it + 1;
    }
    try {
        world_->step();
    } catch (const DivergenceError& e) {  // the world knows ids; the scene knows names
        if (!e.body() || *e.body() >= scene_.parts.size()) throw;
        throw DivergenceError(e.body(), e.time(), e.problem(), scene_.parts[*e.body()].name);
    }
}

void SceneRun::start(const SceneAction& a) {
    using Kind = SceneAction::Kind;
    switch (a.kind) {
        case Kind::Grab:
            atLine(scene_, a.line, "action 'grab' of part '" + scene_.parts[a.body].name + "'", [&] { world_->grab(a.body, a.grab); });
            return;
        case Kind::Release: world_->release(); return;
        case Kind::Velocity: world_->setVelocity(a.body, a.linear, a.angular); return;
        case Kind::Kick:
            for (Index m : a.masses) world_->kickMass(a.body, m, a.linear);
            return;
        case Kind::Move:
            // A snap may have taken the part from the operator: the move is then void.
            if (world_->grabbed() == a.body) running_.emplace_back(a, world_->grabTarget());
            return;
        case Kind::Push:
        case Kind::Force: running_.emplace_back(a, Pose{}); return;
    }
}

void SceneRun::apply(const SceneAction& a, const Pose& moveStart, double t) {
    using Kind = SceneAction::Kind;
    if (a.kind == Kind::Push) world_->applyForce(a.body, a.force);
    if (a.kind == Kind::Force) {
        for (Index m : a.masses) world_->applyMassForce(a.body, m, a.force);
        for (Index f : a.faces) world_->applyFaceForce(a.body, f, a.force);
    }
    if (a.kind == Kind::Move && world_->grabbed() == a.body) {
        const double s = a.duration > 0.0 ? std::min(1.0, (t + scene_.world.timeStep - a.time) / a.duration) : 1.0;
        world_->setGrabTarget(interpolate(moveStart, a.target, s));
    }
}

}  // namespace flexfit
