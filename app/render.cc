// `dgmm render`: density heat maps of a model (PNG, VTK offscreen) and, with --diff, the
// three-panel comparison of two models laid out like Figure 3 of Edgington et al.
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/command.h"
#include "app/figure_options.h"
#include "core/mise.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "render/density_grid.h"
#include "render/display.h"
#include "render/heat_map.h"
#include "render/model_slice.h"
#include "render/slice_figure.h"
#include "util/error.h"
#include "util/output_guard.h"

namespace dgmm::app {
namespace {

struct RenderArgs {
  std::vector<std::string> models;
  std::string output;
  bool diff = false;
  SliceSpec slice;
  std::vector<std::string> conditions;
  std::string data;
  int contours = 6;
  std::string size = "800x640";
  int grid = 200;
  std::string title;
  std::string labels;
  std::string window;
  std::string color_scale = "auto";
  bool json = false;
};

nlohmann::json LayoutJson(const PlotLayout& l) {
  const char* scales[] = {"linear", "log", "quantile", "auto"};
  return {{"range", {l.range.x_min, l.range.x_max, l.range.y_min, l.range.y_max}},
          {"color_range", {l.color_min, l.color_max}},
          {"color_scale", scales[static_cast<int>(l.color_scale)]},
          {"axis_titles", {l.x_title, l.y_title}},
          {"plot_area_px", {{"left", l.left}, {"bottom", l.bottom}, {"right", l.right},
                            {"top", l.top}}}};
}

nlohmann::json ModeJson(const Mixture& mixture, const PlotLayout& layout) {
  Mixture::Mode mode = mixture.MaxDensity();
  Eigen::Vector2d px = layout.ToPixel(mode.x(0), mode.x(1));
  return {{"x", mode.x(0)}, {"y", mode.x(1)}, {"density", std::exp(mode.log_density)},
          {"pixel", {px(0), px(1)}}};
}

// "A,B" -> {"A", "B"}; InputError naming --labels unless exactly two non-empty names.
std::vector<std::string> ParseLabels(const std::string& text) {
  const size_t comma = text.find(',');
  if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos ||
      comma == 0 || comma + 1 == text.size()) {
    throw MakeInputError("", "--labels",
                         "expected two names separated by one comma, e.g. --labels \"EM,DGMM\" "
                         "(got '" + text + "')");
  }
  return {text.substr(0, comma), text.substr(comma + 1)};
}

void Run(const RenderArgs& args) {
  if (args.models.size() > 2 && !args.labels.empty()) {
    throw MakeInputError("", "--labels", "takes one value \"A,B\" (comma-separated), not two "
                                         "space-separated names");
  }
  if (!args.labels.empty()) ParseLabels(args.labels);
  ParseColorScale(args.color_scale);
  // Before any VTK call: a missing display is one clear line, never a crash.
  std::vector<std::string> inputs = args.models;
  if (!args.data.empty()) inputs.push_back(args.data);
  RefuseOutputThatIsAnInput(args.output, inputs);
  RequireDisplay();
  if (args.diff != (args.models.size() == 2)) {
    throw MakeInputError("", "models", args.diff ? "--diff needs exactly two model files"
                                                 : "give one model file (or two with --diff)");
  }
  if (args.contours < 0 || args.contours > 50) {
    throw MakeInputError("", "--contours", "must be between 0 and 50");
  }
  if (args.grid < 10 || args.grid > 2000) {
    throw MakeInputError("", "--grid", "must be between 10 and 2000");
  }
  auto [width, height] = ParseSize(args.size);
  SliceSpec spec = args.slice;
  spec.conditions = ParseConditions(args.conditions);

  std::vector<MotionModel> models;
  std::vector<ModelSlice> slices;
  for (const std::string& path : args.models) {
    models.push_back(ReadModel(path));
    slices.push_back(SliceModel(models.back(), spec, path));
  }
  if (args.diff && slices[0].mixture.dim() != slices[1].mixture.dim()) {
    throw MakeInputError(args.models[1], "dimensions", "differs from " + args.models[0]);
  }
  Eigen::MatrixX2d points(0, 2);
  if (!args.data.empty()) {
    SampleSet set = ReadSampleSet(args.data);
    points = SlicePoints(set, slices[0].command, slices[0].x_index, slices[0].y_index);
  }
  std::vector<const ModelSlice*> slice_ptrs;
  std::vector<const Mixture*> mixtures;
  std::vector<SliceSource> sources;
  for (size_t i = 0; i < slices.size(); ++i) {
    slice_ptrs.push_back(&slices[i]);
    mixtures.push_back(&slices[i].mixture);
    sources.push_back({models[i].kind, args.models[i]});
  }
  const PlotRange range =
      args.window.empty() ? SliceWindow(mixtures, points) : ParseWindow(args.window);
  if (!range.IsValid()) throw MakeInputError(args.models[0], "", "cannot find a plot window");

  SliceFigureOptions figure;
  figure.contours = args.contours;
  figure.grid = args.grid;
  figure.width = width;
  figure.height = height;
  figure.title = args.title;
  figure.labels = args.labels.empty() ? std::vector<std::string>{} : ParseLabels(args.labels);
  figure.color_scale = ParseColorScale(args.color_scale);
  const std::vector<HeatMapSpec> panels = SliceHeatMaps(slice_ptrs, sources, points, range, figure);
  nlohmann::json report = {{"output", args.output}, {"width", width}, {"height", height}};
  if (!args.diff) {
    PlotLayout layout = RenderHeatMap(panels[0], args.output);
    report["panels"] = {LayoutJson(layout)};
    report["panels"][0]["mode"] = ModeJson(slices[0].mixture, layout);
    report["description"] = slices[0].description;
  } else {
    std::vector<PlotLayout> layouts = RenderHeatMapRow(panels, args.output);
    report["width"] = layouts.front().width;
    for (int i = 0; i < 3; ++i) report["panels"].push_back(LayoutJson(layouts[i]));
    for (int i = 0; i < 2; ++i) report["panels"][i]["mode"] = ModeJson(slices[i].mixture, layouts[i]);
    report["description"] = slices[0].description;
    report["ise_of_slices"] = IntegratedSquaredError(slices[0].mixture, slices[1].mixture);
  }
  if (args.json) {
    std::cout << report.dump(2) << "\n";
  } else {
    std::cout << "wrote " << args.output << " (" << report["width"].get<int>() << "x" << height
              << "): " << report["description"].get<std::string>() << "\n";
  }
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<RenderArgs>();
  CLI::App* cmd = root.add_subcommand(
      "render",
      "Density heat map of a model as PNG (or, with --diff, model A, model B and their "
      "difference side by side). Needs an X display: run under `xvfb-run -a`.");
  cmd->add_option("models", args->models, "model file (two with --diff)")
      ->required()
      ->expected(1, -1);
  cmd->add_option("-o,--output", args->output, "PNG to write")->required();
  cmd->add_flag("--diff", args->diff, "compare two models: A, B and A - B (like Figure 3)");
  cmd->add_option("--command", args->slice.command, "command id or label (default: the only one)");
  cmd->add_option("--x-dim", args->slice.x_dim, "dimension on the x axis (default: the first)");
  cmd->add_option("--y-dim", args->slice.y_dim, "dimension on the y axis (default: the second)");
  cmd->add_option("--condition", args->conditions,
                  "name=value (raw units): condition on a dimension, e.g. pitch=0.1 (repeatable)");
  cmd->add_flag("--marginalise,--marginalize", args->slice.marginalise,
                "integrate out dimensions that are neither shown nor conditioned");
  cmd->add_option("--data", args->data, "sample set whose points are overlaid")
      ->check(CLI::ExistingFile);
  cmd->add_option("--contours", args->contours, "number of contour lines (0: none)")
      ->capture_default_str();
  cmd->add_option("--size", args->size, "WIDTHxHEIGHT of the image (of each panel with --diff)")
      ->capture_default_str();
  cmd->add_option("--grid", args->grid, "grid points per axis")->capture_default_str();
  cmd->add_option("--window", args->window,
                  "x_min,x_max,y_min,y_max: the plot window (default: the slices and the data)");
  cmd->add_option("--title", args->title, "title (default: what is shown)");
  cmd->add_option("--labels", args->labels,
                  "names of models A and B for --diff, comma-separated: \"A,B\"");
  cmd->add_option("--color-scale", args->color_scale,
                  "linear, log, quantile or auto (log when the bright part covers < 10% of the "
                  "window, e.g. a peaked model)")
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "print output, plot windows, pixel layout and modes as JSON");
  cmd->callback([args] { Run(*args); });
}

}  // namespace

DGMM_REGISTER_COMMAND("render", Setup);

}  // namespace dgmm::app
