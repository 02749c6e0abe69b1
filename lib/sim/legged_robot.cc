#include "sim/legged_robot.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <set>

#include "sim/actuation_line.h"
#include "sim/contact_extent.h"
#include "sim/replay.h"
#include "util/error.h"

namespace dgmm::sim {
namespace {

Eigen::Vector3d Vec(const mjtNum* v) { return Eigen::Vector3d(v[0], v[1], v[2]); }
Eigen::Matrix3d Mat(const mjtNum* m) { return Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>>(m); }

std::string LegPart(int i, const LegDescription& leg) {
  return "robot.legs[" + std::to_string(i) + "] (" + leg.name + ")";
}

int Find(const mjModel* m, mjtObj type, const std::string& name, const std::string& kind, const std::string& field,
         const std::string& source) {
  const int id = mj_name2id(m, type, name.c_str());
  if (id < 0) throw MakeInputError(source, field, "the model has no " + kind + " named \"" + name + "\"");
  return id;
}

// How far the foot's contact reaches below its foot point: a geom foot's own extent when it can
// touch the floor; else (a site, a body, a visual geom) the lowest point of the geoms on the foot's
// body and the bodies below it that can. -1 when none can.
double FootExtent(const mjModel* m, const mjData* d, const LegChain& leg, const Eigen::Vector3d& foot, int floor) {
  if (leg.foot_geom >= 0 && CanTouch(m, leg.foot_geom, floor)) return ExtentBelow(m, d, leg.foot_geom);
  double extent = -1;
  for (int g = 0; g < m->ngeom; ++g) {
    if (!IsDescendant(m, m->geom_bodyid[g], leg.foot_body) || !CanTouch(m, g, floor)) continue;
    extent = std::max({extent, 0.0, foot.z() - (d->geom_xpos[3 * g + 2] - ExtentBelow(m, d, g))});
  }
  return extent;
}

void BindFoot(const mjModel* m, const FootDescription& foot, const std::string& part, const std::string& source,
              LegChain* leg) {
  if (!foot.site.empty()) {
    leg->foot_site = Find(m, mjOBJ_SITE, foot.site, "site", part + ".foot.site", source);
    leg->foot_body = m->site_bodyid[leg->foot_site];
  } else if (!foot.geom.empty()) {
    leg->foot_geom = Find(m, mjOBJ_GEOM, foot.geom, "geom", part + ".foot.geom", source);
    leg->foot_body = m->geom_bodyid[leg->foot_geom];
  } else {
    leg->foot_body = Find(m, mjOBJ_BODY, foot.body, "body", part + ".foot.body", source);
    leg->foot_offset_m = foot.offset_m;
  }
}

// The values joint j may be asked for: its range (if limited) within the joint values at which its
// servo a (if any, and if its ctrl is limited) holds it: ctrl = -(b0 + b1 gear q) / gain.
Eigen::Vector2d TargetRange(const mjModel* m, int j, int a) {
  Eigen::Vector2d r(-INFINITY, INFINITY);
  if (m->jnt_limited[j]) r = Eigen::Vector2d(m->jnt_range[2 * j], m->jnt_range[2 * j + 1]);
  if (a < 0 || !m->actuator_ctrllimited[a]) return r;
  const std::optional<ServoMap> map = JointServoMap(m, a);  // the actuation line's map
  if (!map || !(std::abs(map->scale) > 0) || !std::isfinite(map->scale)) return r;
  const double q0 = (m->actuator_ctrlrange[2 * a] - map->offset) / map->scale;
  const double q1 = (m->actuator_ctrlrange[2 * a + 1] - map->offset) / map->scale;
  return Eigen::Vector2d(std::max(r[0], std::min(q0, q1)), std::min(r[1], std::max(q0, q1)));
}

// The actuator driving joint k (`j`) of a leg: the one named in the description or the one on
// the joint. The generic gait needs a position servo on every leg joint; a replay does not (-1:
// the joint is driven otherwise, e.g. through a tendon).
int LegActuator(const mjModel* m, const RobotDescription& r, const LegDescription& desc, std::size_t k, int j,
                const std::string& part, const std::string& source) {
  int a = -1;
  if (desc.actuators.empty()) {
    a = ActuatorOf(m, j);
    if (a < 0 && !r.controller.replay()) {
      throw MakeInputError(source, part + ".joints",
                           "no actuator drives joint \"" + desc.joints[k] +
                               "\" (add one, or model the leg without it and list the joint in robot.passive_joints)");
    }
  } else {
    a = Find(m, mjOBJ_ACTUATOR, desc.actuators[k], "actuator", part + ".actuators", source);
    if (m->actuator_trntype[a] != mjTRN_JOINT || m->actuator_trnid[2 * a] != j) {
      throw MakeInputError(source, part + ".actuators",
                           "actuator \"" + desc.actuators[k] + "\" does not drive joint \"" + desc.joints[k] + "\"");
    }
  }
  if (a >= 0 && !r.controller.replay() && !IsPositionServo(m, a)) {
    const char* name = mj_id2name(m, mjOBJ_ACTUATOR, a);
    throw MakeInputError(source, part + ".actuators",
                         std::string("actuator \"") + (name ? name : "?") +
                             "\" is not a position servo: the generic gait sends joint angles; drive a robot with "
                             "motor or tendon actuation by a replay (robot.controller type replay)");
  }
  return a;
}

// Joints, actuators and foot of leg i, checked to lie on one torso-to-foot chain.
LegChain BindChain(const mjModel* m, const RobotDescription& r, int i, int torso, const std::string& source) {
  const LegDescription& desc = r.legs[i];
  const std::string part = LegPart(i, desc);
  LegChain leg;
  leg.name = desc.name;
  BindFoot(m, desc.foot, part, source, &leg);
  int parent_body = torso;
  for (std::size_t k = 0; k < desc.joints.size(); ++k) {
    const int j = Find(m, mjOBJ_JOINT, desc.joints[k], "joint", part + ".joints", source);
    if (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE) {
      throw MakeInputError(source, part + ".joints", "joint \"" + desc.joints[k] + "\" is not a hinge or slide joint");
    }
    const int body = m->jnt_bodyid[j];
    if (body == torso || !IsDescendant(m, body, parent_body) || !IsDescendant(m, leg.foot_body, body)) {
      throw MakeInputError(source, part + ".joints",
                           "joint \"" + desc.joints[k] + "\" is not on the chain from the torso to the foot (in order)");
    }
    parent_body = body;
    leg.joints.push_back(j);
    leg.qpos.push_back(m->jnt_qposadr[j]);
    leg.dofs.push_back(m->jnt_dofadr[j]);
    const int a = LegActuator(m, r, desc, k, j, part, source);
    if (a >= 0) leg.actuators.push_back(a);
    const Eigen::Vector2d range = TargetRange(m, j, a);
    leg.q_lo.conservativeResize(static_cast<int>(k) + 1), leg.q_hi.conservativeResize(static_cast<int>(k) + 1);
    leg.q_lo[k] = range[0], leg.q_hi[k] = range[1];
  }
  return leg;
}

// An actuator for a message: its name, else its index and the joint it drives.
std::string ActuatorLabel(const mjModel* m, int a) {
  const char* name = mj_id2name(m, mjOBJ_ACTUATOR, a);
  if (name) return std::string("actuator \"") + name + "\"";
  std::string label = "actuator " + std::to_string(a) + " (unnamed";
  if (m->actuator_trntype[a] == mjTRN_JOINT) {
    const char* joint = mj_id2name(m, mjOBJ_JOINT, m->actuator_trnid[2 * a]);
    if (joint) label += std::string(", on joint \"") + joint + "\"";
  }
  return label + ")";
}

// robot.held_joints: hinges or slides of no leg, each driven by a position servo (with the gait),
// held at its rest value, which lies within what the joint and its servo allow. Returns their ids.
std::vector<int> BindHeld(const mjModel* m, const RobotDescription& r, const std::set<int>& leg_joints,
                          const std::string& source, LeggedRobot* bound) {
  std::vector<int> ids;
  const MjDataPtr rest = RestPoseData(m, bound->torso_qpos);
  bound->held_q.resize(static_cast<int>(r.held_joints.size()));
  for (std::size_t i = 0; i < r.held_joints.size(); ++i) {
    const std::string& name = r.held_joints[i];
    const int j = Find(m, mjOBJ_JOINT, name, "joint", "robot.held_joints", source);
    std::string problem;
    if (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE) problem = "is not a hinge or slide joint";
    if (leg_joints.count(j)) problem = "is also a leg's joint";
    if (std::count(r.passive_joints.begin(), r.passive_joints.end(), name)) problem = "is also declared passive";
    const int a = ActuatorOf(m, j);
    if (problem.empty() && !r.controller.replay() && (a < 0 || !IsPositionServo(m, a))) {
      problem = a < 0 ? "is driven by no actuator (list it in robot.passive_joints)"
                      : "is not driven by a position servo, which the gait needs to hold it";
    }
    const double q = rest->qpos[m->jnt_qposadr[j]];
    const Eigen::Vector2d range = TargetRange(m, j, a);
    if (problem.empty() && !(q >= range[0] - 1e-9 && q <= range[1] + 1e-9)) {
      char what[120];
      std::snprintf(what, sizeof what, "rests at %g, outside what its range and its servo allow [%g, %g]", q,
                    range[0], range[1]);
      problem = what;
    }
    if (!problem.empty()) throw MakeInputError(source, "robot.held_joints", "joint \"" + name + "\" " + problem);
    bound->held_qpos.push_back(m->jnt_qposadr[j]);
    bound->held_actuators.push_back(a);
    bound->held_q[static_cast<int>(i)] = q;
    ids.push_back(j);
  }
  return ids;
}

// Every joint is a leg's, passive, held or the torso's free joint; every actuator drives a leg
// joint or a held one.
void CheckEverythingAccounted(const mjModel* m, const RobotDescription& r, LeggedRobot* bound,
                              const std::string& source) {
  std::set<int> leg_joints, accounted, driven(bound->leg_actuators.begin(), bound->leg_actuators.end());
  for (const auto& leg : bound->legs) leg_joints.insert(leg.joints.begin(), leg.joints.end());
  for (const auto& name : r.passive_joints) {
    const int j = Find(m, mjOBJ_JOINT, name, "joint", "robot.passive_joints", source);
    if (leg_joints.count(j)) {
      throw MakeInputError(source, "robot.passive_joints", "joint \"" + name + "\" is also a leg's driven joint");
    }
    accounted.insert(j);
  }
  for (int j : BindHeld(m, r, leg_joints, source, bound)) accounted.insert(j);
  driven.insert(bound->held_actuators.begin(), bound->held_actuators.end());
  accounted.insert(leg_joints.begin(), leg_joints.end());
  for (int j = 0; j < m->njnt; ++j) {
    if (m->jnt_type[j] == mjJNT_FREE || accounted.count(j)) continue;
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    throw MakeInputError(source, "robot.legs",
                         std::string("joint \"") + (name ? name : "(unnamed)") +
                             "\" belongs to no leg and is declared neither in robot.passive_joints (undriven) nor in "
                             "robot.held_joints (driven, held at rest: a spine, a neck, a tail)");
  }
  for (int a = 0; a < m->nu && !r.controller.replay(); ++a) {  // a replay drives every actuator
    if (driven.count(a)) continue;
    throw MakeInputError(source, "robot.legs", ActuatorLabel(m, a) + " drives no leg's joint and no held joint");
  }
}

// Rest-pose geometry of every leg: reach, side (checked against the declared one), foot extent.
void MeasureRest(const mjModel* m, const RobotDescription& r, const std::string& source, LeggedRobot* bound) {
  MjDataPtr d = RestPoseData(m, bound->torso_qpos);
  mj_kinematics(m, d.get());
  for (std::size_t i = 0; i < bound->legs.size(); ++i) {
    LegChain& leg = bound->legs[i];
    Eigen::Vector3d last = Vec(d->xanchor + 3 * leg.joints[0]);
    for (std::size_t k = 1; k < leg.joints.size(); ++k) {
      const Eigen::Vector3d a = Vec(d->xanchor + 3 * leg.joints[k]);
      leg.reach_m += (a - last).norm();
      last = a;
    }
    const Eigen::Vector3d foot = FootPoint(m, d.get(), leg);
    leg.reach_m += (foot - last).norm();
    leg.foot_extent_m = FootExtent(m, d.get(), leg, foot, bound->floor_geom);
    if (leg.foot_extent_m < 0) {
      const char* body = mj_id2name(m, mjOBJ_BODY, leg.foot_body);
      throw MakeInputError(source, LegPart(static_cast<int>(i), r.legs[i]) + ".foot",
                           std::string("no geom of body \"") + (body ? body : "(unnamed)") +
                               "\" or below it can touch the floor (their contype/conaffinity and the floor's "
                               "do not meet, and no <pair> joins them)");
    }
    const Eigen::Vector3d in_robot = bound->robot_in_torso.transpose() * foot;
    const int side = FootSide(bound->robot_in_torso, foot);
    const std::string& declared = r.legs[i].side;
    if (!declared.empty() && (declared == "left" ? 1 : -1) != side) {
      throw MakeInputError(source, LegPart(static_cast<int>(i), r.legs[i]) + ".side",
                           "declared " + declared + " but the foot is on the " + (side > 0 ? "left" : "right") +
                               " of the forward axis");
    }
    leg.side = side;
    leg.stance_m = in_robot;
    leg.stance_q.resize(static_cast<int>(leg.qpos.size()));
    for (std::size_t k = 0; k < leg.qpos.size(); ++k) leg.stance_q[k] = d->qpos[leg.qpos[k]];
    bound->reach_m = std::max(bound->reach_m, leg.reach_m);
    if (leg.reach_m < 1e-3) {
      throw MakeInputError(source, LegPart(static_cast<int>(i), r.legs[i]), "the leg has no length");
    }
  }
}

// Stance height and gait lengths from the description (relative to reach unless in metres).
void ChooseLengths(const RobotDescription& r, LeggedRobot* b, const std::string& source) {
  const auto& g = r.gait;
  double rest_drop = 0;
  for (const auto& leg : b->legs) rest_drop = std::max(rest_drop, -leg.stance_m.z());
  b->stance_height_m = g.stance_height_m > 0        ? g.stance_height_m
                       : g.stance_height_reach > 0 ? g.stance_height_reach * b->reach_m
                                                   : 0.9 * rest_drop;
  if (b->stance_height_m < 0.05 * b->reach_m) {
    throw MakeInputError(source, "robot.gait.stance_height_m",
                         "the feet are not below the torso at the model's rest pose: give a stance height");
  }
  b->stride_m = g.stride_m > 0 ? g.stride_m : g.stride_reach * b->reach_m;
  b->step_height_m = g.step_height_m > 0 ? g.step_height_m : g.step_height_reach * b->reach_m;
}

// Starts for the stance's inverse kinematics when the rest pose does not lead there (damped least
// squares is local: it stops where a joint meets its limit or a leg is straight): the middle of
// every joint's range, then draws within the ranges from a fixed seed (the stance is part of the
// robot's description). Unlimited joints span +-pi/2 rad (slides +-reach) about the rest pose.
std::vector<Eigen::VectorXd> StanceStarts(const mjModel* m, const LegChain& leg, const Eigen::VectorXd& rest,
                                          int draws) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::VectorXd> starts;
  for (int s = 0; s <= draws; ++s) {
    Eigen::VectorXd q = rest;
    for (int k = 0; k < q.size(); ++k) {
      const int j = leg.joints[k];
      const double span = m->jnt_type[j] == mjJNT_SLIDE ? leg.reach_m : M_PI / 2;
      const double lo = std::isfinite(leg.q_lo[k]) ? leg.q_lo[k] : q[k] - span;
      const double hi = std::isfinite(leg.q_hi[k]) ? leg.q_hi[k] : q[k] + span;
      q[k] = s == 0 ? 0.5 * (lo + hi) : lo + unit(rng) * (hi - lo);
    }
    starts.push_back(q);
  }
  return starts;
}

// The names of the leg's joints that sit at a limit of their range at q.
std::string JointsAtLimits(const mjModel* m, const LegChain& leg, const Eigen::VectorXd& q) {
  std::string names;
  for (int k = 0; k < q.size(); ++k) {
    const int j = leg.joints[k];
    const double tol = 1e-6 * (1 + std::abs(q[k]));
    if (q[k] > leg.q_lo[k] + tol && q[k] < leg.q_hi[k] - tol) continue;
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    names += (names.empty() ? "" : ", ") + std::string(name ? name : "(unnamed)");
  }
  return names;
}

// Every foot must reach its stance point: inverse kinematics from the rest pose, else from other
// starts (StanceStarts); refused with the joints that end at their limits.
void SolveStance(const mjModel* m, const RobotDescription& r, const std::string& source, LeggedRobot* b) {
  MjDataPtr d = RestPoseData(m, b->torso_qpos);
  for (std::size_t i = 0; i < b->legs.size(); ++i) {
    LegChain& leg = b->legs[i];
    leg.stance_m.z() = -b->stance_height_m;
    const Eigen::Vector3d target = b->robot_in_torso * leg.stance_m;
    const double tolerance = 0.05 * leg.reach_m;
    const Eigen::VectorXd rest = leg.stance_q;
    double residual = SolveLegIk(m, d.get(), leg, target, &leg.stance_q, 200);
    if (residual <= tolerance) continue;
    for (Eigen::VectorXd q : StanceStarts(m, leg, rest, 16)) {
      const double from_here = SolveLegIk(m, d.get(), leg, target, &q, 200, true);
      if (from_here < residual) residual = from_here, leg.stance_q = q;
      if (residual <= tolerance) break;
    }
    if (residual > tolerance) {
      const std::string limits = JointsAtLimits(m, leg, leg.stance_q);
      char what[160];
      std::snprintf(what, sizeof what, "the foot cannot reach the ground %.3g m below the torso (off by %.3g m",
                    b->stance_height_m, residual);
      throw MakeInputError(source, LegPart(static_cast<int>(i), r.legs[i]),
                           what + (limits.empty() ? std::string(")") : "; at their range limits: " + limits + ")") +
                               ": check the joint ranges, or give the model a keyframe with the legs as they stand");
    }
  }
}

// A replay's signals fit its actuators (position targets for servos, forces for the rest), it has
// a standing recording (command [0, 0, 0]) and every recording has a column per actuator.
void BindReplay(const mjModel* m, const RobotDescription& r, const std::string& source, LeggedRobot* b) {
  const ControllerDescription& c = r.controller;
  if (!c.replay()) return;
  std::vector<std::string> names;
  for (int a = 0; a < m->nu; ++a) {
    const char* name = mj_id2name(m, mjOBJ_ACTUATOR, a);
    if (!name) throw MakeInputError(source, "robot.controller", "actuator " + std::to_string(a) + " has no name (a replay's columns name them)");
    names.emplace_back(name);
    if (IsPositionServo(m, a) != (c.signal == "position")) {
      throw MakeInputError(source, "robot.controller.signal",
                           c.signal + " signals, but actuator \"" + name + "\" is " +
                               (IsPositionServo(m, a) ? "a position servo" : "not a position servo"));
    }
  }
  if (m->nu == 0) throw MakeInputError(source, "robot.controller", "the model has no actuators to replay");
  b->stand_recording = FindRecording(c, Eigen::Vector3d::Zero());
  if (b->stand_recording < 0) {
    throw MakeInputError(source, "robot.controller.recordings",
                         "expected a recording of command [0, 0, 0]: the robot stands with it while placed");
  }
  for (const auto& rec : c.recordings) b->replay.push_back(LoadReplayTrack(rec.file, names));
}

}  // namespace

