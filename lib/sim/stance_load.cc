#include "sim/stance_load.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>

namespace dgmm::sim {
namespace {

// The largest force or torque the actuators on `joint` can put on it: their force ranges times
// their gears, summed (0: none, or one not limited).
double JointLimit(const mjModel* m, int joint) {
  double limit = 0;
  for (int a = 0; a < m->nu; ++a) {
    if (m->actuator_trntype[a] != mjTRN_JOINT || m->actuator_trnid[2 * a] != joint) continue;
    if (!m->actuator_forcelimited[a]) return 0;
    const double range = std::max(std::abs(m->actuator_forcerange[2 * a]), std::abs(m->actuator_forcerange[2 * a + 1]));
    limit += range * std::abs(m->actuator_gear[6 * a]);
  }
  return limit;
}

// How far a leg's foot gives under the push `force` (torso frame) through its servos' stiffness:
// |J K^-1 J' F| (-1 when a joint is not held by a position servo). `jac`: the foot's Jacobian.
double Sag(const mjModel* m, const LegChain& leg, const std::vector<mjtNum>& jac, const Eigen::Vector3d& force) {
  Eigen::Vector3d give = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < leg.dofs.size(); ++k) {
    const int a = leg.actuators[k];
    if (a < 0 || !IsPositionServo(m, a)) return -1;
    const Eigen::Vector3d column(jac[leg.dofs[k]], jac[m->nv + leg.dofs[k]], jac[2 * m->nv + leg.dofs[k]]);
    give += column * column.dot(force) / ServoStiffness(m, a);
  }
  return give.norm();
}

}  // namespace

StanceLoad MeasureStanceLoad(const mjModel* m, const LeggedRobot& robot) {
  MjDataPtr d = RestPoseData(m, robot.torso_qpos);
  for (const LegChain& leg : robot.legs) {
    for (std::size_t k = 0; k < leg.qpos.size(); ++k) d->qpos[leg.qpos[k]] = leg.stance_q[k];
  }
  mj_kinematics(m, d.get());
  mj_comPos(m, d.get());
  const double mass = mj_getTotalmass(m);
  StanceLoad worst;
  worst.feet = std::max(1.0, robot.legs.size() * robot.timing.duty);
  const double g = Eigen::Vector3d(m->opt.gravity[0], m->opt.gravity[1], m->opt.gravity[2]).norm();
  const Eigen::Vector3d force(0, 0, mass * g / worst.feet);  // the ground's push on each foot
  std::vector<mjtNum> jacp(3 * m->nv);
  for (std::size_t i = 0; i < robot.legs.size(); ++i) {
    const LegChain& leg = robot.legs[i];
    const Eigen::Vector3d foot = FootPoint(m, d.get(), leg);
    mj_jac(m, d.get(), jacp.data(), nullptr, foot.data(), leg.foot_body);
    const double sag = Sag(m, leg, jacp, force);
    if (sag > worst.sag_m) worst.sag_leg = static_cast<int>(i), worst.sag_m = sag;
    for (std::size_t k = 0; k < leg.joints.size(); ++k) {
      const double limit = JointLimit(m, leg.joints[k]);
      if (!(limit > 0)) continue;
      double tau = 0;
      for (int r = 0; r < 3; ++r) tau += jacp[r * m->nv + leg.dofs[k]] * force[r];
      if (worst.joint < 0 || std::abs(tau) / limit > worst.needed / worst.limit) {
        worst.leg = static_cast<int>(i), worst.joint = leg.joints[k], worst.needed = std::abs(tau), worst.limit = limit;
      }
    }
  }
  return worst;
}

bool ServosGive(const StanceLoad& load, const LeggedRobot& robot) {
  const double kSagShare = 0.1;  // of the stride
  return robot.replay.empty() && load.sag_leg >= 0 && load.sag_m > kSagShare * robot.stride_m;
}

bool LegsHavePassiveJoints(const mjModel* m, const LeggedRobot& robot) {
  for (const LegChain& leg : robot.legs) {
    const int first = m->jnt_bodyid[leg.joints.front()];
    for (int b = leg.foot_body; b > 0; b = m->body_parentid[b]) {
      for (int k = 0; k < m->body_jntnum[b]; ++k) {
        const int j = m->body_jntadr[b] + k;
        if (std::find(leg.joints.begin(), leg.joints.end(), j) == leg.joints.end()) return true;
      }
      if (b == first) break;
    }
  }
  return false;
}

std::vector<std::string> StanceLoadWarnings(const StanceLoad& load, const mjModel* m, const LeggedRobot& robot,
                                            bool feedforward) {
  std::vector<std::string> out;
  char what[600];
  if (load.joint >= 0 && load.needed > load.limit) {
    const char* joint = mj_id2name(m, mjOBJ_JOINT, load.joint);
    std::snprintf(what, sizeof what,
                  "robot: its actuators cannot carry it: with its weight on %.3g feet (the gait's duty factor) joint "
                  "\"%s\" of leg %s needs %.3g at the stance, and its actuator gives at most %.3g (force range x gear); "
                  "expect it to sink or fall. Raise the actuators' force range, or stand lower or wider "
                  "(robot.gait.stance_height_m)",
                  load.feet, joint ? joint : "(unnamed)", robot.legs[load.leg].name.c_str(), load.needed, load.limit);
    out.push_back(what);
  }
  if (!feedforward && ServosGive(load, robot)) {
    std::snprintf(what, sizeof what,
                  "robot: its servos give under its weight: at the stance leg %s's foot moves %.3g m (%.0f%% of the "
                  "stride) under its share of the weight on %.3g feet, so the torso sinks at every step and drifts "
                  "whatever the command; %s",
                  robot.legs[load.sag_leg].name.c_str(), load.sag_m, 100 * load.sag_m / robot.stride_m, load.feet,
                  LegsHavePassiveJoints(m, robot)
                      ? "the legs' passive joints give too, which robot.gait.servo_feedforward cannot take out"
                      : "robot.gait.servo_feedforward: true sends targets that carry the weight");
    out.push_back(what);
  }
  return out;
}

}  // namespace dgmm::sim
