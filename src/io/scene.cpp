// Scene data (scene.hpp).
#include "flexfit/scene.hpp"

#include <sstream>

namespace flexfit {

std::optional<BodyId> Scene::find(std::string_view name) const {
    for (BodyId i = 0; i < parts.size(); ++i)
        if (parts[i].name == name) return i;
    return std::nullopt;
}

std::optional<std::string> stepCountProblem(double duration, double timeStep) {
    const double steps = duration / timeStep;
    std::ostringstream text;
    if (steps < 0.5)
        text << "the duration " << duration << " s is shorter than half the time step " << timeStep << " s: not one step would run";
    else if (!(steps <= kMaxRunSteps))
        text << "the duration " << duration << " s at the time step " << timeStep << " s is " << steps << " steps, more than "
             << kMaxRunSteps << " (a unit mistaken?)";
    else
        return std::nullopt;
    return text.str();
}

}  // namespace flexfit
