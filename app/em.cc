// `dgmm em`: the EM reference, one full-covariance Gaussian mixture per command over y = x||z
// (or x alone with --without-terrain), fitted with k-means++ init and n_init restarts.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "app/command.h"
#include "em/em.h"
#include "em/em_model.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "io/streaming.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/output_guard.h"

namespace dgmm::app {
namespace {

struct EmArgs {
  std::string set, output;
  EmOptions em;
  bool without_terrain = false;
  bool json = false;
};

nlohmann::json OptionsJson(const EmArgs& args) {
  return {{"components", args.em.components},   {"n_init", args.em.n_init},
          {"max_iterations", args.em.max_iterations}, {"tolerance", args.em.tolerance},
          {"reg_covar", args.em.reg_covar},      {"seed", args.em.seed},
          {"with_terrain", !args.without_terrain}, {"init", "kmeans++ then Lloyd"}};
}

void Run(const EmArgs& args) {
  std::string error;
  if (!args.em.IsValid(&error)) {
    throw OptionsError(args.set, error,
                       {{"components", "--components"}, {"n_init", "--n-init"},
                        {"max_iterations", "--max-iter"}, {"tolerance", "--tol"},
                        {"reg_covar", "--reg-covar"}});
  }
  RefuseOutputThatIsAnInput(args.output, {args.set});
  { AtomicFile probe(args.output); }  // fail before the work when the output is unwritable
  const SampleSet set = ReadSampleSet(args.set);
  WarnIfUnderdetermined(set, !args.without_terrain, "em", false);
  const auto start = std::chrono::steady_clock::now();
  EmModelResult fitted = FitEmMotionModel(set, args.em, !args.without_terrain, args.set,
                                          [](long long done, long long total) { ReportProgress("em", done, total); });
  MotionModel& model = fitted.model;
  const int dim = model.dim();
  nlohmann::json commands = nlohmann::json::array();
  double total = 0;
  long long samples = 0;
  for (const auto& [id, s] : fitted.summaries) {
    const std::string label = id < static_cast<int>(set.command_labels.size()) ? set.command_labels[id] : "";
    total += s.log_likelihood;
    samples += s.samples;
    commands.push_back({{"command", id},
                        {"label", label},
                        {"samples", s.samples},
                        {"components", model.mixtures.at(id).size()},
                        {"total_log_likelihood", s.log_likelihood},
                        {"mean_log_likelihood", s.mean_log_likelihood},
                        {"iterations", s.iterations},
                        {"converged", s.converged},
                        {"restarts", s.restarts},
                        {"failed_restarts", s.failed_restarts},
                        {"bic", s.bic},
                        {"report", s.BriefReport()}});
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  model.metadata["training_set"] = std::filesystem::path(args.set).filename().string();
  model.metadata["em_options"] = OptionsJson(args).dump();
  WriteModel(model, args.output);

  const double mean = total / static_cast<double>(samples);
  if (args.json) {
    nlohmann::json out = {{"set", args.set},
                          {"model", args.output},
                          {"kind", model.kind},
                          {"options", OptionsJson(args)},
                          {"dim", dim},
                          {"samples", samples},
                          {"total_log_likelihood", total},
                          {"mean_log_likelihood", mean},
                          {"units", set.transform.empty() ? "raw" : "standardised"},
                          {"seconds", seconds},
                          {"commands", commands}};
    std::cout << out.dump(2) << "\n";
    return;
  }
  std::printf("fitted an EM mixture per command (%s, %s, seed %llu, d = %d) on %s in %s\n",
              Plural(args.em.components, "component").c_str(),
              Plural(args.em.n_init, "restart").c_str(),
              static_cast<unsigned long long>(args.em.seed), dim, Plural(samples, "sample").c_str(),
              FormatSeconds(seconds).c_str());
  for (const auto& c : commands) {
    std::printf("  command %d '%s': %s\n", c["command"].get<int>(),
                c["label"].get<std::string>().c_str(), c["report"].get<std::string>().c_str());
  }
  std::printf("mean log-likelihood %.6f nats per sample (%s units of the set)\nwrote %s\n", mean,
              set.transform.empty() ? "raw" : "standardised", args.output.c_str());
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<EmArgs>();
  CLI::App* cmd = root.add_subcommand(
      "em",
      "Fit the EM reference: one full-covariance Gaussian mixture per command over y = x||z "
      "(x alone with --without-terrain), k-means++ initialisation, best of --n-init restarts "
      "(scikit-learn GaussianMixture semantics).");
  cmd->add_option("set", args->set, "sample set file (.h5)")->required();
  cmd->add_option("-o,--output", args->output, "model file to write (.h5)")->required();
  cmd->add_option("--components", args->em.components, "mixture components per command (>= 1)")
      ->capture_default_str();
  cmd->add_option("--seed", args->em.seed, "seed of the k-means++ initialisation")
      ->capture_default_str();
  cmd->add_option("--n-init", args->em.n_init, "restarts; the best log-likelihood wins")
      ->capture_default_str();
  cmd->add_option("--max-iter", args->em.max_iterations, "E+M steps per restart")
      ->capture_default_str();
  cmd->add_option("--tol", args->em.tolerance,
                  "stop when the mean log-likelihood per sample changes by less than this")
      ->capture_default_str();
  cmd->add_option("--reg-covar", args->em.reg_covar, "added to every covariance diagonal")
      ->capture_default_str();
  cmd->add_flag("--without-terrain", args->without_terrain, "model x alone, ignoring z");
  cmd->add_flag("--json", args->json, "print the per-command summaries as JSON");
  cmd->callback([args] { Run(*args); });
}

}  // namespace
DGMM_REGISTER_COMMAND("em", Setup);
}  // namespace dgmm::app
