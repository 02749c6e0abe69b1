#include "sim/gait_reach.h"

#include <algorithm>
#include <cstdio>
#include <set>

#include "sim/gait_table.h"

namespace dgmm::sim {

Eigen::Vector2d FootTravel(const LeggedRobot& robot, const LegChain& leg, const Eigen::Vector3d& c, double turn_rad) {
  const Eigen::Vector2d p = leg.stance_m.head<2>();
  return robot.timing.duty *
         (robot.stride_m * Eigen::Vector2d(c.x(), c.y()) + turn_rad * c.z() * Eigen::Vector2d(-p.y(), p.x()));
}

std::vector<GaitMiss> MeasureGaitMisses(const mjModel* m, const LeggedRobot& robot, double turn_rad, int phases) {
  MjDataPtr d = RestPoseData(m, robot.torso_qpos);
  std::vector<GaitMiss> out;
  for (int axis = 0; axis < 3; ++axis) {
    for (double sign : {1.0, -1.0}) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      c[axis] = sign;
      for (std::size_t i = 0; i < robot.legs.size(); ++i) {
        const LegChain& leg = robot.legs[i];
        const Eigen::Vector2d travel = FootTravel(robot, leg, c, turn_rad);
        GaitMiss miss{c, static_cast<int>(i), 0, travel.norm()};
        Eigen::VectorXd q = leg.stance_q;
        for (int s = 0; s < phases; ++s) {
          const Eigen::Vector3d offset =
              FootOffset(static_cast<double>(s) / phases, robot.timing.duty, travel, robot.step_height_m);
          const Eigen::Vector3d target = robot.robot_in_torso * (leg.stance_m + offset);
          miss.residual_m = std::max(miss.residual_m, SolveLegIk(m, d.get(), leg, target, &q, 100));
        }
        out.push_back(miss);
      }
    }
  }
  return out;
}

namespace {

std::string CommandText(const Eigen::Vector3d& c) {
  static const char* kNames[] = {"forward", "lateral", "turn"};
  for (int axis = 0; axis < 3; ++axis) {
    if (c[axis] != 0) return std::string(kNames[axis]) + (c[axis] > 0 ? " +" : " -");
  }
  return "stand";
}

}  // namespace

std::vector<std::string> GaitReachWarnings(const std::vector<GaitMiss>& misses, const LeggedRobot& robot,
                                           double share) {
  std::vector<std::string> commands;
  std::set<std::string> legs;
  const GaitMiss* worst = nullptr;
  for (const GaitMiss& miss : misses) {
    if (!(miss.travel_m > 0) || miss.residual_m <= share * miss.travel_m) continue;
    const std::string text = CommandText(miss.command);
    if (std::find(commands.begin(), commands.end(), text) == commands.end()) commands.push_back(text);
    legs.insert(robot.legs[miss.leg].name);
    if (!worst || miss.residual_m / miss.travel_m > worst->residual_m / worst->travel_m) worst = &miss;
  }
  if (!worst) return {};
  std::string command_list, leg_list;
  for (const std::string& c : commands) command_list += (command_list.empty() ? "" : ", ") + c;
  for (const std::string& l : legs) leg_list += (leg_list.empty() ? "" : ", ") + l;
  char worst_text[160];
  std::snprintf(worst_text, sizeof worst_text, "up to %.3g m, %.0f%% of its travel per step (leg %s, %s at full scale)",
                worst->residual_m, 100 * worst->residual_m / worst->travel_m, robot.legs[worst->leg].name.c_str(),
                CommandText(worst->command).c_str());
  return {"robot.gait: the legs' joints cannot make the steps of some commands (" + command_list + "; legs " +
          leg_list + "): a foot misses its target by " + worst_text +
          ", so those commands will travel less than commanded. A leg moving in one plane only needs a sideways "
          "joint to step sideways or turn; check the joint ranges, or shorten the steps (robot.gait.stride_reach, "
          "turn_rad)"};
}

}  // namespace dgmm::sim
