#include "render/slice_explorer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "util/error.h"

namespace dgmm {
namespace {

std::string Number(double v, const char* format = "%.4g") {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), format, v);
  return buffer;
}

// Exact text of a double for a command line (round-trips).
std::string Exact(double v) { return Number(v, "%.17g"); }

std::string CommandLabel(const MotionModel& model, int id) {
  auto it = model.command_labels.find(id);
  if (it != model.command_labels.end() && !it->second.empty()) return it->second;
  return std::to_string(id);
}

// [min, max] of dimension `dim` of the raw mixture over its components' mean +- 3 sigma
// (components with < 1% of the weight ignored).
void IncludeModelSpan(const Mixture& raw, int dim, double* lo, double* hi) {
  const double total = raw.total_weight();
  for (int c = 0; c < raw.size(); ++c) {
    if (raw.weight(c) < 0.01 * total) continue;
    const double mean = raw.component(c).mean()(dim);
    const double sd = std::sqrt(raw.component(c).covariance()(dim, dim));
    *lo = std::min(*lo, mean - 3 * sd);
    *hi = std::max(*hi, mean + 3 * sd);
  }
}

double MixtureMean(const Mixture& raw, int dim) {
  double sum = 0;
  for (int c = 0; c < raw.size(); ++c) sum += raw.weight(c) * raw.component(c).mean()(dim);
  return raw.size() > 0 ? sum / raw.total_weight() : 0.0;
}

}  // namespace

std::string ExplorerOptions::Validate() const {
  if (figure.grid < 10 || figure.grid > 2000) return "--grid must be between 10 and 2000";
  if (figure.contours < 0 || figure.contours > 50) return "--contours must be between 0 and 50";
  if (figure.width < 200 || figure.height < 150 || figure.width > 4000 || figure.height > 4000) {
    return "--size must be between 200x150 and 4000x4000 pixels per panel";
  }
  if (!(near_fraction > 0 && near_fraction <= 1)) return "--near must be in (0, 1]";
  for (const auto& [name, value] : terrain) {
    if (!std::isfinite(value)) return "terrain value of '" + name + "' is not finite";
  }
  return "";
}

SliceExplorer::SliceExplorer(ExplorerInputs inputs, const ExplorerOptions& options)
    : in_(std::move(inputs)),
      figure_(options.figure),
      ellipses_(options.ellipses),
      near_fraction_(options.near_fraction) {
  if (std::string problem = options.Validate(); !problem.empty()) {
    throw MakeInputError("", "options", problem);
  }
  const MotionModel& a = in_.model;
  if (a.mixtures.empty()) throw MakeInputError(in_.model_file, "commands", "the model has none");
  if (a.pose_dim < 2) {
    throw MakeInputError(in_.model_file, "pose_dim",
                         "the viewer shows two pose dimensions; the model has " +
                             std::to_string(a.pose_dim));
  }
  ListCommands();
  PickCommandAndAxes(options);
  MakeSliders(options);
  Update();
}

void SliceExplorer::ListCommands() {
  const MotionModel& a = in_.model;
  names_ = DimensionNames(a);
  if (in_.compare && DimensionNames(*in_.compare) != names_) {
    throw MakeInputError(in_.compare_file, "dimensions",
                         "differ from those of " + in_.model_file);
  }
  for (const auto& [id, mixture] : a.mixtures) {
    const std::string label = CommandLabel(a, id);
    if (in_.compare) {
      try {
        ResolveCommand(*in_.compare, label, in_.compare_file);
      } catch (const InputError&) {
        continue;  // shown only when both models have it
      }
    }
    command_ids_.push_back(id);
    command_labels_.push_back(label);
  }
  if (command_ids_.empty()) {
    throw MakeInputError(in_.compare_file, "commands", "no command in common with " +
                                                           in_.model_file);
  }
  if (in_.data && in_.data->pose_dim() + in_.data->terrain_dim() != a.dim()) {
    throw MakeInputError(in_.data_file, "dimensions",
                         "expected " + std::to_string(a.pose_dim) + " pose + " +
                             std::to_string(a.terrain_dim) + " terrain dimensions like the model");
  }
}