MjDataPtr RestPoseData(const mjModel* m, int torso_qpos) {
  MjDataPtr d(mj_makeData(m));
  if (m->nkey > 0) mju_copy(d->qpos, m->key_qpos, m->nq);
  for (int k = 0; k < 7; ++k) d->qpos[torso_qpos + k] = k == 3 ? 1 : 0;
  return d;
}

Eigen::Vector3d FootPoint(const mjModel* m, const mjData* d, const LegChain& leg) {
  if (leg.foot_site >= 0) return Vec(d->site_xpos + 3 * leg.foot_site);
  if (leg.foot_geom >= 0) return Vec(d->geom_xpos + 3 * leg.foot_geom);
  return Vec(d->xpos + 3 * leg.foot_body) + Mat(d->xmat + 9 * leg.foot_body) * leg.foot_offset_m;
}

namespace {

// dq = J' (J J' + lambda^2 I)^-1 e
Eigen::VectorXd DampedStep(const Eigen::MatrixXd& j, const Eigen::Vector3d& e, double lambda) {
  const Eigen::Matrix3d a = j * j.transpose() + lambda * lambda * Eigen::Matrix3d::Identity();
  return j.transpose() * a.ldlt().solve(e);
}

// Zeroes the Jacobian's columns of joints at a limit that dq pushes further out (they cannot move,
// and the others must not count on them); true when any was.
bool PinLimited(const LegChain& leg, const Eigen::VectorXd& q, const Eigen::VectorXd& dq, Eigen::MatrixXd* j) {
  bool pinned = false;
  for (int k = 0; k < q.size(); ++k) {
    if ((q[k] <= leg.q_lo[k] && dq[k] < 0) || (q[k] >= leg.q_hi[k] && dq[k] > 0)) {
      j->col(k).setZero();
      pinned = true;
    }
  }
  return pinned;
}

}  // namespace

