// `dgmm fit`: one DGMM per command (Algorithm 2, ADDSAMPLE), streamed from a sample set file
// chunk by chunk, so memory does not grow with the file.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/command.h"
#include "app/dgmm_flags.h"
#include "io/model_io.h"
#include "io/sample_stream.h"
#include "io/streaming.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/output_guard.h"

namespace dgmm::app {
namespace {

struct FitArgs {
  std::string set, output;
  double k = 0.7;
  DgmmFlags dgmm;
  std::uint64_t seed = 1;
  bool without_terrain = false;
  int chunk_rows = 65536;
  long long max_components = 0;
  bool max_components_given = false;  // false: DefaultMaxComponents
  bool json = false;
};

// DGMM options from the flags, checked against the set's dimension.
MotionModelOptions Options(const FitArgs& args) {
  if (!std::isfinite(args.k) || args.k <= 0) {
    throw MakeInputError(args.set, "--k",
                         fmt::format("must be a finite number > 0, got {}", args.k));
  }
  MotionModelOptions o;
  o.seed = args.seed;
  o.with_terrain = !args.without_terrain;
  const SampleSetReader reader(args.set);
  const SampleSet& header = reader.header();
  const int dim = header.pose_dim() + (o.with_terrain ? header.terrain_dim() : 0);
  try {
    o.dgmm = DgmmOptionsFromFlags(args.dgmm, dim);
  } catch (const InputError& e) {
    throw MakeInputError(args.set, "", e.what());
  }
  if (args.max_components_given && (args.max_components < 1 || args.max_components > 1000000000)) {
    throw MakeInputError(args.set, "--max-components",
                         fmt::format("{}; expected 1 to 1e9", args.max_components));
  }
  o.dgmm.max_components = static_cast<int>(
      args.max_components_given ? args.max_components : DefaultMaxComponents(reader.size(), dim));
  o.dgmm.k = args.k;
  std::string error;
  if (!o.dgmm.IsValid(&error)) throw MakeInputError(args.set, "options", error);
  return o;
}

void Run(const FitArgs& args) {
  RefuseOutputThatIsAnInput(args.output, {args.set});
  { AtomicFile probe(args.output); }  // fail before the work when the output is unwritable
  const MotionModelOptions options = Options(args);
  const auto start = std::chrono::steady_clock::now();
  std::string warning;
  MotionModel model = LearnMotionModelFromFile(
      args.set, options, args.chunk_rows,
      [](long long done, long long total) { ReportProgress("fit", done, total); }, &warning);
  if (!warning.empty()) std::cerr << "warning: " << args.set << ": " << warning << "\n";
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  model.metadata["training_set"] = std::filesystem::path(args.set).filename().string();
  for (const auto& [id, hit] : model.max_components_hit) {
    if (!hit) continue;
    auto label = model.command_labels.find(id);
    std::cerr << fmt::format(
        "dgmm: warning: {}: command {}{}: the mixture reached --max-components {} and stopped "
        "growing (later samples merged); raise --max-components or k\n",
        args.set, id, label == model.command_labels.end() ? "" : " '" + label->second + "'",
        options.dgmm.max_components);
  }
  WriteModel(model, args.output);

  long long samples = 0;
  nlohmann::json commands = nlohmann::json::array();
  for (const auto& [id, mixture] : model.mixtures) {
    auto label = model.command_labels.find(id);
    const long long n = std::llround(mixture.total_weight());
    samples += n;
    commands.push_back({{"command", id},
                        {"label", label == model.command_labels.end() ? "" : label->second},
                        {"components", mixture.size()},
                        {"max_components_hit", model.max_components_hit.count(id) > 0},
                        {"samples", n}});
  }
  if (args.json) {
    nlohmann::json out = {{"set", args.set},
                          {"model", args.output},
                          {"kind", model.kind},
                          {"k", args.k},
                          {"seed", args.seed},
                          {"variant", args.dgmm.variant},
                          {"dgmm_options", DgmmOptionsJson(model.dgmm_options)},
                          {"dim", model.dim()},
                          {"samples", samples},
                          {"seconds", seconds},
                          {"max_components", options.dgmm.max_components},
                          {"commands", commands}};
    std::cout << out.dump(2) << "\n";
    return;
  }
  std::printf("fitted a DGMM per command (k = %g, seed %llu, %s, d = %d) on %s in %s\n", args.k,
              static_cast<unsigned long long>(args.seed), args.dgmm.variant.c_str(), model.dim(),
              Plural(samples, "sample").c_str(), FormatSeconds(seconds).c_str());
  const DgmmOptions& o = model.dgmm_options;
  std::printf("  covariance %s%s, S0 %s (diagonal %s), floor %.3g\n",
              CovarianceRuleName(o.covariance_rule),
              o.covariance_rule == DgmmOptions::CovarianceRule::kPrior
                  ? fmt::format(" (nu0 = {:g})", o.prior_pseudo_count).c_str()
                  : "",
              InitialCovarianceRuleName(o.initial_covariance_rule),
              fmt::format("{:.3g}", fmt::join(o.initial_covariance_diagonal, ", ")).c_str(),
              o.covariance_floor);
  for (const auto& c : commands) {
    std::printf("  command %d '%s': %s from %s\n", c["command"].get<int>(),
                c["label"].get<std::string>().c_str(),
                Plural(c["components"].get<int>(), "component").c_str(),
                Plural(c["samples"].get<long long>(), "sample").c_str());
  }
  std::printf("wrote %s\n", args.output.c_str());
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<FitArgs>();
  CLI::App* cmd = root.add_subcommand(
      "fit",
      "Fit one Dynamic Gaussian Mixture Model per command (Edgington et al. 2009, Algorithm 2) "
      "by streaming the sample set chunk by chunk; y = x||z unless --without-terrain.");
  cmd->add_option("set", args->set, "sample set file (.h5)")->required();
  cmd->add_option("-o,--output", args->output, "model file to write (.h5)")->required();
  cmd->add_option("--k", args->k, "merge rate k > 0 in t = 1 - (1 - d) exp(-k n)")
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "seed of the random generator")->capture_default_str();
  cmd->add_flag("--without-terrain", args->without_terrain, "model x alone, ignoring z");
  AddDgmmFlags(cmd, &args->dgmm);
  cmd->add_option("--chunk-rows", args->chunk_rows, "samples read per chunk")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000000));
  CLI::Option* cap = cmd->add_option("--max-components", args->max_components,
                  "cap on components per mixture; at the cap every sample merges (default: "
                  "max(50, min(ceil(sqrt(N)), N / (d + 1), 2e9 / (N d^2))) for N samples of "
                  "dimension d)");
  cmd->add_flag("--json", args->json, "print the summary as JSON");
  cmd->callback([args, cap] {
    args->max_components_given = cap->count() > 0;
    Run(*args);
  });
}

}  // namespace
DGMM_REGISTER_COMMAND("fit", Setup);
}  // namespace dgmm::app
