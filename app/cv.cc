// `dgmm cv`: repeated stratified K-fold cross-validation of a sample set (Table I of the paper):
// held-out log-likelihood of the DGMM with and without terrain and of an EM-BIC baseline.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "app/command.h"
#include "app/cv_flags.h"
#include "app/dgmm_flags.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "tune/cross_validation.h"
#include "tune/dimensions.h"
#include "util/error.h"

namespace dgmm::app {
namespace {

struct CvArgs : CvFlags {
  double k = 0.7;
  bool no_em = false;
  int em_max_components = 5;
  int em_n_init = 3;
  DgmmFlags dgmm;
};

nlohmann::json ScoreJson(const CvScore& s) {
  return {{"mean", s.mean},
          {"sd", s.sd},
          {"standard_error", s.standard_error},
          {"mean_per_sample", s.mean_per_sample},
          {"per_repeat", s.per_repeat},
          {"mean_components", s.mean_components}};
}

// One row of the table: its JSON key, its label, its score, and why it was omitted ("" when it
// was computed or not asked for).
struct Row {
  const char* key;
  const char* label;
  const CvScore* score;
  const std::string* omitted;
};

std::vector<Row> Rows(const CvSummary& summary) {
  static const std::string none;
  return {{"dgmm_without_terrain", "DGMM without terrain", &summary.dgmm_without_terrain, &none},
          {"dgmm_with_terrain", "DGMM with terrain", &summary.dgmm_with_terrain, &none},
          {"em_bic_without_terrain", "EM-BIC without terrain", &summary.em_without_terrain,
           &summary.em_without_terrain_omitted},
          {"em_bic_with_terrain", "EM-BIC with terrain", &summary.em_with_terrain,
           &summary.em_with_terrain_omitted}};
}

CvOptions MakeCvOptions(const CvArgs& args, const SampleSet& set) {
  CvOptions options;
  SetCvOptions(args, set, &options);
  options.without_terrain = !args.with_terrain;
  options.with_terrain = !args.without_terrain;
  options.dgmm = DgmmOptionsFromFlags(args.dgmm, set.pose_dim() + set.terrain_dim());
  options.dgmm.k = args.k;
  options.em_baseline = !args.no_em;
  options.em_max_components = args.em_max_components;
  options.em.n_init = args.em_n_init;
  options.progress = [](int done, int total) { ReportProgress("cv folds", done, total); };
  std::string error;
  if (!options.IsValid(&error)) {
    throw OptionsError(args.path, error,
                       {{"em_max_components", "--em-max-components"}, {"threads", "--threads"},
                        {"folds", "--folds"}, {"repeats", "--repeats"}, {"n_init", "--em-n-init"}});
  }
  return options;
}

// The terrain change of each family, by its JSON key.
std::vector<std::pair<std::string, const CvTerrainChange*>> TerrainChanges(const CvSummary& summary) {
  return {{"dgmm", &summary.dgmm_terrain_change}, {"em_bic", &summary.em_terrain_change}};
}

nlohmann::json CvJson(const CvArgs& args, const CvOptions& options, const CvSummary& summary) {
  nlohmann::json out = {{"file", args.path},
                        {"samples", summary.samples},
                        {"commands", summary.commands},
                        {"folds", summary.folds},
                        {"repeats", summary.repeats},
                        {"k", args.k},
                        {"seed", args.seed},
                        {"folds_by", summary.folds_by},
                        {"dgmm_options", DgmmOptionsJson(options.dgmm)},
                        {"shuffle_training", args.shuffle_training},
                        {"has_terrain", summary.has_terrain},
                        {"scored_per_repeat", summary.scored_per_repeat},
                        {"unscored_per_repeat", summary.unscored_per_repeat},
                        {"seconds", summary.seconds}};
  out["rows"] = nlohmann::json::object();
  out["omitted_rows"] = nlohmann::json::object();
  for (const Row& row : Rows(summary)) {
    if (row.score->evaluated) out["rows"][row.key] = ScoreJson(*row.score);
    if (!row.omitted->empty()) out["omitted_rows"][row.key] = *row.omitted;
  }
  out["terrain_change"] = nlohmann::json::object();
  for (const auto& [key, change] : TerrainChanges(summary)) {
    if (change->evaluated) out["terrain_change"][key] = {{"mean", change->mean}, {"paired_standard_error", change->standard_error}};
  }
  return out;
}

void PrintCvTable(const CvArgs& args, const CvSummary& summary) {
  std::cout << fmt::format(
      "{}: {}, {}; {} x {}-fold cross-validation, k = {}, seed {} ({})\n"
      "folds: {}; DGMM: {} variant, covariance {}, S0 {}\n",
      args.path, Plural(summary.samples, "sample"), Plural(summary.commands, "command"),
      summary.repeats, summary.folds, args.k, args.seed, FormatSeconds(summary.seconds),
      summary.folds_by, args.dgmm.variant, args.dgmm.covariance,
      fmt::format("{}", fmt::join(args.dgmm.init_cov, ",")));
  if (summary.unscored_per_repeat > 0) {
    std::cout << fmt::format(
        "note: {} held-out samples per repeat not scored (their command has no sample outside "
        "their fold, e.g. it was recorded in one episode)\n",
        summary.unscored_per_repeat);
  }
  std::cout << "held-out log-likelihood, summed over all validation folds of a repeat\n";
  std::cout << fmt::format("{:<24}{:>22}{:>12}{:>12}{:>10}\n", "model", "mean +- sd (repeats)",
                           "std. error", "per sample", "mean K");
  const std::vector<Row> rows = Rows(summary);
  for (const Row& row : rows) {
    if (!row.score->evaluated) continue;
    const CvScore& s = *row.score;
    const std::string k = s.mean_components > 0 ? fmt::format("{:.2f}", s.mean_components) : "";
    std::cout << fmt::format("{:<24}{:>22}{:>12.1f}{:>12.3f}{:>10}\n", row.label,
                             fmt::format("{:.1f} +- {:.1f}", s.mean, s.sd), s.standard_error,
                             s.mean_per_sample, k);
  }
  for (const Row& row : rows) {
    if (!row.omitted->empty()) std::cout << row.label << ": omitted, " << *row.omitted << "\n";
  }
  if (!summary.has_terrain) std::cout << "(the set has no terrain: no with-terrain rows)\n";
  for (const auto& [key, change] : TerrainChanges(summary)) {
    if (!change->evaluated) continue;
    const double z = change->standard_error > 0 ? change->mean / change->standard_error : 0;
    std::cout << fmt::format("conditioning on terrain changes {} by {:+.1f} (paired std. error {:.1f}, {:+.1f} of them)\n",
                             key == "dgmm" ? "DGMM" : "EM-BIC", change->mean, change->standard_error, z);
  }
}

void RunCv(const CvArgs& args) {
  if (!(args.k > 0) || !std::isfinite(args.k)) {
    throw MakeInputError("", "--k", fmt::format("must be a finite number > 0, got {}", args.k));
  }
  const SampleSet set = ReadCvSet(args);
  const CvOptions options = MakeCvOptions(args, set);
  WarnIfUnderdetermined(set, !args.without_terrain, "cv", true);
  const CvSummary summary = CrossValidate(set, options);
  if (args.json) {
    std::cout << CvJson(args, options, summary).dump(2) << "\n";
    return;
  }
  PrintCvTable(args, summary);
}

void SetupCv(CLI::App& root) {
  auto args = std::make_shared<CvArgs>();
  CLI::App* cmd = root.add_subcommand(
      "cv",
      "Cross-validated held-out log-likelihood (Table I): DGMM and EM-BIC, with and "
      "without terrain");
  AddCvFlags(cmd, args.get());
  cmd->add_option("--k", args->k, "DGMM merge rate k > 0")->capture_default_str();
  cmd->add_flag("--no-em", args->no_em, "Skip the EM-BIC baseline");
  cmd->add_option("--em-max-components", args->em_max_components,
                  "EM-BIC: largest number of components tried per command")
      ->capture_default_str();
  cmd->add_option("--em-n-init", args->em_n_init, "EM restarts per fit")->capture_default_str();
  AddDgmmFlags(cmd, &args->dgmm);
  cmd->add_flag("--with-terrain", args->with_terrain,
                "Only the with-terrain rows, p(x | c, z) (default: both)");
  cmd->add_flag("--without-terrain", args->without_terrain,
                "Only the without-terrain rows, p(x | c) (as fit --without-terrain)");
  cmd->callback([args, cmd] {
    NoteFoldsGiven(*cmd, args.get());
    RunCv(*args);
  });
}

}  // namespace

DGMM_REGISTER_COMMAND("cv", SetupCv);

}  // namespace dgmm::app