double SolveLegsIk(const mjModel* m, mjData* d, const std::vector<LegChain>& legs,
                   const std::vector<Eigen::Vector3d>& targets, std::vector<Eigen::VectorXd>* q, int iterations,
                   bool limits_pin) {
  std::vector<mjtNum> jacp(3 * m->nv);
  std::vector<bool> done(legs.size(), false);
  double worst = 0;
  for (int it = 0; it <= iterations; ++it) {
    for (std::size_t l = 0; l < legs.size(); ++l) {
      for (std::size_t k = 0; k < legs[l].qpos.size(); ++k) d->qpos[legs[l].qpos[k]] = (*q)[l][k];
    }
    mj_kinematics(m, d);  // one pass for every leg: the chains are independent
    mj_comPos(m, d);
    worst = 0;
    bool all_done = true;
    for (std::size_t l = 0; l < legs.size(); ++l) {
      const LegChain& leg = legs[l];
      const Eigen::Vector3d foot = FootPoint(m, d, leg);
      const Eigen::Vector3d e = targets[l] - foot;
      worst = std::max(worst, e.norm());
      done[l] = e.norm() < 1e-5 * leg.reach_m;
      if (done[l] || it == iterations) continue;
      all_done = false;
      const int n = static_cast<int>(leg.qpos.size());
      mj_jac(m, d, jacp.data(), nullptr, foot.data(), leg.foot_body);
      Eigen::MatrixXd j(3, n);
      for (int k = 0; k < n; ++k) {
        for (int r = 0; r < 3; ++r) j(r, k) = jacp[r * m->nv + leg.dofs[k]];
      }
      const double lambda = 0.02 * std::max(leg.reach_m, 1e-3);
      Eigen::VectorXd dq = DampedStep(j, e, lambda);
      if (limits_pin && PinLimited(leg, (*q)[l], dq, &j)) dq = DampedStep(j, e, lambda);
      const double max_step = 0.3;  // rad (or m for slides) per iteration
      if (dq.cwiseAbs().maxCoeff() > max_step) dq *= max_step / dq.cwiseAbs().maxCoeff();
      for (int k = 0; k < n; ++k) {
        double v = (*q)[l][k] + dq[k];
        v = std::clamp(v, leg.q_lo[k], leg.q_hi[k]);
        (*q)[l][k] = v;
      }
    }
    if (all_done) break;
  }
  return worst;
}

