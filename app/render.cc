// `dgmm render`: density heat maps of a model (PNG, VTK offscreen) and, with --diff, the
// three-panel comparison of two models laid out like Figure 3 of Edgington et al.
#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/command.h"
#include "core/mise.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "render/density_grid.h"
#include "render/display.h"
#include "render/heat_map.h"
#include "render/model_slice.h"
#include "util/error.h"

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
  std::string color_scale = "auto";
  bool json = false;
};

std::pair<int, int> ParseSize(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X')) {
    throw MakeInputError("", "--size", "expected WIDTHxHEIGHT, got '" + text + "'");
  }
  return {w, h};
}

std::vector<std::pair<std::string, double>> ParseConditions(const std::vector<std::string>& in) {
  std::vector<std::pair<std::string, double>> out;
  for (const std::string& c : in) {
    auto eq = c.find('=');
    size_t used = 0;
    double value = 0;
    bool ok = eq != std::string::npos && eq > 0;
    if (ok) {
      try {
        value = std::stod(c.substr(eq + 1), &used);
        ok = used == c.size() - eq - 1;
      } catch (const std::exception&) {
        ok = false;
      }
    }
    if (!ok) throw MakeInputError("", "--condition", "expected name=value, got '" + c + "'");
    out.emplace_back(c.substr(0, eq), value);
  }
  return out;
}

std::string Basename(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

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
  const HeatMapSpec::ColorScale color_scale = ParseColorScale(args.color_scale);
  std::vector<const Mixture*> mixtures;
  for (const auto& s : slices) mixtures.push_back(&s.mixture);
  const PlotRange range = ExtentRange(mixtures, points);
  if (!range.IsValid()) throw MakeInputError(args.models[0], "", "cannot find a plot window");

  nlohmann::json report = {{"output", args.output}, {"width", width}, {"height", height}};
  if (!args.diff) {
    const ModelSlice& s = slices[0];
    HeatMapSpec map;
    map.background = MixtureDensityGrid(s.mixture, range, args.grid, args.grid);
    if (args.contours > 0) map.contours.push_back({map.background, args.contours, {200, 200, 200}});
    map.points = points;
    map.color_scale = color_scale;
    map.title = args.title.empty() ? fmt::format("{} model {}: {}", models[0].kind,
                                                 Basename(args.models[0]), s.description)
                                   : args.title;
    map.x_label = s.x_label;
    map.y_label = s.y_label;
    map.width = width;
    map.height = height;
    PlotLayout layout = RenderHeatMap(map, args.output);
    report["panels"] = {LayoutJson(layout)};
    report["panels"][0]["mode"] = ModeJson(s.mixture, layout);
    report["description"] = s.description;
  } else {
    std::vector<std::string> labels;
    if (!args.labels.empty()) labels = ParseLabels(args.labels);
    for (size_t i = labels.size(); i < 2; ++i) {
      labels.push_back(models[i].kind + " " + Basename(args.models[i]));
    }
    std::vector<DensityGrid> grids;
    for (const auto& s : slices) grids.push_back(MixtureDensityGrid(s.mixture, range, args.grid, args.grid));
    std::vector<HeatMapSpec> panels(3);
    const std::array<unsigned char, 3> kA{0, 0, 0}, kB{0, 150, 60}, kGrey{200, 200, 200};
    for (int i = 0; i < 2; ++i) {
      panels[i].background = grids[i];
      if (args.contours > 0) panels[i].contours.push_back({grids[i], args.contours, kGrey});
      panels[i].title = fmt::format("{}: {}", i == 0 ? "A" : "B", labels[i]);
      panels[i].color_scale = color_scale;
    }
    // A and B share one colour scale so equal colours mean equal densities.
    ShareColorScale({&panels[0], &panels[1]});
    HeatMapSpec& d = panels[2];
    d.background = grids[0];
    d.background.values = grids[0].values - grids[1].values;
    d.palette = HeatMapSpec::Palette::kDiverging;
    d.value_label = "A - B (clamped at 99th pct of |A - B|)";
    if (args.contours > 0) {
      d.contours.push_back({grids[0], args.contours, kA, 1.5f, labels[0]});
      d.contours.push_back({grids[1], args.contours, kB, 1.5f, labels[1]});
    }
    d.title = args.title.empty() ? "A - B (red: A higher); contours A black, B green" : args.title;
    for (auto& p : panels) {
      p.points = points;
      p.x_label = slices[0].x_label;
      p.y_label = slices[0].y_label;
      p.width = width;
      p.height = height;
    }
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
