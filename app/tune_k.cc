// `dgmm tune-k`: the DGMM merge rate k that maximises the cross-validated held-out
// log-likelihood, found with Ceres on a smooth fit of the curve (lib/tune/tune_k.h).
#include "tune/tune_k.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/command.h"
#include "io/sample_set_io.h"
#include "render/chart.h"
#include "tune/dimensions.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace dgmm::app {
namespace {

struct TuneKArgs {
  std::string path;
  bool with_terrain = false, without_terrain = false;
  int folds = 10, repeats = 10;
  std::uint64_t seed = 1;
  int threads = 0;
  double k_min = 1e-3, k_max = 10;
  int grid_points = 9, refine_points = 4;
  bool shuffle_training = false;
  std::string variant = "faithful";
  std::string plot, curve_csv;
  std::vector<std::string> pose_dims, terrain_dims;
  bool json = false;
};

void WriteCurveCsv(const TuneKSummary& s, const std::string& path) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path());
    out.precision(10);
    out << "k,log_likelihood,sd,standard_error,smoothed,role\n";
    for (const auto& p : s.curve) {
      out << p.k << "," << p.log_likelihood << "," << p.sd << "," << p.standard_error << ","
          << s.Smoothed(p.k) << "," << p.role << "\n";
    }
    if (!out) throw MakeInputError(path, "", "cannot write");
  }
  file.Commit();
}

void PlotCurve(const TuneKSummary& s, const std::string& path) {
  LineChartSpec spec;
  spec.title = fmt::format("tune-k: k = {:.3g}, held-out log-likelihood {:.1f} +- {:.1f}", s.k,
                           s.log_likelihood, s.standard_error);
  spec.x_label = "merge rate k";
  spec.y_label = fmt::format("held-out log-likelihood ({} x {}-fold, {} terrain)", s.repeats,
                             s.folds, s.with_terrain ? "with" : "without");
  spec.log_x = true;
  ChartSeries cv{"cross-validated (mean +- s.e.)", {}, {}, {}, {}};
  for (const auto& p : s.curve) {
    cv.x.push_back(p.k);
    cv.y.push_back(p.log_likelihood);
    cv.y_error.push_back(p.standard_error);
  }
  ChartSeries fit{"Ceres quadratic fit in log k (over the bracket)", {}, {}, {}, {}};
  // Only over the bracket it was fitted and maximised on (grid points around the best one).
  const double lo = std::log(s.bracket_lo), hi = std::log(s.bracket_hi);
  for (int i = 0; i <= 40; ++i) {
    const double k = std::exp(lo + (hi - lo) * i / 40.0);
    fit.x.push_back(k);
    fit.y.push_back(s.Smoothed(k));
  }
  // The chosen k as a vertical segment spanning its held-out log-likelihood +- one s.e.
  ChartSeries chosen{"chosen k (+- s.e.)",
                     {s.k, s.k},
                     {s.log_likelihood - s.standard_error, s.log_likelihood + s.standard_error},
                     {},
                     {}};
  spec.series = {cv, fit, chosen};
  RenderLineChart(spec, path);
}

