// `dgmm sim-pictures`: pictures of the simulated robot (docs/simulation.md): top-view torso
// trajectories for a few commands on flat ground and on the slope (line charts) and a strip of
// 3-D snapshots of the robot walking up the slope (render/robot_view.h). Needs an X display.
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/command.h"
#include "render/chart.h"
#include "render/display.h"
#include "render/robot_view.h"
#include "sim/simulator.h"
#include "util/error.h"

namespace dgmm::app {
namespace {

struct PicturesArgs {
  std::string config_path;
  std::string output_dir;
  int executions = 3;
  bool json = false;
};

struct NamedCommand {
  const char* name;
  Eigen::Vector3d command;
};

const NamedCommand kCommands[] = {
    {"forward (+0.5,0,0)", {0.5, 0, 0}},   {"backward (-0.5,0,0)", {-0.5, 0, 0}},
    {"left (0,+0.5,0)", {0, 0.5, 0}},      {"right (0,-0.5,0)", {0, -0.5, 0}},
    {"turn left (0,0,+0.5)", {0, 0, 0.5}}, {"forward + turn (+0.5,0,+0.5)", {0.5, 0, 0.5}},
};

// Torso xy in the slope frame (x uphill) over `executions` runs, facing uphill from the origin.
LineChartSpec Trajectories(const sim::SimConfig& config, int executions, const std::string& title) {
  LineChartSpec spec;
  spec.title = title;
  spec.x_label = config.slope_deg != 0 ? "x (m, uphill)" : "x (m)";
  spec.y_label = "y (m)";
  spec.markers = false;
  sim::Simulator sim(config);
  for (const auto& c : kCommands) {
    ChartSeries series;
    series.name = c.name;
    sim.Place(0, 0, 0);
    std::vector<sim::Pose> poses{sim.TorsoPose()};
    for (int e = 0; e < executions; ++e) {
      if (sim.RunCommand(c.command, &poses, 25) != sim::RunOutcome::kCompleted) break;
    }
    for (const auto& p : poses) {
      series.x.push_back(p.position_m.x());
      series.y.push_back(p.position_m.y());
    }
    spec.series.push_back(series);
  }
  return spec;
}

ScenePrimitive ToPrimitive(const sim::GeomSnapshot& g, const Eigen::Matrix3d& level,
                           const Eigen::Vector3d& torso) {
  ScenePrimitive p;
  using T = sim::GeomSnapshot::Type;
  switch (g.type) {
    case T::kPlane: p.type = ScenePrimitive::Type::kPlane; break;
    case T::kSphere: p.type = ScenePrimitive::Type::kSphere; break;
    case T::kCapsule: p.type = ScenePrimitive::Type::kCapsule; break;
    case T::kCylinder: p.type = ScenePrimitive::Type::kCylinder; break;
    case T::kHeightField: p.type = ScenePrimitive::Type::kHeightField; break;
    default: p.type = ScenePrimitive::Type::kBox; break;
  }
  p.size = g.size;
  p.position = level * g.position_m;
  p.rotation = level * g.rotation;
  p.rgba = g.rgba;
  p.grid = g.grid;
  p.spacing = g.spacing_m;
  p.heights = g.heights;
  if (g.type == T::kPlane) {  // a 3 m tile under the robot instead of the whole plane
    p.size = Eigen::Vector3d(1.5, 1.5, 0);
    p.position = level * Eigen::Vector3d(torso.x(), torso.y(), 0);
  }
  return p;
}

// Snapshots of a forward walk up the slope, seen from the side (camera on the -y side).
std::vector<SceneView> Snapshots(const sim::SimConfig& config) {
  sim::Simulator sim(config);
  const Eigen::Matrix3d level = sim::SlopeToLevel(config.slope_deg);
  std::vector<SceneView> scenes;
  auto snap = [&](const sim::Simulator& s, const std::string& caption) {
    SceneView view;
    const Eigen::Vector3d torso = s.TorsoPose().position_m;
    for (const auto& g : s.Geometry()) view.primitives.push_back(ToPrimitive(g, level, torso));
    const Eigen::Vector3d focus = level * torso;
    view.camera.focal_point = focus;
    view.camera.position = focus + Eigen::Vector3d(0.3, -1.6, 0.7);
    view.caption = caption;
    scenes.push_back(view);
  };
  sim.Place(0, 0, 0);
  snap(sim, "t = 0 s");
  const int steps_per_snapshot =
      static_cast<int>(std::lround(0.25 * config.gait.period_s / config.timestep_s));
  int taken = 0;
  sim.RunCommand(
      {0.5, 0, 0},
      [&](const sim::Simulator& s) {
        ++taken;
        if (taken <= 4) {
          char caption[64];
          std::snprintf(caption, sizeof(caption), "t = %.3f s", taken * 0.25 * config.gait.period_s);
          snap(s, caption);
        }
      },
      steps_per_snapshot);
  return scenes;
}

void RunPictures(const PicturesArgs& args) {
  sim::SimConfig config =
      args.config_path.empty() ? sim::SimConfig{} : sim::LoadSimConfig(args.config_path);
  if (args.executions < 1 || args.executions > 20) {
    throw MakeInputError("", "--executions", "expected 1..20");
  }
  if (!std::filesystem::is_directory(args.output_dir)) {
    throw MakeInputError(args.output_dir, "", "the output folder does not exist");
  }
  RequireDisplay();
  const std::filesystem::path dir(args.output_dir);
  sim::SimConfig flat = config;
  flat.slope_deg = 0;
  std::vector<std::string> written;
  auto write_chart = [&](const LineChartSpec& spec, const char* name) {
    RenderLineChart(spec, (dir / name).string());
    written.push_back((dir / name).string());
  };
  write_chart(Trajectories(flat, args.executions, "Torso paths on flat ground (top view)"),
              "trajectories_flat.png");
  char title[96];
  std::snprintf(title, sizeof(title), "Torso paths on the %.0f deg slope, facing uphill (top view)",
                config.slope_deg);
  write_chart(Trajectories(config, args.executions, title), "trajectories_slope.png");
  SceneStripOptions strip;
  strip.panel_width = 360;
  strip.panel_height = 300;
  RenderSceneStrip(Snapshots(config), strip, (dir / "snapshots_slope.png").string());
  written.push_back((dir / "snapshots_slope.png").string());
  if (args.json) {
    std::cout << nlohmann::json{{"written", written}}.dump(2) << "\n";
  } else {
    for (const auto& w : written) std::cout << "wrote " << w << "\n";
  }
}

void SetupPictures(CLI::App& root) {
  auto args = std::make_shared<PicturesArgs>();
  CLI::App* cmd = root.add_subcommand(
      "sim-pictures",
      "Draw the simulated robot: top-view paths on flat ground and on the slope, and 3-D "
      "snapshots walking up the slope (PNG; needs an X display, e.g. xvfb-run -a)");
  cmd->add_option("--config", args->config_path, "Simulation config (JSON)");
  cmd->add_option("-o,--output", args->output_dir, "Existing folder for the PNGs")->required();
  cmd->add_option("--executions", args->executions, "Executions per command in the path plots")
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "List the written files as JSON");
  cmd->callback([args] { RunPictures(*args); });
}

}  // namespace

DGMM_REGISTER_COMMAND("sim-pictures", SetupPictures);

}  // namespace dgmm::app
