#pragma once
// Internal to dgmm_sim (includes MuJoCo): joint targets that carry what the model's own physics
// takes. A position servo holds its joint with torque k (q' - q) (k = -b1 gear^2, its stiffness),
// so a target q' = q only comes within tau / k of q under a load tau. Under soft servos the legs
// sag under the robot's weight and lag behind the gait through the joints' damping and friction
// loss; because a leg is not symmetric fore and aft, the torso then drifts a little at every step
// whatever the command. With robot.gait.servo_feedforward the gait sends
//   q' = q + K^-1 (-J' F - sum_b J_b' m_b g + D qdot + f sign(qdot))
// instead: F the share of the robot's weight on each foot on the ground (statics of the support
// polygon; a foot counts from the moment it touches, as a contact switch would tell), the
// sum the leg's own links' weight (J_b the Jacobian of body b's centre of mass), D and f the
// joints' damping and friction loss at the planned joint velocity qdot, K the servos' stiffness.
// All nominal: what the controller knows, the model before the experiment's payload, leg gains or
// knobs, which therefore still show in the motion.
#include <mujoco/mujoco.h>

#include <Eigen/Core>
#include <vector>

#include "sim/legged_robot.h"

namespace dgmm::sim {

// Vertical loads f_i (N) on feet at horizontal points p_i carrying weight W whose line of action
// meets the ground at c: the least-squares solution of sum_i f_i = W, sum_i f_i (p_i - c) = 0
// weighted by each foot's share s_i in [0, 1] (f = S A' (A S A')^+ b, negative loads clamped to 0).
// A foot with share 0 carries nothing; two feet carry what the line between them can.
Eigen::VectorXd SupportForces(const std::vector<Eigen::Vector2d>& feet_m, const std::vector<double>& share,
                              const Eigen::Vector2d& centre_m, double weight_n);

// The legs' state the feedforward is for: per leg, joint targets, their planned velocities (empty:
// at rest), the foot target (robot frame) and whether it is on the ground (1) or not (0); gravity's
// direction (unit, robot frame).
struct LegPlan {
  std::vector<Eigen::VectorXd> q, q_velocity;
  std::vector<Eigen::Vector3d> feet_robot_m;
  std::vector<double> on_ground;
  Eigen::Vector3d gravity_robot = -Eigen::Vector3d::UnitZ();
};

class ServoFeedforward {
 public:
  ServoFeedforward() = default;
  // Reads the nominal model (before ApplyExperiment and any edit): each leg servo's stiffness, its
  // joint's damping and friction loss, the bodies' masses and the centre of mass at the stance.
  // `robot` bound for the generic gait (every leg joint driven by a position servo).
  ServoFeedforward(const mjModel* nominal, const LeggedRobot& robot, double period_s);

  bool enabled() const { return !stiffness_.empty(); }
  // Per leg, 1 when one of its bodies touches something that is not the robot, else 0.
  std::vector<double> OnGround(const mjModel* model, const mjData* data, int torso_body) const;
  // Target offsets, one per leg joint in leg order, to add to the joint targets.
  // `scratch`: torso at the origin (SolveLegsIk's).
  Eigen::VectorXd Offsets(const mjModel* model, mjData* scratch, const LeggedRobot& robot, const LegPlan& plan) const;

 private:
  Eigen::VectorXd LegWeightTorques(const mjModel* m, mjData* d, const LegChain& leg, int l, double load_n,
                                   const Eigen::Vector3d& gravity_torso) const;

  // Per leg joint, in leg order:
  std::vector<double> stiffness_;        // N m / rad or N / m
  std::vector<double> damping_, friction_loss_, sign_scale_;  // sign(v) ~ tanh(v / sign_scale)
  std::vector<std::vector<int>> bodies_;  // per leg, the bodies its first joint moves
  std::vector<double> mass_kg_;           // per body
  double gravity_ = 0;                    // m/s^2
  double weight_n_ = 0;
  Eigen::Vector3d centre_robot_m_ = Eigen::Vector3d::Zero();  // centre of mass at the stance, robot frame
};

}  // namespace dgmm::sim
