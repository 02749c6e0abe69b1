// `dgmm tune` (alias `tune-k`): the DGMM merge rate k, S0 scale f and prior pseudo-count nu0 that
// maximise the cross-validated held-out log-likelihood: coordinate steps, then a joint Ceres
// quadratic step, with the plateau rule (lib/tune/tune_k.h).
#include "tune/tune_k.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/command.h"
#include "app/dgmm_flags.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "render/chart.h"
#include "tune/dimensions.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/output_guard.h"

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
  bool stratified = false;
  double plateau_tolerance = 0;
  std::vector<double> init_scales = TuneKOptions{}.init_scales;
  std::vector<double> prior_counts = TuneKOptions{}.prior_counts;
  DgmmFlags dgmm;
  std::string plot, curve_csv;
  std::vector<std::string> pose_dims, terrain_dims;
  bool json = false;
  bool no_joint = false;
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
  // The chosen k as a vertical segment spanning its held-out log-likelihood +- one s.e. (at
  // other f, nu0 than the curve's when the joint step moved them: the legend says so).
  const bool moved = s.joint.run && (s.init_scale != s.joint.start.init_scale ||
                                     s.prior_count != s.joint.start.prior_count);
  ChartSeries chosen{
      moved ? fmt::format("chosen k (+- s.e.) at f = {:.3g}, nu0 = {:.3g} (joint step)",
                          s.init_scale, s.prior_count)
            : std::string("chosen k (+- s.e.)"),
      {s.k, s.k},
      {s.log_likelihood - s.standard_error, s.log_likelihood + s.standard_error},
      {},
      {}};
  spec.series = {cv, fit, chosen};
  RenderLineChart(spec, path);
}

// The joint step (lib/tune/tune_k.h, 3.) as JSON; null when it did not run.
nlohmann::json JointJson(const TuneJointStep& j) {
  if (!j.run) return nullptr;
  auto point = [](const TuneKPoint& p) {
    return nlohmann::json{{"k", p.k},
                          {"init_scale", p.init_scale},
                          {"prior_count", p.prior_count},
                          {"log_likelihood", p.log_likelihood},
                          {"standard_error", p.standard_error},
                          {"components", p.components},
                          {"role", p.role}};
  };
  nlohmann::json points = nlohmann::json::array();
  for (const auto& p : j.points) points.push_back(point(p));
  const Plateau& pl = j.plateau;
  return {{"coordinates", j.coordinates},
          {"start", point(j.start)},
          {"surrogate",
           {{"k", j.surrogate_k},
            {"init_scale", j.surrogate_init_scale},
            {"prior_count", j.surrogate_prior_count},
            {"maximum", j.surrogate_maximum},
            {"evaluated_log_likelihood", j.evaluated_log_likelihood},
            {"evaluated_standard_error", j.evaluated_standard_error}}},
          {"rounds", j.rounds},
          {"accepted", j.accepted},
          {"rule", j.rule},
          {"evaluations", j.evaluations},
          {"fit_points", j.fit_points},
          {"tolerance", j.tolerance},
          {"plateau",
           {{"flat", pl.flat},
            {"points", pl.members.size()},
            {"k_range", {pl.k_lo, pl.k_hi}},
            {"init_scale_range", {pl.init_scale_lo, pl.init_scale_hi}},
            {"prior_count_range", {pl.prior_count_lo, pl.prior_count_hi}}}},
          {"points", points},
          {"fit_report", j.fit_report},
          {"maximise_report", j.maximise_report}};
}

// The joint step as text.
void PrintJoint(const TuneKSummary& s) {
  const TuneJointStep& j = s.joint;
  if (!j.run) return;
  const bool moved = s.k != j.start.k || s.init_scale != j.start.init_scale ||
                     s.prior_count != j.start.prior_count;
  std::cout << fmt::format(
      "joint step in ({}): {} round(s), {} new cross-validations, last surrogate fitted to {} "
      "evaluations\n",
      fmt::join(j.coordinates, ", "), j.rounds, j.evaluations, j.fit_points);
  for (const auto& p : j.points) {
    std::cout << fmt::format(
        "  k {:<10.4g} f {:<8.3g} nu0 {:<8.3g} log-likelihood {:.2f} +- {:.2f}, mean K {:.2f}  "
        "{}\n",
        p.k, p.init_scale, p.prior_count, p.log_likelihood, p.standard_error, p.components, p.role);
  }
  std::cout << fmt::format(
      "  surrogate maximum {:.2f} at k = {:.4g}, f = {:.3g}, nu0 = {:.3g}; cross-validated there "
      "{:.2f} +- {:.2f}\n",
      j.surrogate_maximum, j.surrogate_k, j.surrogate_init_scale, j.surrogate_prior_count,
      j.evaluated_log_likelihood, j.evaluated_standard_error);
  std::cout << fmt::format(
      "  {}: {}\n",
      j.accepted ? "ACCEPTED"
                 : (moved ? "NOT ACCEPTED, SIMPLER EQUIVALENT CHOSEN" : "NOT ACCEPTED"),
      j.rule);
  const Plateau& pl = j.plateau;
  if (pl.flat) {
    std::cout << fmt::format(
        "  PLATEAU (joint): {} evaluations within {:.3g} of the best: k from {:.4g} to {:.4g}, f "
        "from {:.3g} to {:.3g}, nu0 from {:.3g} to {:.3g}\n",
        pl.members.size(), j.tolerance, pl.k_lo, pl.k_hi, pl.init_scale_lo, pl.init_scale_hi,
        pl.prior_count_lo, pl.prior_count_hi);
  }
  std::cout << "  Ceres fit: " << j.fit_report << "\n  Ceres maximisation: " << j.maximise_report
            << "\n";
}