void RunTuneK(const TuneKArgs& args) {
  if (args.with_terrain && args.without_terrain) {
    throw MakeInputError("", "--with-terrain/--without-terrain", "give at most one");
  }
  // Unwritable output folders are reported before the long run, not after it.
  for (const std::string& output : {args.plot, args.curve_csv}) {
    if (!output.empty()) AtomicFile probe(output);
  }
  const SampleSet set =
      SelectDimensions(ReadSampleSet(args.path), args.pose_dims, args.terrain_dims);
  if (set.size() == 0) throw MakeInputError(args.path, "samples", "the set is empty");
  WarnIfUnderdetermined(set, !args.without_terrain, "tune-k");
  if (args.with_terrain && set.terrain_dim() == 0) {
    throw MakeInputError(args.path, "z", "--with-terrain needs a set with terrain");
  }
  TuneKOptions options;
  options.with_terrain = !args.without_terrain;
  options.cv.folds = args.folds;
  options.cv.repeats = args.repeats;
  options.cv.seed = args.seed;
  options.cv.threads = args.threads;
  options.cv.shuffle_training = args.shuffle_training;
  options.cv.dgmm.variant = args.variant == "improved" ? DgmmOptions::Variant::kImproved
                                                       : DgmmOptions::Variant::kFaithful;
  options.k_min = args.k_min;
  options.k_max = args.k_max;
  options.grid_points = args.grid_points;
  options.refine_points = args.refine_points;
  options.progress = [](int done, int total) { ReportProgress("tune-k evaluations", done, total); };
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "options", error);
  const TuneKSummary s = TuneK(set, options);
  if (!args.curve_csv.empty()) WriteCurveCsv(s, args.curve_csv);
  if (!args.plot.empty()) PlotCurve(s, args.plot);

  if (args.json) {
    nlohmann::json curve = nlohmann::json::array();
    for (const auto& p : s.curve) {
      curve.push_back({{"k", p.k},
                       {"log_likelihood", p.log_likelihood},
                       {"sd", p.sd},
                       {"standard_error", p.standard_error},
                       {"smoothed", s.Smoothed(p.k)},
                       {"role", p.role}});
    }
    nlohmann::json out = {
        {"file", args.path},
        {"k", s.k},
        {"log_likelihood", s.log_likelihood},
        {"standard_error", s.standard_error},
        {"sd", s.sd},
        {"with_terrain", s.with_terrain},
        {"folds", s.folds},
        {"repeats", s.repeats},
        {"seed", args.seed},
        {"samples", s.samples},
        {"bracket", {s.bracket_lo, s.bracket_hi}},
        {"at_grid_edge", s.at_grid_edge},
        {"fit", {{"u0", s.u0}, {"a", s.a}, {"b", s.b}, {"c", s.c}, {"points", s.fit_points}}},
        {"best_evaluated",
         {{"k", s.best_evaluated_k}, {"log_likelihood", s.best_evaluated_log_likelihood}}},
        {"curve", curve},
        {"seconds", s.seconds}};
    std::cout << out.dump(2) << "\n";
    return;
  }
  std::cout << fmt::format("{}: {} samples, {} x {}-fold, {} terrain, seed {} ({:.1f} s)\n",
                           args.path, s.samples, s.repeats, s.folds,
                           s.with_terrain ? "with" : "without", args.seed, s.seconds);
  std::cout << fmt::format("{:>12}{:>16}{:>12}{:>14}  {}\n", "k", "log-likelihood", "std. error",
                           "smoothed", "");
  for (const auto& p : s.curve) {
    std::cout << fmt::format("{:>12.5g}{:>16.2f}{:>12.2f}{:>14.2f}  {}\n", p.k, p.log_likelihood,
                             p.standard_error, s.Smoothed(p.k), p.role);
  }
  std::cout << fmt::format(
      "bracket [{:.4g}, {:.4g}]{}; quadratic fit on {} points\n", s.bracket_lo, s.bracket_hi,
      s.at_grid_edge ? " (best grid point at the edge: widen --k-min/--k-max)" : "", s.fit_points);
  std::cout << fmt::format("chosen k = {:.5g}: held-out log-likelihood {:.2f} +- {:.2f} (s.e.)\n",
                           s.k, s.log_likelihood, s.standard_error);
}

void SetupTuneK(CLI::App& root) {
  auto args = std::make_shared<TuneKArgs>();
  CLI::App* cmd = root.add_subcommand(
      "tune-k", "Choose the DGMM merge rate k by cross-validated log-likelihood (Ceres)");
  cmd->add_option("set", args->path, "Sample set (.h5)")->required();
  cmd->add_flag("--with-terrain", args->with_terrain, "Maximise p(x | c, z) (the default)");
  cmd->add_flag("--without-terrain", args->without_terrain, "Maximise p(x | c)");
  cmd->add_option("--folds", args->folds, "Folds, >= 2")->capture_default_str();
  cmd->add_option("--repeats", args->repeats, "Repeats")->capture_default_str();
  cmd->add_option("--seed", args->seed, "Seed (the same folds and merges for every k)")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "Worker threads (0: all cores)")
      ->capture_default_str();
  cmd->add_option("--k-min", args->k_min, "Smallest k of the coarse grid")->capture_default_str();
  cmd->add_option("--k-max", args->k_max, "Largest k of the coarse grid")->capture_default_str();
  cmd->add_option("--grid-points", args->grid_points, "Coarse grid points (log spaced)")
      ->capture_default_str();
  cmd->add_option("--refine-points", args->refine_points, "Extra evaluations in the bracket")
      ->capture_default_str();
  cmd->add_flag("--shuffle-training", args->shuffle_training,
                "Stream training folds in a seeded random order");
  cmd->add_option("--variant", args->variant, "DGMM variant")
      ->check(CLI::IsMember({"faithful", "improved"}))
      ->capture_default_str();
  cmd->add_option("--plot", args->plot, "Write the curve as a PNG line chart (needs X)");
  cmd->add_option("--curve-csv", args->curve_csv, "Write the curve as CSV");
  cmd->add_option("--pose-dims", args->pose_dims,
                  "Pose dimensions to model, by name (default: all)")
      ->delimiter(',');
  cmd->add_option("--terrain-dims", args->terrain_dims,
                  "Terrain dimensions to condition on, by name (default: all)")
      ->delimiter(',');
  cmd->add_flag("--json", args->json, "Print JSON");
  cmd->callback([args] { RunTuneK(*args); });
}

}  // namespace

DGMM_REGISTER_COMMAND("tune-k", SetupTuneK);

}  // namespace dgmm::app
