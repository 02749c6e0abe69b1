#pragma once
// Internal to dgmm_sim (includes MuJoCo): loading the robot MJCF, applying a SimConfig to the
// compiled model, and finding the named parts the controller needs.
#include <mujoco/mujoco.h>

#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "sim/gait.h"
#include "sim/sim_config.h"

namespace dgmm::sim {

struct MjModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct MjDataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using MjModelPtr = std::unique_ptr<mjModel, MjModelDeleter>;
using MjDataPtr = std::unique_ptr<mjData, MjDataDeleter>;

// The built-in robot (datasets/robots/scorpion.xml, embedded at build time).
extern const char* const kBuiltinRobotMjcf;

// Compiles MJCF text (no external assets) through an in-memory VFS. Throws InputError
// "<source_name>: <MuJoCo's message>" on failure.
MjModelPtr LoadMjcfString(const std::string& xml, const std::string& source_name);
// Compiles `load_path` with in-memory files (MuJoCo's VFS: found by base name before the disk;
// relative includes and assets resolve against load_path's folder). Throws InputError.
MjModelPtr LoadWithFiles(const std::vector<std::pair<std::string, std::string>>& files,
                         const std::string& load_path, const std::string& source_name);
// Compiles config.mjcf_path, or the built-in robot when it is empty.
MjModelPtr LoadRobotModel(const SimConfig& config);

// One mj_step; false when MuJoCo raised a warning in it (bad numbers, full contact buffers). The
// warning counters are cleared.
bool StepChecked(const mjModel* model, mjData* data);

// Ids of the parts the controller drives, found by the names of docs/simulation.md.
struct RobotParts {
  int torso_body = -1;
  int torso_qpos = -1;  // address of the free joint's 7 qpos (x y z qw qx qy qz)
  int torso_dof = -1;
  int floor_geom = -1;
  // Per leg, per joint (hip_yaw, hip_pitch, knee): actuator id and joint qpos address.
  std::array<std::array<int, 3>, kNumLegs> actuator{};
  std::array<std::array<int, 3>, kNumLegs> joint{};
  std::array<int, kNumLegs> foot_site{};  // <prefix><i>_foot
  std::array<LegGeometry, kNumLegs> legs{};
};

// Finds the parts and measures the leg geometry at q = 0 (checks the conventions). Throws
// InputError naming the missing or misbuilt part.
RobotParts FindRobotParts(const mjModel* model, const SimConfig& config,
                          const std::string& source_name);

// Writes the config's physics into the model: timestep, gravity (slope), friction of every
// geom, masses (bodies <prefix><i>_{coxa,femur,tibia}, torso, payload), actuator gains and
// torque limits, joint damping. Throws InputError when a payload is asked for and the model
// has no body named "payload".
void ApplyConfig(const SimConfig& config, const RobotParts& parts, mjModel* model,
                 const std::string& source_name);

}  // namespace dgmm::sim
