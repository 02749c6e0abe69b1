#pragma once
// Internal to dgmm_sim (includes MuJoCo): the ground the robot stands on. Without a terrain block
// it is the model's floor plane (height 0 everywhere). With one, the robot's MJCF is compiled
// inside a wrapper that adds an hfield geom "dgmm_ground" of the generated heights (terrain.h);
// after the config and any model edit, the hfield takes over the floor geom's contact parameters
// (so floor knobs act on it) and the plane is hidden and no longer collides.
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "sim/mujoco_model.h"
#include "sim/sim_config.h"
#include "sim/terrain.h"

namespace dgmm::sim {

class Ground {
 public:
  // Generates the height field of config.terrain, if any.
  explicit Ground(const SimConfig& config);

  // Compiles the robot of `config` (LoadRobotModel's MJCF, the built-in one when mjcf_path is
  // empty) with the height field geom added when there is terrain. Throws InputError.
  MjModelPtr Load(const SimConfig& config) const;
  // Fills the hfield, copies the floor's contact parameters to it and retires the floor plane.
  // No-op on a plane. Throws InputError when the model has no dgmm_ground geom.
  void Install(mjModel* model, int floor_geom, const std::string& source) const;

  // Ground height along the slope normal at (x, y) of the slope frame (0 on the plane).
  double HeightAt(double x_m, double y_m) const { return field_ ? field_->At(x_m, y_m) : 0.0; }
  const HeightField* field() const { return field_ ? &*field_ : nullptr; }
  // The mean ground height under the points' (x, y) (the fall test's reference); 0 on the plane.
  double MeanUnder(const std::vector<Eigen::Vector3d>& points_m) const;
  // The highest ground under the points `offsets_m` (robot frame x, y) of a robot standing at
  // (x, y) with heading `heading_rad` (placement drops it onto this).
  double HighestUnder(double x_m, double y_m, double heading_rad, const std::vector<Eigen::Vector2d>& offsets_m) const;

 private:
  std::optional<HeightField> field_;
};

// The wrapper MJCF: includes `robot_file` (a name in the same folder or the VFS) and adds the
// hfield asset and geom for `field`.
std::string GroundWrapperMjcf(const std::string& robot_file, const HeightField& field);

}  // namespace dgmm::sim
