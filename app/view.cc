// `dgmm view`: an interactive window over p(x | c, z): command picker, pose axes, one slider per
// terrain dimension, samples near the chosen terrain, A / B / A - B with --compare, hover
// read-out, component ellipses, PNG export drawn like `dgmm render` (lib/render/viewer.h).
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "app/command.h"
#include "app/figure_options.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "render/display.h"
#include "render/viewer.h"
#include "util/error.h"

namespace dgmm::app {
namespace {

struct ViewArgs {
  std::string model, compare, data;
  std::string command, x_dim, y_dim;
  std::vector<std::string> conditions;
  std::string size;  // default: 800x640, or 560x448 per panel with --compare
  int grid = 200;
  int contours = 6;
  double near = 0.1;
  bool ellipses = false;
  std::string save_prefix = "dgmm-view";
  std::string replay, record, screenshot;
};

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw MakeInputError(path, "", "cannot read the event file");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void Run(const ViewArgs& args) {
  // Before any VTK call: a missing display is one clear line, never a crash.
  RequireDisplay();
  ExplorerInputs inputs;
  inputs.model = ReadModel(args.model);
  inputs.model_file = args.model;
  if (!args.compare.empty()) {
    inputs.compare = ReadModel(args.compare);
    inputs.compare_file = args.compare;
  }
  if (!args.data.empty()) {
    inputs.data = ReadSampleSet(args.data);
    inputs.data_file = args.data;
  }
  ExplorerOptions options;
  auto [width, height] =
      ParseSize(!args.size.empty() ? args.size : args.compare.empty() ? "800x640" : "560x448");
  options.figure.width = width;
  options.figure.height = height;
  options.figure.grid = args.grid;
  options.figure.contours = args.contours;
  options.command = args.command;
  options.x_dim = args.x_dim;
  options.y_dim = args.y_dim;
  options.terrain = ParseConditions(args.conditions);
  options.near_fraction = args.near;
  options.ellipses = args.ellipses;
  const std::string events = args.replay.empty() ? "" : Slurp(args.replay);

  ViewerOptions viewer_options;
  viewer_options.save_prefix = args.save_prefix;
  viewer_options.record_file = args.record;
  viewer_options.on_message = [](const std::string& line) { std::cout << line << std::endl; };
  Viewer viewer(SliceExplorer(std::move(inputs), options), viewer_options);
  if (!args.replay.empty()) viewer.Replay(events);
  if (!args.screenshot.empty()) {
    viewer.SaveWindow(args.screenshot);
    std::cout << "wrote " << args.screenshot << std::endl;
  }
  if (args.replay.empty() && args.screenshot.empty()) viewer.Run();
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App* cmd = root.add_subcommand(
      "view",
      "Interactive window over p(x | c, z): pick a command and two pose dimensions, move one "
      "slider per terrain dimension, hover for the density; s saves the view as `dgmm render` "
      "draws it. Needs an X display. Keys: docs/viewer.md.");
  cmd->add_option("model", args->model, "model file (A)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--compare", args->compare, "second model (B): A, B and A - B side by side")
      ->check(CLI::ExistingFile);
  cmd->add_option("--data", args->data, "sample set: its samples near the chosen terrain are drawn")
      ->check(CLI::ExistingFile);
  cmd->add_option("--command", args->command, "first command shown (id or label)");
  cmd->add_option("--x-dim", args->x_dim, "pose dimension on the x axis (default: the first)");
  cmd->add_option("--y-dim", args->y_dim, "pose dimension on the y axis (default: the second)");
  cmd->add_option("--condition", args->conditions,
                  "name=value (raw units): initial terrain slider value (repeatable)");
  cmd->add_option("--size", args->size,
                  "WIDTHxHEIGHT of each panel (default 800x640; 560x448 with --compare)");
  cmd->add_option("--grid", args->grid, "grid points per axis")->capture_default_str();
  cmd->add_option("--contours", args->contours, "number of contour lines (0: none)")
      ->capture_default_str();
  cmd->add_option("--near", args->near,
                  "samples shown: terrain within this fraction of each slider's span")
      ->capture_default_str();
  cmd->add_flag("--ellipses", args->ellipses, "start with the component ellipses on");
  cmd->add_option("--save-prefix", args->save_prefix, "key s writes PREFIX-<n>.png")
      ->capture_default_str();
  cmd->add_option("--replay", args->replay,
                  "play a recorded event file (vtkInteractorEventRecorder) instead of waiting "
                  "for the user, then exit")
      ->check(CLI::ExistingFile);
  cmd->add_option("--record", args->record, "record the session's events to this file");
  cmd->add_option("--screenshot", args->screenshot,
                  "write the whole window (after --replay, if given) to this PNG, then exit");
  cmd->callback([args] { Run(*args); });
}

}  // namespace

DGMM_REGISTER_COMMAND("view", Setup);

}  // namespace dgmm::app
