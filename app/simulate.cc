// `dgmm simulate`: records a sample set with the simulated robot (built-in or a robot block) following the
// paper's protocol (lib/sim/protocol.h, docs/simulation.md) and writes it as HDF5.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/command.h"
#include "io/sample_set_io.h"
#include "sim/protocol.h"
#include "sim/sim_config.h"
#include "util/error.h"
#include "util/output_guard.h"

namespace dgmm::app {
namespace {

struct SimulateArgs {
  std::string config_path;
  std::string protocol = "paper";
  std::uint64_t seed = 0;
  std::string output;
  int placements = 0;
  int executions = 5;
  bool json = false;
  bool print_config = false;
};

void RunSimulate(const SimulateArgs& args) {
  const sim::SimConfig config =
      args.config_path.empty() ? sim::SimConfig{} : sim::LoadSimConfig(args.config_path);
  if (args.print_config) {
    std::cout << sim::SimConfigToJson(config);
    return;
  }
  if (args.output.empty()) throw MakeInputError("", "--output", "required (the .h5 file to write)");
  RefuseOutputThatIsAnInput(args.output, {args.config_path});
  const std::filesystem::path folder =
      std::filesystem::absolute(args.output).parent_path();
  if (!std::filesystem::is_directory(folder)) {
    throw MakeInputError(args.output, "", "its folder does not exist");
  }
  sim::ProtocolOptions options;
  options.protocol = sim::ParseProtocol(args.protocol);
  options.seed = args.seed;
  options.placements = args.placements;
  options.executions_per_placement = args.executions;
  std::string error;
  if (!options.IsValid(&error)) {
    throw OptionsError("", error,
                       {{"executions_per_placement", "--executions"},
                        {"placements", "--placements"}});
  }

  sim::SimSummary summary;
  const SampleSet set = sim::SimulateProtocol(
      config, options,
      [](long long done, long long total) { ReportProgress("simulate: placement", done, total); },
      &summary);
  for (const std::string& w : summary.warnings) Warn(args.config_path + ": " + w);  // they may say why
  if (set.size() == 0) {
    throw MakeInputError(args.config_path, "", "every placement fell; nothing to write (" +
                                                   summary.BriefReport() + ")");
  }
  WriteSampleSet(set, args.output);
  if (args.json) {
    nlohmann::json j = {{"output", args.output},
                        {"protocol", args.protocol},
                        {"seed", args.seed},
                        {"samples", summary.samples},
                        {"placements", summary.placements},
                        {"falls", summary.falls},
                        {"abandoned_placements", summary.abandoned_placements},
                        {"executions", summary.executions},
                        {"tilted_executions", summary.tilted_executions},
                        {"simulated_seconds", summary.simulated_seconds},
                        {"wall_seconds", summary.wall_seconds},
                        {"cpu_seconds", summary.cpu_seconds},
                        {"simulated_seconds_per_wall_second", summary.SimulatedPerWallSecond()},
                        {"samples_per_second", summary.SamplesPerWallSecond()}};
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "wrote " << args.output << ": " << summary.BriefReport() << "\n";
  }
}

void SetupSimulate(CLI::App& root) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd = root.add_subcommand(
      "simulate",
      "Record a sample set with the simulated robot (the built-in octopod or a config's robot block) on the slope (paper protocol)");
  cmd->add_option("--config", args->config_path,
                  "Simulation config (JSON; missing fields keep their defaults, see "
                  "docs/simulation.md and --print-config)");
  cmd->add_option("--protocol", args->protocol,
                  "paper (26 commands x 3 headings x 5 = 390 samples), paper-830 (166 random "
                  "placements x 5 = 830), trajectories (100 random placements, each a sequence of "
                  "--executions random commands: for checking predictions) or continuous (166 "
                  "random placements x 5 commands drawn uniformly from [-0.5, 0.5]^3, stored as "
                  "the conditioning dimensions cmd_long, cmd_lat, cmd_turn of z)")
      ->capture_default_str();
  cmd->add_option("--seed", args->seed, "Random seed: same seed, same file")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "Sample set to write (.h5)");
  cmd->add_option("--placements", args->placements,
                  "Override the number of placements (0: the protocol's own)")
      ->capture_default_str();
  cmd->add_option("--executions", args->executions, "Executions of the command per placement")
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "Print the summary as JSON");
  cmd->add_flag("--print-config", args->print_config,
                "Print the effective config as JSON and exit");
  cmd->callback([args] { RunSimulate(*args); });
}

}  // namespace

DGMM_REGISTER_COMMAND("simulate", SetupSimulate);

}  // namespace dgmm::app
