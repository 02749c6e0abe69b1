#include "sim2real/figures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>

#include "render/chart.h"
#include "render/density_grid.h"
#include "render/display.h"
#include "render/heat_map.h"
#include "sim2real/samples.h"

namespace dgmm::sim2real {

DeficitHeatMapContent DescribeDeficitHeatMap(const Analysis& a) {
  DeficitHeatMapContent h;
  h.before = a.baseline.before.heat;
  if (a.knobs_analysed) h.after = a.adequacy.after.heat;
  for (Eigen::Index i = 0; i < h.before.rows(); ++i) {
    const int c = i < static_cast<Eigen::Index>(a.inputs.real_commands.size()) ? a.inputs.real_commands[i] : -1;
    h.commands.push_back(c >= 0 && c < static_cast<int>(a.inputs.command_labels.size())
                             ? a.inputs.command_labels[c]
                             : "command " + std::to_string(i));
  }
  h.terrain = a.baseline.terrain_labels;
  h.terrain.resize(h.before.cols(), "all terrain");
  std::vector<double> magnitudes;
  for (const Eigen::MatrixXd* m : {&h.before, &h.after}) {
    for (Eigen::Index k = 0; k < m->size(); ++k) {
      if (std::isfinite(m->data()[k])) magnitudes.push_back(std::abs(m->data()[k]));
    }
  }
  if (!magnitudes.empty()) {
    const size_t at = static_cast<size_t>(std::ceil(0.99 * (magnitudes.size() - 1)));
    std::nth_element(magnitudes.begin(), magnitudes.begin() + at, magnitudes.end());
    h.color_max = magnitudes[at];
  }
  if (!(h.color_max > 0)) h.color_max = 1e-12;
  h.x_label = "terrain region (k-means of the terrain z)";
  h.y_label = "command";
  h.value_label = "deficit (nats/sample)";
  return h;
}

namespace {

// Mean and covariance of (dx, dy) under the sim model, or the knob correction when given, at z
// (first executions mixed in with the real set's share).
void PlanarPrediction(const Analysis& a, int c, const Eigen::VectorXd& z, const Correction* correction,
                      Eigen::Vector2d* mean, Eigen::Matrix2d* cov) {
  const double first = a.inputs.first_execution_share;
  const Prediction p = a.baseline.sim_model.Predict(c, z, first);
  Eigen::VectorXd m = p.mean;
  Eigen::MatrixXd s = p.chol * p.chol.transpose();
  if (correction) {
    const int dx = static_cast<int>(m.size());
    m += first * correction->Shift(c, z, 1.0, dx) + (1 - first) * correction->Shift(c, z, 0.0, dx);
    s = correction->Covariance(s);
  }
  const int i = a.inputs.layout.dx, j = a.inputs.layout.dy;
  *mean << m(i), m(j);
  *cov << s(i, i), s(i, j), s(j, i), s(j, j);
}

double Planar(const Eigen::Vector2d& mean, const Eigen::Matrix2d& cov, double x, double y) {
  Eigen::Vector2d d(x - mean(0), y - mean(1));
  const double det = cov.determinant();
  if (!(det > 0)) return 0.0;
  return std::exp(-0.5 * d.dot(cov.inverse() * d)) / (2 * M_PI * std::sqrt(det));
}

void LogLikelihoodBars(const Analysis& a, const std::filesystem::path& dir, std::vector<ReportFigure>* figures) {
  BarChartSpec bars;
  bars.title = "Held-out real log-likelihood per sample";
  bars.y_label = "nats per sample";
  if (a.knobs_analysed) {
    bars.categories = {"sim-trained", "knob-corrected", "real-trained ceiling"};
    bars.series.push_back({"held-out", {0, 1, 2}, {a.baseline.ll_sim, a.adequacy.ll_corrected, a.baseline.ll_ceiling}, {}, {}});
  } else {
    bars.categories = {"sim-trained", "real-trained ceiling"};
    bars.series.push_back({"held-out", {0, 1}, {a.baseline.ll_sim, a.baseline.ll_ceiling}, {}, {}});
  }
  RenderBarChart(bars, (dir / "loglik.png").string());
  figures->push_back({"loglik.png", a.knobs_analysed ? "Held-out real log-likelihood per sample: (a) sim-trained, (b) "
                                                       "knob-corrected, (c) real-trained ceiling."
                                                     : "Held-out real log-likelihood per sample: sim-trained and the "
                                                       "real-trained ceiling."});
}

// One panel of the deficit heat map: cell (c, t) is an equal block [t, t + 1] x [c, c + 1], the
// first command row at the top (as in the table), one symmetric colour scale for both panels.
HeatMapSpec DeficitPanel(const DeficitHeatMapContent& content, const Eigen::MatrixXd& h, const std::string& title) {
  constexpr int kPerCell = 16;
  const int rows = static_cast<int>(h.rows()), cols = static_cast<int>(h.cols());
  HeatMapSpec heat;
  heat.palette = HeatMapSpec::Palette::kDiverging;
  heat.color_max = content.color_max;
  heat.background.range = {0, double(cols), 0, double(rows)};
  const int nx = std::max(2, cols * kPerCell), ny = std::max(2, rows * kPerCell);
  heat.background.values.resize(ny, nx);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int c = rows - 1 - std::min(rows - 1, j * rows / (ny - 1));
      const int t = std::min(cols - 1, i * cols / (nx - 1));
      heat.background.values(j, i) = std::isfinite(h(c, t)) ? h(c, t) : 0.0;
    }
  }
  // Tick labels: the region's name and its pitch/roll on a second line (the explanation in
  // parentheses is in the report's table).
  for (const std::string& label : content.terrain) {
    const size_t open = label.find(" ("), close = label.find("): ");
    heat.x_categories.push_back(open != std::string::npos && close != std::string::npos && close > open
                                    ? label.substr(0, open) + "\n" + label.substr(close + 3)
                                    : label);
  }
  heat.y_categories.assign(content.commands.rbegin(), content.commands.rend());
  heat.title = title;
  heat.x_label = content.x_label;
  heat.y_label = content.y_label;
  heat.value_label = content.value_label;
  heat.width = 640;
  heat.height = std::max(420, 140 + 34 * rows);
  return heat;
}