double SolveLegIk(const mjModel* m, mjData* d, const LegChain& leg, const Eigen::Vector3d& target,
                  Eigen::VectorXd* q, int iterations, bool limits_pin) {
  std::vector<Eigen::VectorXd> qs = {*q};
  const double residual = SolveLegsIk(m, d, {leg}, {target}, &qs, iterations, limits_pin);
  *q = qs[0];
  return residual;
}

LeggedRobot BindRobot(const mjModel* m, const RobotDescription& r, const std::string& source) {
  LeggedRobot b;
  b.torso_body = Find(m, mjOBJ_BODY, r.torso_body, "body", "robot.torso_body", source);
  const int root = m->body_jntadr[b.torso_body];
  if (root < 0 || m->jnt_type[root] != mjJNT_FREE) {
    throw MakeInputError(source, "robot.torso_body", "the torso body \"" + r.torso_body + "\" needs a free joint");
  }
  b.torso_qpos = m->jnt_qposadr[root];
  b.torso_dof = m->jnt_dofadr[root];
  b.floor_geom = Find(m, mjOBJ_GEOM, r.floor_geom, "geom", "robot.floor_geom", source);
  b.robot_in_torso = RobotFrame(r.forward_axis);
  for (int i = 0; i < static_cast<int>(r.legs.size()); ++i) {
    b.legs.push_back(BindChain(m, r, i, b.torso_body, source));
    b.leg_actuators.insert(b.leg_actuators.end(), b.legs.back().actuators.begin(), b.legs.back().actuators.end());
  }
  CheckEverythingAccounted(m, r, &b, source);
  BindReplay(m, r, source, &b);
  MeasureRest(m, r, source, &b);
  std::vector<LegPlace> places;
  for (const auto& leg : b.legs) places.push_back({leg.side, leg.stance_m.x()});
  b.timing = ResolveGait(r.gait, places, source);
  ChooseLengths(r, &b, source);
  SolveStance(m, r, source, &b);
  return b;
}