void SliceExplorer::PickCommandAndAxes(const ExplorerOptions& options) {
  const MotionModel& a = in_.model;
  if (!options.command.empty()) {
    const int id = ResolveCommand(a, options.command, in_.model_file);
    auto it = std::find(command_ids_.begin(), command_ids_.end(), id);
    if (it == command_ids_.end()) {
      throw MakeInputError(in_.compare_file, "command", "has no command '" + options.command + "'");
    }
    command_index_ = static_cast<int>(it - command_ids_.begin());
  }
  auto pose_index = [&](const std::string& name, int fallback) {
    if (name.empty()) return fallback;
    auto it = std::find(names_.begin(), names_.begin() + a.pose_dim, name);
    if (it == names_.begin() + a.pose_dim) {
      throw MakeInputError(in_.model_file, "dimension", "'" + name + "' is not a pose dimension");
    }
    return static_cast<int>(it - names_.begin());
  };
  x_index_ = pose_index(options.x_dim, 0);
  y_index_ = pose_index(options.y_dim, x_index_ == 0 ? 1 : 0);
  if (x_index_ == y_index_) throw MakeInputError("", "dimension", "x and y must differ");
}

void SliceExplorer::MakeSliders(const ExplorerOptions& options) {
  const MotionModel& a = in_.model;
  // Slider spans: the data's terrain when given, else the model's 3-sigma extent.
  const Mixture first = RawMixture(a, command_ids_[command_index_]);
  std::vector<Mixture> raws;
  for (int id : command_ids_) raws.push_back(RawMixture(a, id));
  for (int t = 0; t < a.terrain_dim; ++t) {
    const int dim = a.pose_dim + t;
    TerrainSlider slider;
    slider.name = names_[dim];
    double lo = INFINITY, hi = -INFINITY;
    if (in_.data) {
      for (int id : command_ids_) {
        const Eigen::MatrixXd samples = RawSamples(*in_.data, id);
        if (samples.rows() == 0) continue;
        lo = std::min(lo, samples.col(dim).minCoeff());
        hi = std::max(hi, samples.col(dim).maxCoeff());
      }
    }
    if (!(lo < hi)) {
      for (const Mixture& raw : raws) IncludeModelSpan(raw, dim, &lo, &hi);
    }
    if (!std::isfinite(lo) || !std::isfinite(hi)) lo = hi = 0;
    if (!(lo < hi)) {  // a constant terrain: a span relative to its magnitude
      const double pad = std::max(1e-3, 0.1 * std::abs(lo));
      lo -= pad;
      hi += pad;
    }
    slider.min = lo;
    slider.max = hi;
    slider.value = std::clamp(MixtureMean(first, dim), lo, hi);
    terrain_.push_back(slider);
  }
  for (const auto& [name, value] : options.terrain) {
    auto it = std::find_if(terrain_.begin(), terrain_.end(),
                           [&](const TerrainSlider& s) { return s.name == name; });
    if (it == terrain_.end()) {
      throw MakeInputError(in_.model_file, "condition", "'" + name + "' is not a terrain dimension");
    }
    // A value outside the span widens it: the user's condition is kept exactly.
    it->min = std::min(it->min, value);
    it->max = std::max(it->max, value);
    it->value = value;
  }
}

void SliceExplorer::StepCommand(int step) {
  const int n = static_cast<int>(command_ids_.size());
  command_index_ = ((command_index_ + step) % n + n) % n;
  Update();
}

bool SliceExplorer::PickCommand(const std::string& text) {
  if (text.empty()) return false;
  int found = -1;
  for (size_t i = 0; i < command_labels_.size() && found < 0; ++i) {
    if (command_labels_[i] == text) found = static_cast<int>(i);
  }
  for (size_t i = 0; i < command_labels_.size() && found < 0; ++i) {
    if (command_labels_[i].rfind(text, 0) == 0) found = static_cast<int>(i);
  }
  if (found < 0) return false;
  command_index_ = found;
  Update();
  return true;
}

void SliceExplorer::StepX(int step) {
  const int n = in_.model.pose_dim;
  const int next = ((x_index_ + step) % n + n) % n;
  if (next == y_index_) y_index_ = x_index_;  // the axes swap
  x_index_ = next;
  Update();
}

void SliceExplorer::StepY(int step) {
  const int n = in_.model.pose_dim;
  const int next = ((y_index_ + step) % n + n) % n;
  if (next == x_index_) x_index_ = y_index_;
  y_index_ = next;
  Update();
}

