// Shared by the part benchmarks: the models (torus1, heart) and the part settings they step.
#pragma once

#include "flexfit/flexfit.hpp"

namespace flexfit::bench {

// 0: torus1, 1: heart; built once.
inline const std::shared_ptr<const PartModel>& modelByIndex(int which) {
    static const std::shared_ptr<const PartModel> models[2] = {buildPartModel(makeTorus1()), buildPartModel(makeHeart())};
    return models[which];
}

// Elastic preset (the models' default), 1 ms steps, restoration constraint c = 0.001.
inline PartSettings settings(PartMode mode) {
    PartSettings s;
    s.mode = mode;
    s.simulation.timeStep = 1e-3;
    s.simulation.restoration.method = RestorationMethod::Constraint;
    s.simulation.restoration.constraintFraction = 1e-3;
    return s;
}

}  // namespace flexfit::bench