void RunTuneK(const TuneKArgs& args) {
  if (args.with_terrain && args.without_terrain) {
    throw MakeInputError("", "--with-terrain/--without-terrain", "give at most one");
  }
  // Unwritable output folders are reported before the long run, not after it.
  for (const auto& [output, flag] :
       {std::pair{args.plot, "--plot"}, {args.curve_csv, "--curve-csv"}}) {
    if (output.empty()) continue;
    RefuseOutputThatIsAnInput(output, {args.path}, flag);
    AtomicFile probe(output);
  }
  const SampleSet set =
      SelectDimensions(ReadSampleSet(args.path), args.pose_dims, args.terrain_dims);
  if (set.size() == 0) throw MakeInputError(args.path, "samples", "the set is empty");
  if (args.folds < 2) throw MakeInputError(args.path, "--folds", "must be >= 2");
  RefuseMoreFoldsThanSamples(set, args.folds, args.path);
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
  options.cv.dgmm = DgmmOptionsFromFlags(args.dgmm, set.pose_dim() + set.terrain_dim());
  options.cv.group_by_episode = !args.stratified;
  options.plateau_tolerance = args.plateau_tolerance;
  options.init_scales = args.init_scales;
  options.prior_counts = args.prior_counts;
  options.k_min = args.k_min;
  options.k_max = args.k_max;
  options.grid_points = args.grid_points;
  options.refine_points = args.refine_points;
  options.joint = !args.no_joint;
  options.progress = [](int done, int total) {
    if (total >= 0) {
      ReportProgress("tune cross-validations", done, total);
    } else if (ShowProgress()) {
      std::fprintf(stderr, "\rtune cross-validations %d", done);
    }
  };
  std::string error;
  if (!options.IsValid(&error)) {
    throw OptionsError(args.path, error,
                       {{"k_min", "--k-min/--k-max"},
                        {"grid_points", "--grid-points"},
                        {"refine_points", "--refine-points"},
                        {"plateau_tolerance", "--plateau-tolerance"},
                        {"init_scales", "--init-scales"},
                        {"prior_counts", "--prior-counts"},
                        {"threads", "--threads"},
                        {"folds", "--folds"},
                        {"repeats", "--repeats"}});
  }
  const TuneKSummary s = TuneK(set, options);
  const std::string folds_by = s.folds_by;
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
                       {"components", p.components},
                       {"role", p.role}});
    }
    auto side = [](const std::vector<TuneKPoint>& pts) {
      nlohmann::json a = nlohmann::json::array();
      for (const auto& p : pts) {
        a.push_back({{"init_scale", p.init_scale},
                     {"prior_count", p.prior_count},
                     {"log_likelihood", p.log_likelihood},
                     {"standard_error", p.standard_error},
                     {"components", p.components}});
      }
      return a;
    };
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
        {"folds_by", folds_by},
        {"plateau",
         {{"flat", s.plateau},
          {"k_range", {s.plateau_k_lo, s.plateau_k_hi}},
          {"points", s.plateau_points},
          {"tolerance", s.plateau_tolerance}}},
        {"k_rule", s.k_rule},
        {"components", s.components},
        {"init_scale", s.init_scale_tuned ? nlohmann::json(s.init_scale) : nlohmann::json()},
        {"init_scale_plateau", s.init_scale_plateau},
        {"prior_count", s.prior_count_tuned ? nlohmann::json(s.prior_count) : nlohmann::json()},
        {"prior_count_plateau", s.prior_count_plateau},
        {"scale_curve", side(s.scale_curve)},
        {"prior_curve", side(s.prior_curve)},
        {"evaluations", s.evaluations},
        {"cycles", s.cycles},
        {"joint", JointJson(s.joint)},
        {"start_dgmm_options", DgmmOptionsJson(options.cv.dgmm)},
        {"seconds", s.seconds}};
    std::cout << out.dump(2) << "\n";
    return;
  }
  std::cout << fmt::format(
      "{}: {} samples, {} x {}-fold, {} terrain, seed {}; {} cross-validations in {} cycle(s) "
      "({:.1f} s)\n",
      args.path, s.samples, s.repeats, s.folds, s.with_terrain ? "with" : "without", args.seed,
      s.evaluations, s.cycles, s.seconds);
  // The coordinate steps' choice (the joint step's start when it ran; the final choice below).
  TuneKPoint cyclic = s.joint.start;
  if (!s.joint.run) {
    cyclic.k = s.k;
    cyclic.init_scale = s.init_scale;
    cyclic.prior_count = s.prior_count;
  }
  std::cout << "last k step (at the coordinate steps' S0 scale and nu0):\n";
  std::cout << "folds: " << folds_by << "\n";
  std::cout << fmt::format("{:>12}{:>16}{:>12}{:>14}{:>10}  {}\n", "k", "log-likelihood",
                           "std. error", "smoothed", "mean K", "");
  for (const auto& p : s.curve) {
    std::cout << fmt::format("{:>12.5g}{:>16.2f}{:>12.2f}{:>14.2f}{:>10.2f}  {}\n", p.k,
                             p.log_likelihood, p.standard_error, s.Smoothed(p.k), p.components,
                             p.role);
  }
  std::cout << fmt::format(
      "bracket [{:.4g}, {:.4g}]{}; quadratic fit on {} points\n", s.bracket_lo, s.bracket_hi,
      s.at_grid_edge ? " (best grid point at the edge: widen --k-min/--k-max)" : "", s.fit_points);
  if (s.plateau) {
    std::cout << fmt::format(
        "PLATEAU: {} evaluations within {:.3g} of the best, k from {:.4g} to {:.4g} are "
        "equivalent; k = {:.5g} is the simplest model there, not a sharp optimum\n",
        s.plateau_points, s.plateau_tolerance, s.plateau_k_lo, s.plateau_k_hi, cyclic.k);
  } else {
    std::cout << "k: " << s.k_rule << "\n";
  }
  auto print_side = [](const char* name, const std::vector<TuneKPoint>& pts, bool scale) {
    for (const auto& p : pts) {
      std::cout << fmt::format("  {} {:<8.3g} log-likelihood {:.2f} +- {:.2f}, mean K {:.2f}\n",
                               name, scale ? p.init_scale : p.prior_count, p.log_likelihood,
                               p.standard_error, p.components);
    }
  };
  if (s.init_scale_tuned) {
    print_side("S0 scale", s.scale_curve, true);
    std::cout << fmt::format(
        "S0 scale f = {:.3g}{}\n", cyclic.init_scale,
        s.init_scale_plateau ? " (PLATEAU: simplest of the equivalent values)" : "");
  }
  if (s.prior_count_tuned) {
    print_side("nu0", s.prior_curve, false);
    std::cout << fmt::format(
        "prior pseudo-count nu0 = {:.3g}{}\n", cyclic.prior_count,
        s.prior_count_plateau ? " (PLATEAU: simplest of the equivalent values)" : "");
  }
  PrintJoint(s);
  std::cout << fmt::format(
      "chosen k = {:.5g}: held-out log-likelihood {:.2f} +- {:.2f} (s.e.), {:.2f} Gaussians per "
      "command\n",
      s.k, s.log_likelihood, s.standard_error, s.components);
  std::cout << fmt::format(
      "fit with: dgmm fit {} --k {:.5g}{}{}{} -o model.h5\n", args.path, s.k,
      s.init_scale_tuned ? fmt::format(" --init-scale {:g}", s.init_scale) : "",
      s.prior_count_tuned ? fmt::format(" --prior-count {:g}", s.prior_count) : "",
      s.with_terrain ? "" : " --without-terrain");
}

