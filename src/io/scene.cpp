// Scene data (scene.hpp).
#include "flexfit/scene.hpp"

namespace flexfit {

std::optional<BodyId> Scene::find(std::string_view name) const {
    for (BodyId i = 0; i < parts.size(); ++i)
        if (parts[i].name == name) return i;
    return std::nullopt;
}

}  // namespace flexfit