void SliceExplorer::SetTerrain(int i, double value) {
  TerrainSlider& s = terrain_.at(static_cast<size_t>(i));
  if (!std::isfinite(value)) return;
  if (!locked_window_) {
    locked_window_ = window();
    held_by_terrain_ = true;
  }
  s.value = std::clamp(value, s.min, s.max);
  Update(/*keep_window=*/true);
}

void SliceExplorer::ToggleConditioned() {
  conditioned_ = !conditioned_;
  Update();
}

void SliceExplorer::ScaleNearFraction(double factor) {
  near_fraction_ = std::clamp(near_fraction_ * factor, 0.01, 1.0);
  Update(/*keep_window=*/true);
}

PlotRange SliceExplorer::window() const {
  if (locked_window_) return *locked_window_;
  std::vector<const Mixture*> mixtures;
  for (const ModelSlice& s : slices_) mixtures.push_back(&s.mixture);
  return SliceWindow(mixtures, points_);
}

void SliceExplorer::Zoom(double factor, double x, double y) {
  const PlotRange w = window();
  if (!(factor > 0) || !std::isfinite(x) || !std::isfinite(y)) return;
  PlotRange z{x + (w.x_min - x) * factor, x + (w.x_max - x) * factor,
              y + (w.y_min - y) * factor, y + (w.y_max - y) * factor};
  if (z.IsValid()) {
    locked_window_ = z;
    held_by_terrain_ = false;
  }
}

void SliceExplorer::Pan(double fx, double fy) {
  PlotRange w = window();
  const double dx = fx * (w.x_max - w.x_min), dy = fy * (w.y_max - w.y_min);
  locked_window_ = PlotRange{w.x_min + dx, w.x_max + dx, w.y_min + dy, w.y_max + dy};
  held_by_terrain_ = false;
}

void SliceExplorer::Update(bool keep_window) {
  if (held_by_terrain_ && !keep_window) ResetWindow();
  SliceSpec spec;
  spec.command = command_labels_[command_index_];
  spec.x_dim = names_[x_index_];
  spec.y_dim = names_[y_index_];
  spec.marginalise = true;
  if (conditioned_) {
    for (const TerrainSlider& s : terrain_) spec.conditions.emplace_back(s.name, s.value);
  }
  slices_.clear();
  slices_.push_back(SliceModel(in_.model, spec, in_.model_file));
  if (in_.compare) slices_.push_back(SliceModel(*in_.compare, spec, in_.compare_file));

  points_.resize(0, 2);
  if (!in_.data) return;
  const Eigen::MatrixXd samples = RawSamples(*in_.data, command_ids_[command_index_]);
  std::vector<Eigen::Index> near;
  for (Eigen::Index r = 0; r < samples.rows(); ++r) {
    bool keep = true;
    for (size_t t = 0; t < terrain_.size() && conditioned_ && keep; ++t) {
      const TerrainSlider& s = terrain_[t];
      const double z = samples(r, in_.model.pose_dim + static_cast<Eigen::Index>(t));
      keep = std::abs(z - s.value) <= near_fraction_ * (s.max - s.min);
    }
    if (keep) near.push_back(r);
  }
  points_.resize(static_cast<Eigen::Index>(near.size()), 2);
  for (size_t k = 0; k < near.size(); ++k) {
    points_(static_cast<Eigen::Index>(k), 0) = samples(near[k], x_index_);
    points_(static_cast<Eigen::Index>(k), 1) = samples(near[k], y_index_);
  }
}

std::vector<HeatMapSpec> SliceExplorer::Panels() const {
  std::vector<const ModelSlice*> slices;
  std::vector<SliceSource> sources{{in_.model.kind, in_.model_file}};
  for (const ModelSlice& s : slices_) slices.push_back(&s);
  if (in_.compare) sources.push_back({in_.compare->kind, in_.compare_file});
  std::vector<HeatMapSpec> panels = SliceHeatMaps(slices, sources, points_, window(), figure_);
  if (ellipses_) {
    for (size_t i = 0; i < slices_.size(); ++i) {
      panels[i].curves = ComponentEllipses(slices_[i].mixture);
    }
  }
  return panels;
}