void SetupTuneK(CLI::App& root) {
  auto args = std::make_shared<TuneKArgs>();
  CLI::App* cmd = root.add_subcommand(
      "tune",
      "Choose the DGMM merge rate k, the S0 scale and the prior strength by cross-validated "
      "log-likelihood (coordinate steps, then a joint Ceres quadratic step); reports plateaus");
  cmd->alias("tune-k");
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
  AddDgmmFlags(cmd, &args->dgmm);
  cmd->add_flag("--stratified", args->stratified,
                "Folds stratified by command even when the set has episodes");
  cmd->add_option("--plateau-tolerance", args->plateau_tolerance,
                  "Nats of held-out log-likelihood within which evaluations are equivalent "
                  "(0: one standard error of the best)")
      ->capture_default_str();
  cmd->add_option("--init-scales", args->init_scales,
                  "Grid of S0 scales f tried at the chosen k (--init-cov data); empty: keep")
      ->delimiter(',');
  cmd->add_option("--prior-counts", args->prior_counts,
                  "Grid of nu0 tried at the chosen k (--covariance prior); empty: keep")
      ->delimiter(',');
  cmd->add_option("--plot", args->plot, "Write the curve as a PNG line chart (needs X)");
  cmd->add_option("--curve-csv", args->curve_csv, "Write the curve as CSV");
  cmd->add_option("--pose-dims", args->pose_dims,
                  "Pose dimensions to model, by name (default: all)")
      ->delimiter(',');
  cmd->add_option("--terrain-dims", args->terrain_dims,
                  "Terrain dimensions to condition on, by name (default: all)")
      ->delimiter(',');
  cmd->add_flag("--no-joint", args->no_joint,
                "Skip the joint Ceres step after the coordinate cycles");
  cmd->add_flag("--json", args->json, "Print JSON");
  cmd->callback([args] { RunTuneK(*args); });
}

}  // namespace

DGMM_REGISTER_COMMAND("tune", SetupTuneK);

}  // namespace dgmm::app
