#pragma once
// Internal to dgmm_sim (includes MuJoCo): a RobotDescription bound to a compiled model and
// checked against it, and the generic gait that walks it (numerical inverse kinematics on each
// foot's Jacobian, timing from gait_table.h). Used by Simulator when a config has a robot block.
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "sim/gait_table.h"
#include "sim/mujoco_model.h"
#include "sim/replay.h"
#include "sim/robot_description.h"
#include "sim/sim_config.h"

namespace dgmm::sim {

struct LegChain {
  std::string name;
  std::vector<int> joints, qpos, dofs, actuators;
  int foot_site = -1, foot_geom = -1, foot_body = -1;
  Eigen::Vector3d foot_offset_m = Eigen::Vector3d::Zero();  // in foot_body's frame
  int side = 1;                    // +1 left, -1 right of the forward axis
  double reach_m = 0;              // joint-to-joint and last joint-to-foot lengths at rest, summed
  double foot_extent_m = 0;        // lowest contact point below the foot point
  Eigen::Vector3d stance_m = Eigen::Vector3d::Zero();  // standing foot position, robot frame
  Eigen::VectorXd stance_q;        // the leg's joint values there
  // Per joint, the values the gait may ask for: its range (if limited) within what its servo can be
  // commanded to (its ctrlrange, if limited, through ctrl = offset + scale q); -inf/+inf when free.
  Eigen::VectorXd q_lo, q_hi;
};

struct LeggedRobot {
  int torso_body = -1, torso_qpos = -1, torso_dof = -1, floor_geom = -1;
  Eigen::Matrix3d robot_in_torso = Eigen::Matrix3d::Identity();  // columns: forward, left, up
  std::vector<LegChain> legs;
  std::vector<int> leg_actuators;  // every actuator a leg drives
  // robot.held_joints: qpos addresses, their actuators (-1: none, a replay's robot) and rest values.
  std::vector<int> held_qpos, held_actuators;
  Eigen::VectorXd held_q;
  GaitTiming timing;
  double reach_m = 0, stance_height_m = 0, stride_m = 0, step_height_m = 0;
  // A replay controller's tracks (one per robot.controller.recordings entry, columns in actuator
  // id order) and the standing one; empty with the generic gait.
  std::vector<ReplayTrack> replay;
  int stand_recording = -1;
};

// Binds and validates (one-line InputError "<source>: robot.<part>: <problem>"): parts exist and
// are of the right kind, each leg's joints lie on its torso-to-foot chain, every joint is driven
// by a position servo of its leg, declared passive, or declared held (driven off the legs, held at
// rest by the gait's position servo), no actuator drives anything else, declared
// sides agree with the geometry, the gait fits the legs and every foot reaches the ground at the
// stance height.
LeggedRobot BindRobot(const mjModel* model, const RobotDescription& robot, const std::string& source);

// The model's own physics kept; only what the experiment sets: timestep and the slope (gravity
// tilted, magnitude kept), per-leg gains (robot.leg_gain) on the leg's servos and a payload
// (config.payload: mass on the torso at (forward, left, up) offsets). With
// robot.overwrite_physics, config.friction replaces every geom's friction. Throws InputError
// "<source>: payload.<field>: ..." for a payload over 10 times the robot's mass or further than
// 2 leg reaches from the torso (relative bounds: a robot of any size).
void ApplyExperiment(const SimConfig& config, const LeggedRobot& bound, mjModel* model, const std::string& source = "");

// A compact ball (radius 0.1 leg reach) rigidly added to body `torso` at `p_m` (body frame): the
// body's mass, centre of mass and inertia (parallel axes; the principal frame turns when the payload
// adds products of inertia) updated.
void AddPayload(mjModel* model, int torso, const Eigen::Vector3d& p_m, double mass_kg, double reach_m);

// Damped least squares on the foot's Jacobian restricted to the leg's joints, joint ranges
// respected: moves `q` (the leg's joint values) towards placing the foot at `target_m` (torso
// frame) in `iterations` steps, using `scratch` (torso at the origin). Returns the residual (m).
// With `limits_pin`, a step that would push a joint beyond its limit is solved again without that
// joint (the others do not count on it; the stance's search from other starts). Without it a
// joint is only clamped, as the gait has always done (its recordings stay bit-identical).
double SolveLegIk(const mjModel* model, mjData* scratch, const LegChain& leg, const Eigen::Vector3d& target_m,
                  Eigen::VectorXd* q, int iterations, bool limits_pin = false);

// The same for every leg at once (one forward-kinematics pass per iteration: the legs' chains are
// independent); returns the largest residual.
double SolveLegsIk(const mjModel* model, mjData* scratch, const std::vector<LegChain>& legs,
                   const std::vector<Eigen::Vector3d>& targets_m, std::vector<Eigen::VectorXd>* q, int iterations,
                   bool limits_pin = false);

// Data at the model's first keyframe (qpos0 without one) with the torso's free joint at the world's
// origin, unrotated: the frame every rest-pose measurement (reach, stance, gait reach, load) is made in.
MjDataPtr RestPoseData(const mjModel* model, int torso_qpos);

// Foot point of a leg in the world frame of `data`.
Eigen::Vector3d FootPoint(const mjModel* model, const mjData* data, const LegChain& leg);

// Actuator `a` is a position servo: force = gain * ctrl - gain * q (MuJoCo's <position>).
bool IsPositionServo(const mjModel* model, int a);

// A position servo's stiffness at its joint: torque per unit of joint error, -b1 gear^2.
double ServoStiffness(const mjModel* model, int a);

// Body `body` is `ancestor` or lies below it (every body lies below the world body, 0).
bool IsDescendant(const mjModel* model, int body, int ancestor);

// The actuator driving `joint` through a joint transmission, or -1.
int ActuatorOf(const mjModel* model, int joint);

// Forward, left and up of the robot (columns) in the torso frame, for a forward axis there.
Eigen::Matrix3d RobotFrame(const Eigen::Vector3d& forward);

// The side of a foot at `foot` (torso frame): +1 left of the forward axis (or on it), -1 right.
// The one rule for a leg's side (the binding's check of a declared side, the draft's sides).
int FootSide(const Eigen::Matrix3d& robot_in_torso, const Eigen::Vector3d& foot);

}  // namespace dgmm::sim