std::string SliceExplorer::Readout(double x, double y) const {
  std::string text = "at (" + Number(x) + ", " + Number(y) + ")";
  const Eigen::Vector2d point(x, y);
  std::vector<double> densities;
  for (size_t i = 0; i < slices_.size(); ++i) {
    const Mixture& m = slices_[i].mixture;
    if (slices_.size() > 1) text += i == 0 ? "  A:" : "  B:";
    if (m.empty()) {
      text += " no components";
      densities.push_back(0);
      continue;
    }
    const double log_p = m.LogDensity(point);
    densities.push_back(std::exp(log_p));
    Eigen::Index best = 0;
    m.LogResponsibilities(point).maxCoeff(&best);
    const int c = static_cast<int>(best);
    text += " p=" + Number(densities.back()) + ", component " + std::to_string(c + 1) + "/" +
            std::to_string(m.size()) + " (" + Number(100 * m.weight(c) / m.total_weight(), "%.0f") +
            "% of weight)";
  }
  if (densities.size() == 2) text += "  A-B=" + Number(densities[0] - densities[1]);
  return text;
}

std::string SliceExplorer::Status() const {
  std::string text = "command " + command_labels_[command_index_] + " (" +
                     std::to_string(command_index_ + 1) + "/" +
                     std::to_string(command_labels_.size()) + ")  x: " + names_[x_index_] +
                     "  y: " + names_[y_index_];
  if (!terrain_.empty()) {
    if (conditioned_) {
      text += "  | z:";
      for (const TerrainSlider& s : terrain_) text += " " + s.name + "=" + Number(s.value);
    } else {
      text += "  | marginal over the terrain";
    }
  }
  if (in_.data) {
    text += "  | " + std::to_string(points_.rows()) + " samples";
    if (conditioned_ && !terrain_.empty()) text += " within " + Number(100 * near_fraction_) + "%";
  }
  text += !window_locked()   ? "  | window: auto"
          : held_by_terrain_ ? "  | window: held"
                             : "  | window: zoomed";
  return text;
}

std::vector<std::string> SliceExplorer::RenderArguments(const std::string& png) const {
  const bool filtered = in_.data && conditioned_ && !terrain_.empty();
  if (filtered) return {};
  std::vector<std::string> args{in_.model_file};
  if (in_.compare) {
    args.push_back(in_.compare_file);
    args.push_back("--diff");
  }
  args.insert(args.end(), {"--command", command_labels_[command_index_], "--x-dim",
                           names_[x_index_], "--y-dim", names_[y_index_]});
  if (conditioned_) {
    for (const TerrainSlider& s : terrain_) {
      args.insert(args.end(), {"--condition", s.name + "=" + Exact(s.value)});
    }
  }
  if (in_.model.pose_dim > 2 || (!conditioned_ && !terrain_.empty())) {
    args.push_back("--marginalise");
  }
  if (in_.data) args.insert(args.end(), {"--data", in_.data_file});
  args.insert(args.end(), {"--contours", std::to_string(figure_.contours), "--size",
                           std::to_string(figure_.width) + "x" + std::to_string(figure_.height),
                           "--grid", std::to_string(figure_.grid)});
  if (locked_window_) {
    const PlotRange& w = *locked_window_;
    args.insert(args.end(), {"--window", Exact(w.x_min) + "," + Exact(w.x_max) + "," +
                                             Exact(w.y_min) + "," + Exact(w.y_max)});
  }
  args.insert(args.end(), {"-o", png});
  return args;
}

std::vector<CurveOverlay> ComponentEllipses(const Mixture& mixture2d, int segments) {
  std::vector<CurveOverlay> curves;
  for (int c = 0; c < mixture2d.size(); ++c) {
    const Gaussian& g = mixture2d.component(c);
    const Eigen::Matrix2d l = g.cholesky_l().topLeftCorner<2, 2>();
    CurveOverlay curve;
    curve.points.resize(segments + 1, 2);
    for (int k = 0; k <= segments; ++k) {
      const double angle = 2 * std::numbers::pi * k / segments;
      const Eigen::Vector2d p = g.mean().head<2>() + 2.0 * l * Eigen::Vector2d(std::cos(angle),
                                                                               std::sin(angle));
      curve.points.row(k) = p.transpose();
    }
    curve.rgb = {140, 255, 140};  // green: apart from the grey contours and blue samples
    curve.width = 1.5f;
    curves.push_back(std::move(curve));
  }
  return curves;
}

}  // namespace dgmm
