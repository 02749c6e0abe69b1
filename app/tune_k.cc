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
#include "app/cv_flags.h"
#include "app/dgmm_flags.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "render/chart.h"
#include "render/display.h"
#include "tune/dimensions.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/output_guard.h"

namespace dgmm::app {
namespace {

struct TuneKArgs : CvFlags {
  double k_min = 1e-3, k_max = 10;
  int grid_points = 9, refine_points = 4;
  double plateau_tolerance = 0;
  std::vector<double> init_scales = TuneKOptions{}.init_scales;
  std::vector<double> prior_counts = TuneKOptions{}.prior_counts;
  DgmmFlags dgmm;
  std::string plot, curve_csv;
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
  spec.title = fmt::format("tune: k = {:.3g}, held-out log-likelihood {:.1f} +- {:.1f}{}", s.k,
                           s.log_likelihood, s.standard_error,
                           s.plateau_spans_grid ? " (k not identifiable)" : "");
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
  // The plateau as a band: its range of k at the best evaluation and at the best minus the
  // tolerance (the evaluations between the two lines are equivalent).
  if (s.plateau) {
    const double top = s.best_evaluated_log_likelihood, bottom = top - s.plateau_tolerance;
    spec.series.push_back(
        {fmt::format("plateau: {}", s.PlateauMeaning()),
         {s.plateau_k_lo, s.plateau_k_lo, s.plateau_k_hi, s.plateau_k_hi, s.plateau_k_lo},
         {bottom, top, top, bottom, bottom},
         {},
         std::array<unsigned char, 3>{120, 120, 120}});
  }
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

// The recommended settings as command-line words: --k, the tuned --init-scale and --prior-count
// (or the user's when not tuned and not the default) and the user's other non-default DGMM flags.
std::vector<std::string> RecommendedFlags(const TuneKSummary& s, const TuneKArgs& args) {
  std::vector<std::string> words = {"--k", fmt::format("{:.6g}", s.k)};
  const DgmmFlags defaults;
  if (s.init_scale_tuned || args.dgmm.init_scale != defaults.init_scale) {
    words.insert(words.end(),
                 {"--init-scale",
                  fmt::format("{:.6g}", s.init_scale_tuned ? s.init_scale : args.dgmm.init_scale)});
  }
  if (s.prior_count_tuned || args.dgmm.prior_count != defaults.prior_count) {
    words.insert(words.end(), {"--prior-count",
                               fmt::format("{:.6g}", s.prior_count_tuned ? s.prior_count
                                                                         : args.dgmm.prior_count)});
  }
  const std::vector<std::string> other = NonDefaultDgmmFlags(args.dgmm);
  words.insert(words.end(), other.begin(), other.end());
  return words;
}

// The two recipes `tune` prints: fit the recommended model, and cross-validate it with the same
// folds, repeats and seed (its DGMM row reproduces the recommended log-likelihood).
std::pair<std::string, std::string> Recipes(const TuneKSummary& s, const TuneKArgs& args) {
  const std::string flags = fmt::format("{}", fmt::join(RecommendedFlags(s, args), " "));
  const std::string terrain = s.with_terrain ? "" : " --without-terrain";
  std::string fit =
      fmt::format("dgmm fit {} {}{} --seed {} -o model.h5", args.path, flags, terrain, args.seed);
  std::string cv = fmt::format("dgmm cv {} {}{}", args.path, flags, terrain);
  if (args.folds_given) cv += fmt::format(" --folds {}", args.folds);
  if (args.stratified) cv += " --stratified";
  if (args.shuffle_training) cv += " --shuffle-training";
  if (!args.pose_dims.empty()) cv += fmt::format(" --pose-dims {}", fmt::join(args.pose_dims, ","));
  if (!args.terrain_dims.empty()) {
    cv += fmt::format(" --terrain-dims {}", fmt::join(args.terrain_dims, ","));
  }
  cv += fmt::format(" --repeats {} --seed {}", args.repeats, args.seed);
  return {fit, cv};
}

nlohmann::json PointsJson(const std::vector<TuneKPoint>& pts, const TuneKSummary* s) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& p : pts) {
    nlohmann::json point = {{"k", p.k},
                            {"init_scale", p.init_scale},
                            {"prior_count", p.prior_count},
                            {"log_likelihood", p.log_likelihood},
                            {"sd", p.sd},
                            {"standard_error", p.standard_error},
                            {"components", p.components},
                            {"role", p.role}};
    if (s) point["smoothed"] = s->Smoothed(p.k);
    a.push_back(point);
  }
  return a;
}

// `tune --json` (documented in docs/log-import.md, "What tune reports"): what to use first
// ("recommended"), then how each setting was searched.
nlohmann::json TuneJson(const TuneKSummary& s, const TuneKArgs& args, const TuneKOptions& options) {
  const auto [fit, cv] = Recipes(s, args);
  auto or_null = [](bool tuned, double v) { return tuned ? nlohmann::json(v) : nlohmann::json(); };
  return {{"file", args.path},
          {"samples", s.samples},
          {"with_terrain", s.with_terrain},
          {"folds", s.folds},
          {"folds_by", s.folds_by},
          {"repeats", s.repeats},
          {"seed", args.seed},
          {"recommended",
           {{"k", s.k},
            {"init_scale", or_null(s.init_scale_tuned, s.init_scale)},
            {"prior_count", or_null(s.prior_count_tuned, s.prior_count)},
            {"log_likelihood", s.log_likelihood},
            {"standard_error", s.standard_error},
            {"sd", s.sd},
            {"components_per_command", s.components},
            {"flags", RecommendedFlags(s, args)},
            {"fit_command", fit},
            {"cv_command", cv}}},
          {"k_search",
           {{"grid", {{"k_min", s.k_min}, {"k_max", s.k_max}, {"points", options.grid_points}}},
            {"best_grid_k", s.best_grid_k},
            {"optimum_at_grid_edge", !s.grid_edge.empty()},
            {"grid_edge", s.grid_edge.empty() ? nlohmann::json() : nlohmann::json(s.grid_edge)},
            {"bracket", {s.bracket_lo, s.bracket_hi}},
            {"quadratic_refinement",
             {{"k_at_maximum", s.quadratic_k},
              {"u0", s.u0},
              {"a", s.a},
              {"b", s.b},
              {"c", s.c},
              {"points", s.fit_points},
              {"fit_report", s.fit_report},
              {"maximise_report", s.maximise_report}}},
            {"best_evaluated",
             {{"k", s.best_evaluated_k}, {"log_likelihood", s.best_evaluated_log_likelihood}}},
            {"plateau",
             {{"flat", s.plateau},
              {"k_range", {s.plateau_k_lo, s.plateau_k_hi}},
              {"points", s.plateau_points},
              {"tolerance", s.plateau_tolerance},
              {"spans_whole_grid", s.plateau_spans_grid},
              {"meaning", s.PlateauMeaning()}}},
            {"rule", s.k_rule},
            {"curve", PointsJson(s.curve, &s)}}},
          {"init_scale_search",
           {{"tuned", s.init_scale_tuned},
            {"plateau", s.init_scale_plateau},
            {"curve", PointsJson(s.scale_curve, nullptr)}}},
          {"prior_count_search",
           {{"tuned", s.prior_count_tuned},
            {"plateau", s.prior_count_plateau},
            {"curve", PointsJson(s.prior_curve, nullptr)}}},
          {"joint", JointJson(s.joint)},
          {"evaluations", s.evaluations},
          {"cycles", s.cycles},
          {"start_dgmm_options", DgmmOptionsJson(options.cv.dgmm)},
          {"seconds", s.seconds}};
}

// The k step, f and nu0 steps as text.
void PrintSearch(const TuneKSummary& s) {
  // The coordinate steps' choice (the joint step's start when it ran; the final choice below).
  TuneKPoint cyclic = s.joint.start;
  if (!s.joint.run) {
    cyclic.k = s.k;
    cyclic.init_scale = s.init_scale;
    cyclic.prior_count = s.prior_count;
  }
  std::cout << "last k step (at the coordinate steps' S0 scale and nu0):\n";
  std::cout << fmt::format("{:>12}{:>16}{:>12}{:>14}{:>10}  {}\n", "k", "log-likelihood",
                           "std. error", "smoothed", "mean K", "");
  for (const auto& p : s.curve) {
    std::cout << fmt::format("{:>12.5g}{:>16.2f}{:>12.2f}{:>14.2f}{:>10.2f}  {}\n", p.k,
                             p.log_likelihood, p.standard_error, s.Smoothed(p.k), p.components,
                             p.role);
  }
  std::cout << fmt::format(
      "bracket [{:.4g}, {:.4g}]; quadratic refinement on {} points: maximum at "
      "k = {:.4g}\n",
      s.bracket_lo, s.bracket_hi, s.fit_points, s.quadratic_k);
  if (s.plateau) {
    // The meaning names the range itself unless the plateau is the whole grid.
    const std::string range = s.plateau_spans_grid
                                  ? fmt::format(", k from {:.4g} to {:.4g} (the whole grid)",
                                                s.plateau_k_lo, s.plateau_k_hi)
                                  : "";
    std::cout << fmt::format(
        "PLATEAU: {} evaluations within {:.3g} of the best{}: {}: k = {:.5g}\n", s.plateau_points,
        s.plateau_tolerance, range, s.PlateauMeaning(), cyclic.k);
  } else {
    std::cout << "k: " << s.k_rule << "\n";
  }
  if (!s.grid_edge.empty() && !s.plateau_spans_grid) {
    std::cout << fmt::format(
        "k at the {} end of the grid [{:.4g}, {:.4g}]: the optimum may lie "
        "beyond it (widen {})\n",
        s.grid_edge, s.k_min, s.k_max, s.grid_edge == "low" ? "--k-min" : "--k-max");
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
}

TuneKOptions MakeTuneOptions(const TuneKArgs& args, const SampleSet& set) {
  TuneKOptions options;
  options.with_terrain = !args.without_terrain;
  SetCvOptions(args, set, &options.cv);
  options.cv.dgmm = DgmmOptionsFromFlags(args.dgmm, set.pose_dim() + set.terrain_dim());
  options.plateau_tolerance = args.plateau_tolerance;
  options.init_scales = args.init_scales;
  options.prior_counts = args.prior_counts;
  options.k_min = args.k_min;
  options.k_max = args.k_max;
  options.grid_points = args.grid_points;
  options.refine_points = args.refine_points;
  options.joint = !args.no_joint;
  options.progress = [](int done, int total) {
    ReportProgress("tune cross-validations", done, total);
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
  return options;
}

void RunTuneK(const TuneKArgs& args) {
  // Unwritable output folders are reported before the long run, not after it.
  for (const auto& [output, flag] :
       {std::pair{args.plot, "--plot"}, {args.curve_csv, "--curve-csv"}}) {
    if (output.empty()) continue;
    RefuseOutputThatIsAnInput(output, {args.path}, flag);
    AtomicFile probe(output);
  }
  if (!args.plot.empty()) RequireDisplay();  // before the long run, not after it
  const SampleSet set = ReadCvSet(args);
  const TuneKOptions options = MakeTuneOptions(args, set);
  WarnIfUnderdetermined(set, !args.without_terrain, "tune", true);
  const TuneKSummary s = TuneK(set, options);
  if (!args.curve_csv.empty()) WriteCurveCsv(s, args.curve_csv);
  if (!args.plot.empty()) PlotCurve(s, args.plot);
  if (args.json) {
    std::cout << TuneJson(s, args, options).dump(2) << "\n";
    return;
  }
  std::cout << fmt::format("{}: {}, {} x {}-fold, {} terrain, seed {}; {} in {} ({})\n", args.path,
                           Plural(s.samples, "sample"), s.repeats, s.folds,
                           s.with_terrain ? "with" : "without", args.seed,
                           Plural(s.evaluations, "cross-validation"), Plural(s.cycles, "cycle"),
                           FormatSeconds(s.seconds));
  std::cout << "folds: " << s.folds_by << "\n";
  PrintSearch(s);
  PrintJoint(s);
  std::cout << fmt::format(
      "chosen k = {:.5g}: held-out log-likelihood {:.2f} +- {:.2f} (s.e.), {:.2f} Gaussians per "
      "command\n",
      s.k, s.log_likelihood, s.standard_error, s.components);
  const auto [fit, cv] = Recipes(s, args);
  std::cout << "fit with: " << fit << "\n";
  std::cout << "cross-validate with: " << cv << "\n";
}

void SetupTuneK(CLI::App& root) {
  auto args = std::make_shared<TuneKArgs>();
  CLI::App* cmd = root.add_subcommand(
      "tune",
      "Choose the DGMM merge rate k, the S0 scale and the prior strength by cross-validated "
      "log-likelihood (coordinate steps, then a joint Ceres quadratic step); reports plateaus");
  cmd->alias("tune-k");
  AddCvFlags(cmd, args.get());
  cmd->add_flag("--with-terrain", args->with_terrain, "Maximise p(x | c, z) (the default)");
  cmd->add_flag("--without-terrain", args->without_terrain, "Maximise p(x | c)");
  cmd->add_option("--k-min", args->k_min, "Smallest k of the coarse grid")->capture_default_str();
  cmd->add_option("--k-max", args->k_max, "Largest k of the coarse grid")->capture_default_str();
  cmd->add_option("--grid-points", args->grid_points, "Coarse grid points (log spaced)")
      ->capture_default_str();
  cmd->add_option("--refine-points", args->refine_points, "Extra evaluations in the bracket")
      ->capture_default_str();
  AddDgmmFlags(cmd, &args->dgmm);
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
  cmd->add_flag("--no-joint", args->no_joint,
                "Skip the joint Ceres step after the coordinate cycles");
  cmd->callback([args, cmd] {
    NoteFoldsGiven(*cmd, args.get());
    RunTuneK(*args);
  });
}

}  // namespace

DGMM_REGISTER_COMMAND("tune", SetupTuneK);

}  // namespace dgmm::app