void DeficitHeatMap(const Analysis& a, const std::filesystem::path& dir, std::vector<ReportFigure>* figures) {
  const DeficitHeatMapContent content = DescribeDeficitHeatMap(a);
  if (content.before.rows() < 1 || content.before.cols() < 1) return;
  std::vector<HeatMapSpec> panels = {DeficitPanel(content, content.before, "Deficit of the sim model")};
  if (content.after.size() > 0) {
    panels.push_back(DeficitPanel(content, content.after, "Deficit after the knob correction (same colour scale)"));
  }
  RenderHeatMapRow(panels, (dir / "heat_map.png").string());
  figures->push_back({"heat_map.png", "Held-out deficit (nats per real sample, real-trained ceiling minus model) per "
                                      "command x terrain region" +
                                          std::string(content.after.size() > 0 ? ", before and after the knob correction, "
                                                                                 "on one colour scale"
                                                                               : "") +
                                          " (red: the model explains the real data worse than the ceiling; white: no "
                                          "difference or no samples)."});
}

std::string AxisLabel(const SampleSet& real, const SampleSet& sim, int dim) {
  const std::string name = dim < static_cast<int>(real.x_names.size()) ? real.x_names[dim] : "x" + std::to_string(dim);
  const std::string unit = dim < static_cast<int>(real.x_units.size()) && !real.x_units[dim].empty()
                               ? real.x_units[dim] : (dim < static_cast<int>(sim.x_units.size()) ? sim.x_units[dim] : "");
  return name + " (" + (unit.empty() ? "no unit recorded" : unit) + ")";
}

// "command C on T (pitch=.., roll=..), N real samples" for a cell region.
std::string CellContext(const Analysis& a, const Region& g, const Eigen::VectorXd& z, size_t points) {
  std::string condition;
  for (int d = 0; d < static_cast<int>(z.size()); ++d) {
    const std::string name = d < static_cast<int>(a.inputs.real_set.z_names.size()) ? a.inputs.real_set.z_names[d]
                                                                                    : "z" + std::to_string(d);
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s%s=%.2f", condition.empty() ? "" : ", ", name.c_str(), z(d));
    condition += buf;
  }
  const auto& labels = a.inputs.command_labels;
  const std::string command = g.command >= 0 && g.command < static_cast<int>(labels.size()) ? labels[g.command] : "?";
  std::string terrain = g.terrain >= 0 && g.terrain < static_cast<int>(a.baseline.terrain_labels.size())
                            ? a.baseline.terrain_labels[g.terrain] : "all terrain";
  terrain = terrain.substr(0, terrain.find(" ("));
  return "command " + command + " on " + terrain + (condition.empty() ? "" : " (" + condition + ")") + ", " +
         std::to_string(points) + " real samples";
}

