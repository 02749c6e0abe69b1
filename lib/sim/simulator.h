#pragma once
// The eight-legged robot on its slope in MuJoCo, driven by the gait controller. MuJoCo stays
// behind a pimpl: this header is plain Eigen. The world frame is the slope frame (z normal to
// the plane, uphill = +x); the slope is made by tilting gravity, so "up" for the IMU is
// (sin a, 0, cos a) for slope angle a.
#include <Eigen/Core>
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sim/gait.h"
#include "sim/pose.h"
#include "sim/sim_config.h"

struct mjModel_;  // MuJoCo's compiled model (mujoco/mjmodel.h); only lib/sim dereferences it

namespace dgmm::sim {

// An edit of the compiled model after the config was applied (e.g. a knob of lib/sim/knobs.h
// that the JSON config does not expose: contact solref, a mass scale). Empty: none.
using ModelEdit = std::function<void(mjModel_*)>;

// A drawable geometric primitive of the simulated scene, in the slope frame (for robot_view).
struct GeomSnapshot {
  enum class Type { kPlane, kSphere, kCapsule, kCylinder, kBox, kHeightField, kOther };
  Type type = Type::kOther;
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  // MuJoCo geom_size (half-sizes / radius, half-length)
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // geom -> slope frame
  Eigen::Vector4d rgba = Eigen::Vector4d::Ones();
  // kHeightField: the ground's grid x grid heights (m, row-major, row = y), `spacing_m` apart,
  // centred on position_m (terrain.h).
  int grid = 0;
  double spacing_m = 0;
  std::vector<float> heights;
};

// Why a command execution ended.
enum class RunOutcome { kCompleted, kFell, kUnstable };

class Simulator {
 public:
  // Loads the built-in robot (or config.mjcf_path) and applies the config. Throws InputError for
  // an invalid config, an unloadable MJCF or one that breaks the naming/kinematic conventions
  // (or, with a robot block, one its description does not fit: lib/sim/legged_robot.h).
  explicit Simulator(const SimConfig& config, const ModelEdit& edit = {});
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  // Resets the robot to its standing pose at (x, y) on the slope, heading `heading_rad` (slope
  // frame, 0 = facing uphill, +pi/2 = facing +y), then stands still for settle_duration_s.
  // Returns kFell when it does not come to rest upright.
  RunOutcome Place(double x_m, double y_m, double heading_rad);
  // Runs the gait for command_duration_s. `trajectory` (optional) receives the torso pose every
  // `sample_every` steps. Stops early on a fall/flip (torso tilted > 60 deg from the slope normal
  // or its centre below 40% of the stance height above the mean ground under the feet) or
  // numerical instability.
  RunOutcome RunCommand(const Eigen::Vector3d& command, std::vector<Pose>* trajectory = nullptr,
                        int sample_every = 10);
  // As above, calling observer(*this) every `observe_every` steps (e.g. to take snapshots).
  RunOutcome RunCommand(const Eigen::Vector3d& command,
                        const std::function<void(const Simulator&)>& observer, int observe_every);
  // Stands still (nominal stance) for the given time.
  RunOutcome Stand(double seconds);

  Pose TorsoPose() const;                // true torso pose in the slope frame
  // Every foot's point in the slope frame (the built-in robot: its foot sites; a robot block's:
  // each leg's foot).
  std::vector<Eigen::Vector3d> FootPositions() const;
  // The ground's height along the slope normal at (x, y) of the slope frame (0 on the plane).
  double GroundHeight(double x_m, double y_m) const;
  // Is the ground level: no slope, no height field, and every geom of the world that the robot can
  // touch a plane facing up (a model's own ramps, boxes or height fields make it uneven)?
  bool LevelGround() const;
  // Is the ground a plane facing up under gravity tilted by the slope (no height field, every geom
  // of the world the robot can touch a plane facing up)? A slope of 0 makes it level.
  bool PlaneGround() const;
  // Is gravity tilted to a slope (the config's slope_deg not 0), on a plane or a height field?
  bool SlopedGround() const;
  Eigen::Vector2d TruePitchRoll() const; // <pitch, roll> relative to gravity (rad)
  Eigen::Vector3d Up() const;            // unit vector against gravity, slope frame
  double time_s() const;                 // simulated time since construction
  double total_mass_kg() const;
  // The longest leg's reach (m): hip to foot summed over the leg's links.
  double leg_reach_m() const;
  int leg_count() const;
  // Placements are drawn in [-w, w]^2 (m): config.placement_half_width_m, or by default 1 m for
  // the built-in robot and 2.5 leg reaches for a robot block's.
  double placement_half_width_m() const;
  // The built-in robot's legs (a robot block's robot: all zero; see leg_reach_m()).
  const std::array<LegGeometry, kNumLegs>& legs() const;
  const SimConfig& config() const;

  // Advice on the config against this robot: the ground against its scale (terrain.h
  // TerrainScaleWarnings) and, for a robot block's robot, steps its legs cannot make (gait_reach.h)
  // and actuators too weak to carry it (stance_load.h); empty when nothing is far off.
  std::vector<std::string> RobotWarnings() const;

  // Physics steps since construction in which the robot touched itself (two of its bodies in
  // contact: a leg striking another leg or the body; self_contact.h), and the pair met most often
  // ("<body> with <body>", empty when none).
  long long SelfContactSteps() const;
  std::string SelfContactPair() const;

  // Visible geoms (alpha > 0) at the current state, slope frame.
  std::vector<GeomSnapshot> Geometry() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Rotation slope frame -> gravity-aligned frame (z up): Ry(-slope).
Eigen::Matrix3d SlopeToLevel(double slope_deg);

}  // namespace dgmm::sim
