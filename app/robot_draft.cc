// `dgmm robot-draft`: a first simulation config with a `robot` block for an MJCF nobody has
// described yet (lib/sim/robot_draft.h), bound as `dgmm simulate` would bind it.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/command.h"
#include "sim/robot_draft.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/output_guard.h"

namespace dgmm::app {
namespace {

namespace fs = std::filesystem;

struct RobotDraftArgs {
  std::string mjcf, output;
  std::vector<double> forward_axis{1, 0, 0};
  double foot_band = sim::RobotDraftOptions{}.foot_band;
};

// The config: the MJCF's path relative to the config's folder (as `dgmm simulate` reads it), what
// the experiment sets (flat ground, the model's own timestep, commands of three gait cycles) and
// the drafted block.
std::string ConfigText(const RobotDraftArgs& args, const sim::RobotDraft& draft) {
  const fs::path parent = fs::path(args.output).parent_path();
  const fs::path folder = parent.empty() ? fs::current_path() : fs::absolute(parent);
  const nlohmann::json config = {{"mjcf_path", fs::absolute(args.mjcf).lexically_normal().lexically_relative(folder)},
                                 {"slope_deg", 0.0},
                                 {"timestep_s", draft.timestep_s},
                                 {"command_duration_s", std::round(3e6 * draft.robot.gait.period_s) / 1e6},
                                 {"settle_duration_s", 0.5},
                                 {"robot", nlohmann::json::parse(sim::RobotDescriptionToJson(draft.robot))}};
  return config.dump(2) + "\n";
}

void Run(const RobotDraftArgs& args) {
  if (args.forward_axis.size() != 3) throw MakeInputError("", "--forward-axis", "three numbers x,y,z expected");
  if (!args.output.empty()) {
    RefuseOutputThatIsAnInput(args.output, {args.mjcf});
    AtomicFile probe(args.output);  // fail before the work when unwritable
  }
  sim::RobotDraftOptions options;
  options.forward_axis = Eigen::Vector3d(args.forward_axis[0], args.forward_axis[1], args.forward_axis[2]);
  options.foot_band = args.foot_band;
  const sim::RobotDraft draft = sim::DraftRobot(args.mjcf, options);
  for (const auto& note : draft.notes) Warn(args.mjcf + ": " + note);
  const std::string text = ConfigText(args, draft);
  if (args.output.empty()) {
    std::cout << text;
  } else {
    AtomicFile file(args.output);
    std::ofstream(file.temp_path()) << text;
    file.Commit();
  }
  std::string legs;
  for (const auto& leg : draft.robot.legs) legs += (legs.empty() ? "" : ", ") + leg.name + " (" + leg.side + ")";
  std::fprintf(stderr, "%s: %s, torso %s, floor %s; %s\n", args.mjcf.c_str(),
               Plural(static_cast<long long>(draft.robot.legs.size()), "leg").c_str(), draft.robot.torso_body.c_str(),
               draft.robot.floor_geom.c_str(), legs.c_str());
  if (draft.bind_error.empty()) {
    std::fprintf(stderr, "the draft binds as dgmm simulate binds it%s%s\n", args.output.empty() ? "" : ": dgmm simulate --config ",
                 args.output.c_str());
  } else {
    Warn("the draft does not bind yet, edit it: " + draft.bind_error);
  }
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<RobotDraftArgs>();
  CLI::App* cmd = root.add_subcommand(
      "robot-draft",
      "Draft a simulation config with a robot block for your MJCF (docs/simulation.md, \"Bring your own robot\"): "
      "the torso is the body with the free joint, the floor the named plane on the world body, a leg each jointed "
      "branch below the torso whose lowest geom stands on the ground at the rest pose (its driven joints torso to "
      "foot, undriven ones passive, named by their joints' common prefix, side from the geometry; a branch carrying "
      "legs on both sides is a body segment, its joints held when driven). The draft is "
      "bound as dgmm simulate binds it and what it lacks is said; read it before you trust it.");
  cmd->add_option("mjcf", args->mjcf, "the robot's MJCF (a scene with a floor, or the robot with one)")->required();
  cmd->add_option("-o,--output", args->output, "config to write (JSON; default: stdout)");
  cmd->add_option("--forward-axis", args->forward_axis, "the robot's forward direction in the torso frame (x,y,z)")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--foot-band", args->foot_band,
                  "a branch is a leg when its lowest point is within this share of the torso-to-ground depth of the "
                  "lowest branch")
      ->capture_default_str();
  cmd->callback([args] { Run(*args); });
}

}  // namespace

DGMM_REGISTER_COMMAND("robot-draft", Setup);

}  // namespace dgmm::app