namespace {

// MuJoCo's compiler marks a body whose inertial frame is its own frame (body_sameframe), and its
// geoms and sites sitting at the body's origin (1) or its centre of mass (2), and positions them by
// copying instead of from body_ipos: after the centre of mass moved, kinematics must read it, and
// what sat at the old centre must stay where it is on the body (geom_pos and site_pos are in the
// body's frame either way).
void UseTheInertialFrame(mjModel* m, int body) {
  m->body_sameframe[body] = 0;
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_bodyid[g] == body && m->geom_sameframe[g] == 2) m->geom_sameframe[g] = 0;
  }
  for (int s = 0; s < m->nsite; ++s) {
    if (m->site_bodyid[s] == body && m->site_sameframe[s] == 2) m->site_sameframe[s] = 0;
  }
  if (!m->body_simple[body]) return;
  m->body_simple[body] = 0;  // a simple body has a diagonal mass matrix at its own origin
  for (int i = m->nv - 1, run = 0; i >= 0; --i) {
    m->dof_simplenum[i] = m->body_simple[m->dof_bodyid[i]] ? ++run : (run = 0);
  }
}

}  // namespace

// The payload is a solid ball of radius 0.1 x the longest leg's reach (a compact block whatever the
// robot's size) at p in the torso's frame, merged into the torso's mass, centre and inertia: about
// the new centre c, in the body's frame (R the inertial frame's rotation, D its principal moments),
//   I = R D R^T + m0 (|c0-c|^2 1 - (c0-c)(c0-c)^T) + m (|p-c|^2 1 - (p-c)(p-c)^T + 0.4 r^2 1),
// whose principal axes become the body's inertial frame (mju_eig3, as MuJoCo's compiler turns a
// fullinertia into one). A tensor that stays diagonal in the inertial frame keeps its axes as they were.
void AddPayload(mjModel* m, int torso, const Eigen::Vector3d& p, double mass, double reach_m) {
  using Matrix3 = Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>;  // MuJoCo's layout
  const double m0 = m->body_mass[torso];
  const Eigen::Vector3d c0(m->body_ipos[3 * torso], m->body_ipos[3 * torso + 1], m->body_ipos[3 * torso + 2]);
  const Eigen::Vector3d c = (m0 * c0 + mass * p) / (m0 + mass);
  const double kRadius = 0.1 * reach_m;
  auto moved = [](double kg, const Eigen::Vector3d& d) -> Matrix3 {
    return kg * (d.squaredNorm() * Matrix3::Identity() - d * d.transpose());
  };
  Matrix3 rotation;
  mju_quat2Mat(rotation.data(), m->body_iquat + 4 * torso);
  const Eigen::Vector3d principal(m->body_inertia + 3 * torso);
  const Matrix3 added = moved(m0, c0 - c) + moved(mass, p - c) + 0.4 * mass * kRadius * kRadius * Matrix3::Identity();
  const Matrix3 in_frame = principal.asDiagonal().toDenseMatrix() + rotation.transpose() * added * rotation;
  const bool diagonal = (in_frame - Matrix3(in_frame.diagonal().asDiagonal())).isZero(0);
  if (diagonal) {
    for (int k = 0; k < 3; ++k) m->body_inertia[3 * torso + k] = in_frame(k, k);
  } else {
    const Matrix3 full = rotation * in_frame * rotation.transpose();
    Matrix3 axes;
    mju_eig3(m->body_inertia + 3 * torso, axes.data(), m->body_iquat + 4 * torso, full.data());
  }
  for (int k = 0; k < 3; ++k) m->body_ipos[3 * torso + k] = c[k];
  m->body_mass[torso] = m0 + mass;
  UseTheInertialFrame(m, torso);
}

