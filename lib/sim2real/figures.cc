#include "sim2real/figures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>

#ifdef DGMM_SIM2REAL_HAVE_RENDER
#include "render/chart.h"
#include "render/density_grid.h"
#include "render/display.h"
#include "render/heat_map.h"
#include "sim2real/samples.h"
#endif

namespace dgmm::sim2real {

DeficitHeatMapContent DescribeDeficitHeatMap(const Sim2RealResult& r) {
  DeficitHeatMapContent h;
  h.before = r.heat_before;
  h.after = r.heat_after;
  for (Eigen::Index i = 0; i < r.heat_before.rows(); ++i) {
    const int c = i < static_cast<Eigen::Index>(r.real_commands.size()) ? r.real_commands[i] : -1;
    h.commands.push_back(c >= 0 && c < static_cast<int>(r.command_labels.size())
                             ? r.command_labels[c]
                             : "command " + std::to_string(i));
  }
  h.terrain = r.terrain_labels;
  h.terrain.resize(r.heat_before.cols(), "all terrain");
  std::vector<double> magnitudes;
  for (const Eigen::MatrixXd* m : {&r.heat_before, &r.heat_after}) {
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

#ifndef DGMM_SIM2REAL_HAVE_RENDER
std::vector<ReportFigure> RenderFigures(const Sim2RealResult&, const SampleSet&, const SampleSet&,
                                        const std::filesystem::path&, std::string* note) {
  *note = "figures skipped: dgmm was built without the render library";
  return {};
}
#else
namespace {

// Mean and covariance of (dx, dy) under the sim (corrected = false) or corrected model at z.
void PlanarPrediction(const Sim2RealResult& r, int c, const Eigen::VectorXd& z, bool corrected,
                      double first_share, Eigen::Vector2d* mean, Eigen::Matrix2d* cov) {
  Prediction p = r.sim_model.Predict(c, z, first_share);
  Eigen::VectorXd m = p.mean;
  Eigen::MatrixXd s = p.chol * p.chol.transpose();
  if (corrected) {
    int pitch_col = r.terrain_dim >= 1 ? 0 : -1, roll_col = r.terrain_dim >= 2 ? 1 : -1;
    const double pitch = pitch_col >= 0 ? z(pitch_col) : 0, roll = roll_col >= 0 ? z(roll_col) : 0;
    const Eigen::Vector3d g = BodyGravity(pitch, roll);
    for (size_t k = 0; k < r.fit.effects.size(); ++k) {
      const EffectSpec& e = r.library[r.fit.effects[k]];
      if (e.is_noise) continue;
      m += first_share * EffectDesign(e, r.layout, r.sim_model.Predict(c, z, 1.0).mean, g, true) * r.fit.theta[k] +
           (1 - first_share) * EffectDesign(e, r.layout, r.sim_model.Predict(c, z, 0.0).mean, g, false) * r.fit.theta[k];
    }
    s *= std::exp(2 * r.fit.log_tau);
  }
  const int a = r.layout.dx, b = r.layout.dy;
  *mean << m(a), m(b);
  *cov << s(a, a), s(a, b), s(b, a), s(b, b);
}

double Planar(const Eigen::Vector2d& mean, const Eigen::Matrix2d& cov, double x, double y) {
  Eigen::Vector2d d(x - mean(0), y - mean(1));
  const double det = cov.determinant();
  if (!(det > 0)) return 0.0;
  return std::exp(-0.5 * d.dot(cov.inverse() * d)) / (2 * M_PI * std::sqrt(det));
}

}  // namespace

std::vector<ReportFigure> RenderFigures(const Sim2RealResult& r, const SampleSet& sim,
                                        const SampleSet& real, const std::filesystem::path& dir,
                                        std::string* note) {
  std::vector<ReportFigure> figures;
  if (auto problem = DisplayProblem()) {
    *note = "figures skipped: " + *problem;
    return figures;
  }
  try {
    // 1. Held-out log-likelihood bars.
    BarChartSpec bars;
    bars.title = "Held-out real log-likelihood per sample";
    bars.y_label = "nats per sample";
    bars.categories = {"sim-trained", "corrected", "real-trained ceiling"};
    bars.series.push_back({"held-out", {0, 1, 2}, {r.ll_sim, r.ll_corrected, r.ll_ceiling}, {}, {}});
    RenderBarChart(bars, (dir / "loglik.png").string());
    figures.push_back({"loglik.png", "Held-out real log-likelihood per sample: (a) sim-trained, "
                                     "(b) corrected, (c) real-trained ceiling."});
    // 2. Heat map: rows = commands (as in the table), columns = terrain regions; cell (c, t) is
    // the block [t, t + 1] x [c, c + 1] (nearest-neighbour upsampling, so cells are equal blocks),
    // before and after the correction side by side.
    if (r.heat_before.rows() >= 1 && r.heat_before.cols() >= 1) {
      const DeficitHeatMapContent content = DescribeDeficitHeatMap(r);
      // Cell (c, t) is an equal block; the first command row is drawn at the top, as in the
      // table; both panels share one symmetric colour scale.
      auto blocks = [&](const Eigen::MatrixXd& h, const std::string& title) {
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
      };
      RenderHeatMapRow({blocks(r.heat_before, "Deficit before the correction"),
                        blocks(r.heat_after, "Deficit after the correction (same colour scale)")},
                       (dir / "heat_map.png").string());
      figures.push_back({"heat_map.png", "Held-out deficit (nats per real sample, real-trained "
                                         "ceiling minus model) per command x terrain region, "
                                         "before and after the correction, on one colour scale "
                                         "(red: the model explains the real data worse than the "
                                         "ceiling; white: no difference or no samples)."});
    }
    // 3. Density maps for the two worst cells: sim, corrected, corrected - sim; real points overlaid.
    if (r.layout.has_planar()) {
      std::vector<int> map = AlignCommands(sim, real);
      int drawn = 0;
      for (const auto& g : r.before) {
        if (g.family != "cell" || drawn >= 2) continue;
        Eigen::VectorXd z = r.terrain_centres.row(g.terrain).transpose();
        std::vector<Eigen::Vector2d> pts;
        for (int i = 0; i < real.size(); ++i) {
          const int c = map[real.command(i)];
          if (c != g.command) continue;
          Eigen::Index t = 0;
          if (r.terrain_dim > 0) (r.terrain_centres.rowwise() - real.z.row(i)).rowwise().squaredNorm().minCoeff(&t);
          if (t == g.terrain) pts.emplace_back(real.x(i, r.layout.dx), real.x(i, r.layout.dy));
        }
        Eigen::Vector2d m0, m1;
        Eigen::Matrix2d s0, s1;
        PlanarPrediction(r, g.command, z, false, r.first_execution_share, &m0, &s0);
        PlanarPrediction(r, g.command, z, true, r.first_execution_share, &m1, &s1);
        Eigen::MatrixX2d points(pts.size(), 2);
        for (size_t k = 0; k < pts.size(); ++k) points.row(k) = pts[k].transpose();
        // The window holds both models' mass and every real sample of the cell.
        Mixture before(2), after(2);
        before.Add(1, Gaussian(m0, s0));
        after.Add(1, Gaussian(m1, s1));
        const PlotRange range = ExtentRange({&before, &after}, points);
        auto axis = [&](int dim) {
          const std::string name = dim < static_cast<int>(real.x_names.size()) ? real.x_names[dim] : "x" + std::to_string(dim);
          const std::string unit = dim < static_cast<int>(real.x_units.size()) && !real.x_units[dim].empty()
                                       ? real.x_units[dim] : (dim < static_cast<int>(sim.x_units.size()) ? sim.x_units[dim] : "");
          return name + " (" + (unit.empty() ? "no unit recorded" : unit) + ")";
        };
        const std::string per_area = axis(r.layout.dx).find("(m)") != std::string::npos &&
                                             axis(r.layout.dy).find("(m)") != std::string::npos
                                         ? " (1/m^2)" : "";
        std::string condition;
        for (int d = 0; d < static_cast<int>(z.size()); ++d) {
          const std::string name = d < static_cast<int>(real.z_names.size()) ? real.z_names[d] : "z" + std::to_string(d);
          char buf[64];
          std::snprintf(buf, sizeof buf, "%s%s=%.2f", condition.empty() ? "" : ", ", name.c_str(), z(d));
          condition += buf;
        }
        const std::string command_label =
            g.command >= 0 && g.command < static_cast<int>(r.command_labels.size()) ? r.command_labels[g.command] : "?";
        std::string terrain_name = g.terrain >= 0 && g.terrain < static_cast<int>(r.terrain_labels.size())
                                       ? r.terrain_labels[g.terrain] : "all terrain";
        terrain_name = terrain_name.substr(0, terrain_name.find(" ("));
        const std::string context = "command " + command_label + " on " + terrain_name +
                                    (condition.empty() ? "" : " (" + condition + ")") + ", " +
                                    std::to_string(pts.size()) + " real samples";
        auto panel = [&](const std::string& title, auto f, HeatMapSpec::Palette pal, const std::string& value) {
          HeatMapSpec h;
          h.background = SampleGrid(f, range, 80, 80);
          h.palette = pal;
          h.color_scale = HeatMapSpec::ColorScale::kAuto;
          h.points = points;
          h.title = title + ": " + context;
          h.x_label = axis(r.layout.dx);
          h.y_label = axis(r.layout.dy);
          h.value_label = value;
          h.width = 560;
          h.height = 500;
          return h;
        };
        std::vector<HeatMapSpec> row = {
            panel("sim-trained", [&](double x, double y) { return Planar(m0, s0, x, y); },
                  HeatMapSpec::Palette::kSequential, "density" + per_area),
            panel("corrected", [&](double x, double y) { return Planar(m1, s1, x, y); },
                  HeatMapSpec::Palette::kSequential, "density" + per_area),
            panel("corrected - sim", [&](double x, double y) { return Planar(m1, s1, x, y) - Planar(m0, s0, x, y); },
                  HeatMapSpec::Palette::kDiverging, "difference" + per_area)};
        // Sim-trained and corrected on one scale: equal colours mean equal densities.
        ShareColorScale({&row[0], &row[1]});
        const std::string file = "density_" + std::to_string(drawn + 1) + ".png";
        RenderHeatMapRow(row, (dir / file).string());
        figures.push_back({file, "p(dx, dy | c, z) for " + context +
                                     ": sim-trained and corrected (one colour scale) and their "
                                     "difference; cyan/black dots: the real samples of the cell."});
        ++drawn;
      }
    }
  } catch (const std::exception& e) {
    *note = std::string("some figures skipped: ") + e.what();
  }
  return figures;
}
#endif

}  // namespace dgmm::sim2real