// The real samples (dx, dy) of a cell region.
Eigen::MatrixX2d CellPoints(const Analysis& a, const Region& g) {
  const Samples& real = a.inputs.real;
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < real.size(); ++i) {
    if (real.command[i] == g.command && a.baseline.real_terrain[i] == g.terrain) {
      pts.emplace_back(real.x(i, a.inputs.layout.dx), real.x(i, a.inputs.layout.dy));
    }
  }
  Eigen::MatrixX2d points(pts.size(), 2);
  for (size_t k = 0; k < pts.size(); ++k) points.row(k) = pts[k].transpose();
  return points;
}

void CellDensities(const Analysis& a, const Region& g, const std::string& file, std::vector<ReportFigure>* figures,
                   const std::filesystem::path& dir) {
  const Eigen::VectorXd z = a.baseline.terrain_centres.row(g.terrain).transpose();
  const Eigen::MatrixX2d points = CellPoints(a, g);
  Eigen::Vector2d m0, m1;
  Eigen::Matrix2d s0, s1;
  PlanarPrediction(a, g.command, z, nullptr, &m0, &s0);
  PlanarPrediction(a, g.command, z, &a.correction, &m1, &s1);
  // The window holds both models' mass and every real sample of the cell.
  Mixture before(2), after(2);
  before.Add(1, Gaussian(m0, s0));
  after.Add(1, Gaussian(m1, s1));
  const PlotRange range = ExtentRange({&before, &after}, points);
  const std::string x_axis = AxisLabel(a.inputs.real_set, a.inputs.sim_set, a.inputs.layout.dx);
  const std::string y_axis = AxisLabel(a.inputs.real_set, a.inputs.sim_set, a.inputs.layout.dy);
  const std::string per_area =
      x_axis.find("(m)") != std::string::npos && y_axis.find("(m)") != std::string::npos ? " (1/m^2)" : "";
  const std::string context = CellContext(a, g, z, points.rows());
  auto panel = [&](const std::string& title, auto f, HeatMapSpec::Palette pal, const std::string& value) {
    HeatMapSpec h;
    h.background = SampleGrid(f, range, 80, 80);
    h.palette = pal;
    h.color_scale = HeatMapSpec::ColorScale::kAuto;
    h.points = points;
    h.title = title + ": " + context;
    h.x_label = x_axis, h.y_label = y_axis, h.value_label = value;
    h.width = 560, h.height = 500;
    return h;
  };
  std::vector<HeatMapSpec> row = {
      panel("sim-trained", [&](double x, double y) { return Planar(m0, s0, x, y); }, HeatMapSpec::Palette::kSequential,
            "density" + per_area),
      panel("knob-corrected", [&](double x, double y) { return Planar(m1, s1, x, y); }, HeatMapSpec::Palette::kSequential,
            "density" + per_area),
      panel("corrected - sim", [&](double x, double y) { return Planar(m1, s1, x, y) - Planar(m0, s0, x, y); },
            HeatMapSpec::Palette::kDiverging, "difference" + per_area)};
  ShareColorScale({&row[0], &row[1]});  // equal colours mean equal densities
  RenderHeatMapRow(row, (dir / file).string());
  figures->push_back({file, "p(dx, dy | c, z) for " + context + ": sim-trained and knob-corrected (one colour scale) "
                                                                "and their difference; dots: the real samples of the cell."});
}

}  // namespace

std::vector<ReportFigure> RenderFigures(const Analysis& a, const std::filesystem::path& dir, std::string* note) {
  std::vector<ReportFigure> figures;
  if (auto problem = DisplayProblem()) {
    *note = "figures skipped: " + *problem;
    return figures;
  }
  try {
    LogLikelihoodBars(a, dir, &figures);
    DeficitHeatMap(a, dir, &figures);
    // Density maps for the two worst cells (the knob correction against the sim model).
    if (a.inputs.layout.has_planar() && a.knobs_analysed) {
      int drawn = 0;
      for (const auto& g : a.baseline.before.regions) {
        if (g.family != "cell" || drawn >= 2) continue;
        CellDensities(a, g, "density_" + std::to_string(++drawn) + ".png", &figures, dir);
      }
    }
  } catch (const std::exception& e) {
    *note = std::string("some figures skipped: ") + e.what();
  }
  return figures;
}

}  // namespace dgmm::sim2real
