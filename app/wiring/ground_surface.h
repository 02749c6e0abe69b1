#pragma once
// The ground of a simulation config as prediction reads it (lib/predict/ground_terrain.h): its
// slope, its height field (the `terrain` block) and the robot's footprint, the feet relative to
// the torso when it stands on flat ground, measured in the simulator.
#include "predict/ground_terrain.h"
#include "sim/sim_config.h"

namespace dgmm::app {

// Throws InputError naming the part of the config or model that is wrong.
predict::GroundSurface GroundSurfaceOf(const sim::SimConfig& config);

}  // namespace dgmm::app
