// Flexfit: rigid-deformable parts for virtual assembly. Umbrella header.
#pragma once

#include "flexfit/activity.hpp"
#include "flexfit/assembly.hpp"
#include "flexfit/collision_world.hpp"
#include "flexfit/core.hpp"
#include "flexfit/generators.hpp"
#include "flexfit/mesh.hpp"
#include "flexfit/mesh_io.hpp"
#include "flexfit/part.hpp"
#include "flexfit/pose.hpp"
#include "flexfit/kring.hpp"
#include "flexfit/mass_properties.hpp"
#include "flexfit/part_model.hpp"
#include "flexfit/part_state.hpp"
#include "flexfit/simulation.hpp"
#include "flexfit/topology.hpp"
#include "flexfit/world.hpp"
