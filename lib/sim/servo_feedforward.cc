#include "sim/servo_feedforward.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace dgmm::sim {

Eigen::VectorXd SupportForces(const std::vector<Eigen::Vector2d>& feet, const std::vector<double>& share,
                              const Eigen::Vector2d& centre, double weight_n) {
  const int n = static_cast<int>(feet.size());
  Eigen::MatrixXd a(3, n);  // rows: sum of loads, their moments about the centre
  for (int i = 0; i < n; ++i) a.col(i) << 1, feet[i].x() - centre.x(), feet[i].y() - centre.y();
  const Eigen::VectorXd s = Eigen::Map<const Eigen::VectorXd>(share.data(), n).cwiseMax(0.0);
  const Eigen::Vector3d b(weight_n, 0, 0);
  const Eigen::Matrix3d ass = a * s.asDiagonal() * a.transpose();
  const Eigen::Vector3d y = ass.completeOrthogonalDecomposition().solve(b);
  return (s.asDiagonal() * a.transpose() * y).cwiseMax(0.0);
}

ServoFeedforward::ServoFeedforward(const mjModel* m, const LeggedRobot& robot, double period_s) {
  for (const LegChain& leg : robot.legs) {
    for (std::size_t k = 0; k < leg.joints.size(); ++k) {
      // A position servo: BindRobot refuses anything else under the gait.
      stiffness_.push_back(ServoStiffness(m, leg.actuators[k]));
      damping_.push_back(m->dof_damping[leg.dofs[k]]);
      friction_loss_.push_back(m->dof_frictionloss[leg.dofs[k]]);
      // Friction's sign smoothed over 5% of a joint's sweep per cycle (a radian, or a leg's reach).
      const double sweep = m->jnt_type[leg.joints[k]] == mjJNT_SLIDE ? leg.reach_m : 1.0;
      sign_scale_.push_back(0.05 * sweep / period_s);
    }
    bodies_.emplace_back();
    for (int b = 1; b < m->nbody; ++b) {
      if (IsDescendant(m, b, m->jnt_bodyid[leg.joints.front()])) bodies_.back().push_back(b);
    }
  }
  mass_kg_.assign(m->body_mass, m->body_mass + m->nbody);
  gravity_ = Eigen::Vector3d(m->opt.gravity[0], m->opt.gravity[1], m->opt.gravity[2]).norm();
  weight_n_ = mj_getTotalmass(m) * gravity_;
  MjDataPtr d = RestPoseData(m, robot.torso_qpos);
  for (const LegChain& leg : robot.legs) {
    for (std::size_t k = 0; k < leg.qpos.size(); ++k) d->qpos[leg.qpos[k]] = leg.stance_q[k];
  }
  mj_kinematics(m, d.get());
  mj_comPos(m, d.get());
  const double* c = d->subtree_com + 3 * robot.torso_body;  // the torso is the root: the whole robot
  centre_robot_m_ = robot.robot_in_torso.transpose() * Eigen::Vector3d(c[0], c[1], c[2]);
}

std::vector<double> ServoFeedforward::OnGround(const mjModel* m, const mjData* d, int torso) const {
  std::vector<double> on(bodies_.size(), 0.0);
  for (int c = 0; c < d->ncon; ++c) {
    const int a = m->geom_bodyid[d->contact[c].geom1], b = m->geom_bodyid[d->contact[c].geom2];
    for (std::size_t l = 0; l < bodies_.size(); ++l) {
      const bool has_a = std::count(bodies_[l].begin(), bodies_[l].end(), a) > 0;
      const bool has_b = std::count(bodies_[l].begin(), bodies_[l].end(), b) > 0;
      if ((has_a && !IsDescendant(m, b, torso)) || (has_b && !IsDescendant(m, a, torso))) on[l] = 1;
    }
  }
  return on;
}

// -J' F - sum_b J_b' m_b g for leg l carrying load_n (d at the legs' targets).
Eigen::VectorXd ServoFeedforward::LegWeightTorques(const mjModel* m, mjData* d, const LegChain& leg, int l,
                                                   double load_n, const Eigen::Vector3d& g) const {
  std::vector<mjtNum> jacp(3 * m->nv);
  Eigen::VectorXd tau = Eigen::VectorXd::Zero(static_cast<int>(leg.dofs.size()));
  auto balance = [&](const Eigen::Vector3d& force) {
    for (std::size_t j = 0; j < leg.dofs.size(); ++j) {
      for (int r = 0; r < 3; ++r) tau[j] -= jacp[r * m->nv + leg.dofs[j]] * force[r];
    }
  };
  const Eigen::Vector3d foot = FootPoint(m, d, leg);
  mj_jac(m, d, jacp.data(), nullptr, foot.data(), leg.foot_body);
  balance(-load_n * g);  // the ground's push on the foot
  for (int b : bodies_[l]) {
    mj_jacBodyCom(m, d, jacp.data(), nullptr, b);
    balance(mass_kg_[b] * gravity_ * g);
  }
  return tau;
}

Eigen::VectorXd ServoFeedforward::Offsets(const mjModel* m, mjData* d, const LeggedRobot& robot,
                                          const LegPlan& plan) const {
  const std::size_t n = robot.legs.size();
  const Eigen::Vector3d& g = plan.gravity_robot;
  double feet_z = 0;  // where the line of gravity through the centre of mass meets the feet's mean height
  for (const auto& f : plan.feet_robot_m) feet_z += f.z() / n;
  const Eigen::Vector2d centre = centre_robot_m_.head<2>() + g.head<2>() * (feet_z - centre_robot_m_.z()) / g.z();
  std::vector<Eigen::Vector2d> feet_xy;
  for (const auto& f : plan.feet_robot_m) feet_xy.push_back(f.head<2>());
  const Eigen::VectorXd load = SupportForces(feet_xy, plan.on_ground, centre, weight_n_);
  for (std::size_t l = 0; l < n; ++l) {
    for (std::size_t k = 0; k < robot.legs[l].qpos.size(); ++k) d->qpos[robot.legs[l].qpos[k]] = plan.q[l][k];
  }
  mj_kinematics(m, d);
  mj_comPos(m, d);
  const Eigen::Vector3d g_torso = robot.robot_in_torso * g;
  Eigen::VectorXd offsets(static_cast<int>(stiffness_.size()));
  int k = 0;
  for (std::size_t l = 0; l < n; ++l) {
    const Eigen::VectorXd tau = LegWeightTorques(m, d, robot.legs[l], static_cast<int>(l), load[l], g_torso);
    for (int j = 0; j < tau.size(); ++j, ++k) {
      const double v = plan.q_velocity.empty() ? 0 : plan.q_velocity[l][j];
      offsets[k] = (tau[j] + damping_[k] * v + friction_loss_[k] * std::tanh(v / sign_scale_[k])) / stiffness_[k];
    }
  }
  return offsets;
}

}  // namespace dgmm::sim
