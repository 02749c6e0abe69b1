// `dgmm score`: total and mean log-likelihood of a sample set under a model, streamed from the
// file chunk by chunk, with a per-command breakdown.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "app/command.h"
#include "io/model_io.h"
#include "io/streaming.h"
#include "util/error.h"

namespace dgmm::app {
namespace {

struct ScoreArgs {
  std::string model, set;
  int chunk_rows = 65536;
  bool json = false;
};

void Run(const ScoreArgs& args) {
  const MotionModel model = ReadModel(args.model);
  const FileScore score = ScoreSampleSetFile(
      model, args.set, args.chunk_rows,
      [](long long done, long long total) { ReportProgress("score", done, total); });
  const ScoreSummary& s = score.summary;
  if (std::isnan(s.total_log_likelihood) || s.samples == 0) {
    throw MakeInputError(args.model, "",
                         "the score of " + args.set + " is not a number (" +
                             std::to_string(s.samples) + " samples); nothing to report");
  }
  if (args.json) {
    nlohmann::json commands = nlohmann::json::array();
    for (const auto& [id, c] : score.by_command) {
      commands.push_back({{"command", id},
                          {"label", c.label},
                          {"samples", c.samples},
                          {"total_log_likelihood", c.total_log_likelihood},
                          {"mean_log_likelihood", c.total_log_likelihood / c.samples}});
    }
    nlohmann::json out = {{"model", args.model},
                          {"set", args.set},
                          {"total_log_likelihood", s.total_log_likelihood},
                          {"mean_log_likelihood", s.mean_log_likelihood},
                          {"samples", s.samples},
                          {"commands", commands}};
    std::cout << out.dump(2) << "\n";
    return;
  }
  std::printf("total log-likelihood %.10g over %s, mean %.6f nats per sample\n",
              s.total_log_likelihood, Plural(s.samples, "sample").c_str(), s.mean_log_likelihood);
  for (const auto& [id, c] : score.by_command) {
    std::printf("  command %d '%s': %s, total %.10g, mean %.6f\n", id, c.label.c_str(),
                Plural(c.samples, "sample").c_str(), c.total_log_likelihood,
                c.total_log_likelihood / c.samples);
  }
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<ScoreArgs>();
  CLI::App* cmd = root.add_subcommand(
      "score",
      "Log-likelihood of a sample set under a model: sum log p(x | c) (or p(x | c, z) when the "
      "model has terrain), in the raw units of x. Commands are matched by label.");
  cmd->add_option("model", args->model, "model file (.h5)")->required();
  cmd->add_option("set", args->set, "sample set file (.h5)")->required();
  cmd->add_option("--chunk-rows", args->chunk_rows, "samples read per chunk")
      ->capture_default_str()
      ->check(CLI::Range(1, 100000000));
  cmd->add_flag("--json", args->json,
                "print total_log_likelihood, mean_log_likelihood, samples and per-command "
                "figures as JSON");
  cmd->callback([args] { Run(*args); });
}

}  // namespace
DGMM_REGISTER_COMMAND("score", Setup);
}  // namespace dgmm::app
