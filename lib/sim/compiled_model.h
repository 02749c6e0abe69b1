#pragma once
// The robot model as MuJoCo compiled it, as bytes: the input of simulation cache keys.
#include <string>

#include "sim/sim_config.h"

namespace dgmm::sim {

// config's robot (config.mjcf_path, or the built-in robot) compiled and serialised by
// mj_saveModel: everything MuJoCo read for it (included files, meshes, height fields, defaults)
// and nothing of where its files are, so a key over these bytes changes when any file the model
// is built from changes and not when the robot's folder moves. Throws InputError naming the MJCF.
std::string CompiledModelBytes(const SimConfig& config);

}  // namespace dgmm::sim
