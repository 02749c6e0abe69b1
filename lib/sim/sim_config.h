#pragma once
// Physical and sensing parameters of the simulated eight-legged robot and its slope, loaded from
// and saved to a small JSON file (every field optional; missing fields keep the defaults below).
// Only lib/sim sees MuJoCo: this header is plain data.
#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>

#include "sim/robot_description.h"
#include "sim/terrain.h"

namespace dgmm::sim {

inline constexpr int kNumLegs = 8;

// Contact friction of the slope surface (MuJoCo geom friction: sliding, torsional, rolling).
// The feet use the same values; MuJoCo takes the maximum of the two geoms per contact.
struct FrictionConfig {
  double sliding = 1.0;     // dimensionless coefficient
  double torsional = 0.01;  // m
  double rolling = 0.0001;  // m
};

// Masses of the built-in robot (kg). Total = torso + 8 * (coxa + femur + tibia) ~ 12.4 kg.
struct MassConfig {
  double torso_kg = 8.0;
  double coxa_kg = 0.15;   // hip housing (hip yaw -> hip pitch)
  double femur_kg = 0.25;  // upper leg segment (hip pitch -> knee)
  double tibia_kg = 0.15;  // lower leg segment with foot (knee -> foot)
};

// An extra point-like mass rigidly attached to the torso (e.g. a battery pack moved sideways).
struct PayloadConfig {
  double mass_kg = 0.0;
  Eigen::Vector3d position_body_m = Eigen::Vector3d::Zero();  // torso frame: x fwd, y left, z up
};

// Position servos: torque = kp * leg_gain[i] * db(q_target(t - latency) - q) - damping * dq,
// clamped, with the backlash dead band db(e) = sign(e) max(0, |e| - backlash_rad / 2) (identity
// at backlash 0). Leg i: 0..3 left side front to back, 4..7 right side front to back. The latency
// is applied in whole integrator steps: round(latency_s / timestep_s) steps.
struct ActuatorConfig {
  double kp_nm_per_rad = 60.0;
  std::array<double, kNumLegs> leg_gain{1, 1, 1, 1, 1, 1, 1, 1};  // kp scale per leg
  double joint_damping_nms_per_rad = 0.5;
  double torque_limit_nm = 12.0;
  double latency_s = 0.0;  // delay between a target's computation and the servo seeing it, [0, MaxLatencyS]
  double backlash_rad = 0.0;  // total free play of each leg joint's gear train, [0, 0.2]
};

// Periodic alternating-tetrapod gait; a command <long, lat, turn> in [-1, 1]^3 scales the
// stride (long/lat, metres of foot travel per half cycle) and the turn (rad of yaw per cycle).
struct GaitConfig {
  double period_s = 0.5;          // one full cycle (both tetrapods swing once)
  double stride_m = 0.12;         // foot travel per stance phase at |command| = 1
  double turn_rad = 0.15;         // yaw of the foot pattern per stance phase at |turn| = 1
  double step_height_m = 0.05;    // swing foot lift
  double stance_height_m = 0.14;  // torso height above the feet
};

// Sensor noise: the motion tracker (pose deltas x) and the IMU (terrain z = <pitch, roll>),
// zero-mean Gaussian, independent per reading.
struct NoiseConfig {
  double tracker_position_sd_m = 0.003;
  double tracker_yaw_sd_rad = 0.01;
  double tracker_roll_sd_rad = 0.005;
  double tracker_pitch_sd_rad = 0.005;
  double imu_pitch_sd_rad = 0.01;
  double imu_roll_sd_rad = 0.01;
};

// Names a user-supplied MJCF must use (docs/simulation.md, "Bring your own robot"). Leg
// actuators are "<actuator_prefix><i>_<joint>" for i in 0..7 and joint in hip_yaw, hip_pitch,
// knee, e.g. "leg3_knee"; hinge joints carry the same names.
struct RobotNames {
  std::string torso_body = "torso";
  std::string floor_geom = "floor";
  std::string actuator_prefix = "leg";
};

struct SimConfig {
  double slope_deg = 18.0;  // incline of the plane about the world y axis (uphill = +x)
  FrictionConfig friction;
  MassConfig masses;
  PayloadConfig payload;
  ActuatorConfig actuators;
  GaitConfig gait;
  NoiseConfig noise;
  double timestep_s = 0.002;          // MuJoCo integrator step
  double command_duration_s = 1.5;    // one execution of a command
  double settle_duration_s = 0.5;     // standing still after each placement before reading z
  // Placements are drawn in [-w, w]^2 of the slope frame. 0: the default, 1 m for the built-in
  // robot (its leg reach is 0.41 m) and 2.5 leg reaches for a robot block's robot; on a plane
  // where the robot stands does not change its physics, on terrain it picks the patch of ground.
  double placement_half_width_m = 0;
  std::string mjcf_path;              // empty: the built-in robot (datasets/robots/scorpion.xml)
  RobotNames names;
  // Any legged robot (robot_description.h): with it, the model's own physics is the nominal and
  // only slope, timestep and robot.leg_gain are applied; friction, masses, actuators, gait and
  // names above are then unused. Without it, the built-in eight-legged conventions.
  std::optional<RobotDescription> robot;
  // Ground beyond the plane (terrain.h): a seeded height field over the slope. Without it, the
  // model's floor plane.
  std::optional<TerrainDescription> terrain;

  // False with a one-line reason (field and expected range) for non-finite or out-of-range values.
  bool IsValid(std::string* error) const;
};

// Parses a JSON object; unknown keys are errors (typos must not silently fall back to defaults).
// Throws InputError "<source_name>: <field>: <problem>" for bad JSON, types or values.
// The longest actuator latency a config may give: a third of its gait's cycle, 0.2 s at the least
// (a robot four times the hexapod's size walks a 1.2 s cycle).
double MaxLatencyS(const SimConfig& config);

SimConfig SimConfigFromJson(const std::string& json_text, const std::string& source_name);
// Reads a JSON config file; a relative mjcf_path or replay recording is made absolute against the
// config file's folder (so a set's recorded config finds them from any working directory).
SimConfig LoadSimConfig(const std::string& path);
// Pretty-printed JSON with every field (round-trips through SimConfigFromJson).
std::string SimConfigToJson(const SimConfig& config);
// Writes SimConfigToJson atomically; throws InputError on failure.
void SaveSimConfig(const SimConfig& config, const std::string& path);

}  // namespace dgmm::sim
