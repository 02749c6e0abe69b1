#include "sim2real/figures.h"

#include <algorithm>
#include <cmath>
#include <exception>

#ifdef DGMM_SIM2REAL_HAVE_RENDER
#include "render/chart.h"
#include "render/density_grid.h"
#include "render/display.h"
#include "render/heat_map.h"
#include "sim2real/samples.h"
#endif

namespace dgmm::sim2real {

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
    if (r.heat_before.rows() >= 2 && r.heat_before.cols() >= 2) {
      auto blocks = [](const Eigen::MatrixXd& h, const std::string& title) {
        constexpr int kPerCell = 16;
        HeatMapSpec heat;
        heat.palette = HeatMapSpec::Palette::kDiverging;
        heat.background.range = {0, double(h.cols()), 0, double(h.rows())};
        const int nx = static_cast<int>(h.cols()) * kPerCell, ny = static_cast<int>(h.rows()) * kPerCell;
        heat.background.values.resize(ny, nx);
        for (int j = 0; j < ny; ++j) {
          for (int i = 0; i < nx; ++i) {
            const int c = std::min<int>(h.rows() - 1, j * h.rows() / (ny - 1));
            const int t = std::min<int>(h.cols() - 1, i * h.cols() / (nx - 1));
            heat.background.values(j, i) = std::isfinite(h(c, t)) ? h(c, t) : 0.0;
          }
        }
        heat.title = title;
        heat.x_label = "terrain region k in [k, k+1] (see table)";
        heat.y_label = "command row r in [r, r+1] (table order)";
        heat.value_label = "nats/sample";
        heat.width = 560;
        heat.height = 640;
        return heat;
      };
      RenderHeatMapRow({blocks(r.heat_before, "Deficit before the correction"),
                        blocks(r.heat_after, "Deficit after the correction")},
                       (dir / "heat_map.png").string());
      figures.push_back({"heat_map.png", "Held-out deficit (nats per real sample, real-trained "
                                         "ceiling minus model) per command x terrain region, "
                                         "before and after the correction (rows and columns in "
                                         "the order of the report's table; white: no samples)."});
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
        PlotRange range;
        range.x_min = range.x_max = m0(0);
        range.y_min = range.y_max = m0(1);
        for (const auto& [m, s] : {std::pair{m0, s0}, std::pair{m1, s1}}) {
          range.Include(m(0) - 3.5 * std::sqrt(s(0, 0)), m(1) - 3.5 * std::sqrt(s(1, 1)));
          range.Include(m(0) + 3.5 * std::sqrt(s(0, 0)), m(1) + 3.5 * std::sqrt(s(1, 1)));
        }
        for (const auto& p : pts) range.Include(p(0), p(1));
        Eigen::MatrixX2d points(pts.size(), 2);
        for (size_t k = 0; k < pts.size(); ++k) points.row(k) = pts[k].transpose();
        auto panel = [&](const std::string& title, auto f, HeatMapSpec::Palette pal, const std::string& value) {
          HeatMapSpec h;
          h.background = SampleGrid(f, range, 80, 80);
          h.palette = pal;
          h.points = points;
          h.title = title;
          h.x_label = "dx";
          h.y_label = "dy";
          h.value_label = value;
          h.width = 520;
          h.height = 460;
          return h;
        };
        std::vector<HeatMapSpec> row = {
            panel("sim-trained", [&](double x, double y) { return Planar(m0, s0, x, y); },
                  HeatMapSpec::Palette::kSequential, "density"),
            panel("corrected", [&](double x, double y) { return Planar(m1, s1, x, y); },
                  HeatMapSpec::Palette::kSequential, "density"),
            panel("corrected - sim", [&](double x, double y) { return Planar(m1, s1, x, y) - Planar(m0, s0, x, y); },
                  HeatMapSpec::Palette::kDiverging, "difference")};
        const std::string file = "density_" + std::to_string(drawn + 1) + ".png";
        RenderHeatMapRow(row, (dir / file).string());
        figures.push_back({file, "p(dx, dy | c, z) in " + g.label +
                                     ": sim-trained, corrected and their difference; dots: the real samples."});
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