namespace {

// The payload against the robot's own scale (the config's check is only for finite numbers).
void CheckPayload(const PayloadConfig& p, const LeggedRobot& b, const mjModel* m, const std::string& source) {
  const double robot_kg = mj_getTotalmass(m);
  char what[160];
  if (p.mass_kg > 10 * robot_kg) {
    std::snprintf(what, sizeof what, "%.4g kg is over 10 times the robot's mass (%.4g kg)", p.mass_kg, robot_kg);
    throw MakeInputError(source, "payload.mass_kg", what);
  }
  const double distance = p.position_body_m.norm();
  if (p.mass_kg > 0 && distance > 2 * b.reach_m) {
    std::snprintf(what, sizeof what, "%.4g m from the torso, expected within 2 leg reaches (%.4g m)", distance,
                  2 * b.reach_m);
    throw MakeInputError(source, "payload.position_body_m", what);
  }
}

}  // namespace

void ApplyExperiment(const SimConfig& config, const LeggedRobot& b, mjModel* m, const std::string& source) {
  const RobotDescription& r = *config.robot;
  CheckPayload(config.payload, b, m, source);
  m->opt.timestep = config.timestep_s;
  const double g = Eigen::Vector3d(m->opt.gravity[0], m->opt.gravity[1], m->opt.gravity[2]).norm();
  const double slope = config.slope_deg * M_PI / 180;
  m->opt.gravity[0] = -g * std::sin(slope);  // the slope frame: downhill is -x
  m->opt.gravity[1] = 0;
  m->opt.gravity[2] = -g * std::cos(slope);
  for (const auto& leg : b.legs) {
    const auto it = r.leg_gain.find(leg.name);
    if (it == r.leg_gain.end() || it->second == 1.0) continue;
    for (int a : leg.actuators) {
      m->actuator_gainprm[mjNGAIN * a] *= it->second;
      m->actuator_biasprm[mjNBIAS * a + 1] *= it->second;
    }
  }
  if (config.payload.mass_kg > 0) {
    AddPayload(m, b.torso_body, b.robot_in_torso * config.payload.position_body_m, config.payload.mass_kg,
               b.reach_m);
  }
  if (r.overwrite_physics) {
    for (int i = 0; i < m->ngeom; ++i) {
      m->geom_friction[3 * i + 0] = config.friction.sliding;
      m->geom_friction[3 * i + 1] = config.friction.torsional;
      m->geom_friction[3 * i + 2] = config.friction.rolling;
    }
  }
}

bool IsDescendant(const mjModel* m, int body, int ancestor) {
  for (int b = body; b > 0; b = m->body_parentid[b]) {
    if (b == ancestor) return true;
  }
  return ancestor == 0;
}

int ActuatorOf(const mjModel* m, int joint) {
  for (int a = 0; a < m->nu; ++a) {
    if (m->actuator_trntype[a] == mjTRN_JOINT && m->actuator_trnid[2 * a] == joint) return a;
  }
  return -1;
}

Eigen::Matrix3d RobotFrame(const Eigen::Vector3d& forward) {
  Eigen::Matrix3d r;
  r.col(0) = forward.normalized();
  r.col(2) = Eigen::Vector3d::UnitZ();
  r.col(1) = r.col(2).cross(r.col(0));
  return r;
}

int FootSide(const Eigen::Matrix3d& robot_in_torso, const Eigen::Vector3d& foot) {
  return (robot_in_torso.transpose() * foot).y() >= 0 ? 1 : -1;
}

double ServoStiffness(const mjModel* m, int a) {
  const double gear = m->actuator_gear[6 * a];
  return -m->actuator_biasprm[mjNBIAS * a + 1] * gear * gear;
}

bool IsPositionServo(const mjModel* m, int a) {
  return m->actuator_gaintype[a] == mjGAIN_FIXED && m->actuator_biastype[a] == mjBIAS_AFFINE &&
         m->actuator_biasprm[mjNBIAS * a + 1] < 0;
}

}  // namespace dgmm::sim
