// `dgmm sim2real`: where the simulation fails on real recordings, what physics it left out, the
// corrected model, and how much of the gap it closes (lib/sim2real, docs/sim2real.md).
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/command.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "sim2real/corrected_model.h"
#include "sim/sim_config.h"
#include "sim2real/figures.h"
#include "sim2real/knob_analysis.h"
#include "sim2real/pipeline.h"
#include "sim2real/recalibrate.h"
#include "sim2real/report.h"
#include "sim2real/verdict.h"
#include "util/atomic_dir.h"
#include "util/atomic_file.h"
#include "util/output_guard.h"
#include "util/error.h"

namespace dgmm::app {
namespace {

struct Sim2RealArgs {
  std::string sim, real, out, sim_config, cache;
  int signature_placements = 78;
  std::vector<std::string> effects;
  std::uint64_t seed = 1;
  int bootstrap = 20;
  int permutations = 1000;
  bool json = false;
  bool no_figures = false;
  bool legacy_resim = false;
  bool no_knobs = false;
  bool no_experiment_check = false;
};

void WriteText(const std::filesystem::path& path, const std::string& text) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path(), std::ios::binary);
    out << text;
    if (!out) throw MakeInputError(path.string(), "", "cannot write");
  }
  file.Commit();
}

// Refuses, before any output exists, what has no answer: identical --sim and --real files,
// inputs inside the output folder, a --sim-config that cannot be loaded.
void CheckInputs(const Sim2RealArgs& args) {
  namespace fs = std::filesystem;
  if (SameFile(args.sim, args.real) || SameContent(args.sim, args.real)) {
    throw MakeInputError(args.real, "--real",
                         "is the same data as --sim " + args.sim +
                             "; expected a real set to compare with the simulation");
  }
  CheckOutputDir(args.out, "report.json");
  std::error_code ec;
  const fs::path out = fs::weakly_canonical(args.out, ec);
  for (const std::string& input : {args.sim, args.real, args.sim_config}) {
    if (input.empty()) continue;
    const fs::path in = fs::weakly_canonical(input, ec);
    auto mismatch = std::mismatch(out.begin(), out.end(), in.begin(), in.end());
    if (!out.empty() && mismatch.first == out.end()) {
      throw MakeInputError(input, "-o",
                           "is inside the output folder " + args.out +
                               ", which is replaced as a whole; move it or choose another -o");
    }
  }
  if (!args.sim_config.empty()) sim::LoadSimConfig(args.sim_config);  // refuse up front
}

void Run(const Sim2RealArgs& args) {
  namespace fs = std::filesystem;
  const SampleSet sim = ReadSampleSet(args.sim);
  const SampleSet real = ReadSampleSet(args.real);
  if (sim.pose_dim() != real.pose_dim() || sim.terrain_dim() != real.terrain_dim()) {
    throw MakeInputError(args.real, sim.pose_dim() != real.pose_dim() ? "x" : "z",
                         fmt::format("{} pose and {} terrain dimensions; expected those of --sim "
                                     "{} ({} and {})",
                                     real.pose_dim(), real.terrain_dim(), args.sim, sim.pose_dim(),
                                     sim.terrain_dim()));
  }
  CheckInputs(args);
  // Everything is written into a sibling folder that replaces -o whole at the end.
  AtomicDir output(args.out, "report.json");
  const fs::path out_dir = output.temp_path();
  sim2real::Sim2RealOptions options;
  options.seed = args.seed;
  options.selection.bootstrap_selection = args.bootstrap;
  options.locate.mmd.permutations = args.permutations;
  options.only_effects = args.effects;
  ReportStage("sim2real: analysing " + std::to_string(real.size()) + " real vs " +
              std::to_string(sim.size()) + " sim samples");
  const sim2real::Sim2RealResult result = sim2real::RunSim2Real(sim, real, options);

  sim2real::ReportContext ctx;
  ctx.sim_path = args.sim;
  ctx.real_path = args.real;
  ctx.corrected_model_file = "corrected_model.h5";
  ctx.sim_model_file = "sim_model.h5";
  WriteModel(sim2real::BuildCorrectedModel(result, sim), (out_dir / ctx.corrected_model_file).string());
  WriteModel(sim2real::BuildSimModel(result, sim), (out_dir / ctx.sim_model_file).string());
  sim2real::Verdict verdict = sim2real::VerdictFromEffects(result);
  if (!args.sim_config.empty() && !args.no_knobs) {
    ReportStage("sim2real: simulator knobs (signatures, selection, refinement)");
    sim2real::KnobAnalysisOptions ko;
    ko.seed = args.seed;
    ko.selection = options.selection;
    ko.signatures.cache_dir = args.cache;
    ko.signatures.placements = args.signature_placements;
    ko.experiment.enabled = !args.no_experiment_check;
    ko.experiment.seed = args.seed;
    const sim::SimConfig config = sim::LoadSimConfig(args.sim_config);  // a bad config is the user's error
    try {
      const sim2real::KnobAnalysis knobs = sim2real::AnalyseKnobs(sim, real, config, result, ko);
      verdict = knobs.verdict;
      ctx.knob_analysis_json = sim2real::KnobAnalysisJson(knobs);
    } catch (const InputError& e) {
      // E.g. a sim set without episodes: the data-level verdict stands, and the report says why.
      ctx.notes.push_back(std::string("simulator-knob analysis skipped: ") + e.what());
    }
  }
  ctx.verdict_json = sim2real::VerdictJson(verdict);
  ctx.verdict_sentence = verdict.sentence;
  if (!args.sim_config.empty() && args.legacy_resim) {
    ReportStage("sim2real: re-simulating with fitted physical parameters (legacy scans)");
    sim2real::RecalibrationOptions recal;
    recal.sim_config_path = args.sim_config;
    recal.seed = args.seed;
    ctx.recalibration_json = sim2real::Recalibrate(result, real, recal);
    // The recalibrated config on its own, ready for `dgmm simulate --config`.
    const auto recal_json = nlohmann::json::parse(ctx.recalibration_json, nullptr, false);
    if (!recal_json.is_discarded() && recal_json.contains("recalibrated_config")) {
      WriteText(out_dir / "recalibrated_config.json",
                recal_json["recalibrated_config"].dump(2) + "\n");
    }
  }
  if (args.no_figures) {
    ctx.notes.push_back("figures skipped: --no-figures");
  } else {
    std::string note;
    ctx.figures = sim2real::RenderFigures(result, sim, real, out_dir, &note);
    if (!note.empty()) ctx.notes.push_back(note);
  }
  const std::string json = sim2real::ReportJson(result, ctx);
  WriteText(out_dir / "report.html", sim2real::ReportHtml(result, ctx, out_dir));
  WriteText(out_dir / "report.json", json);  // the marker of a complete result, last
  output.Commit();
  if (args.json) {
    std::cout << json;
    return;
  }
  std::cout << result.conclusion << "\n";
  if (!verdict.sentence.empty()) std::cout << "verdict: " << verdict.sentence << "\n";
  for (const auto& n : ctx.notes) std::cout << "note: " << n << "\n";
  std::cout << "report: " << (fs::path(args.out) / "report.html").string() << "\n";
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<Sim2RealArgs>();
  CLI::App* cmd = root.add_subcommand(
      "sim2real",
      "Compare a simulated and a real sample set: locate where the sim-trained model fails "
      "(terrain, sequence, command), name the physics the simulation left out (slip, traction, "
      "payload offset, actuator asymmetry, latency, compliance, bias, noise), write the corrected "
      "model and show how much of the gap it closes. Writes report.html, report.json, "
      "corrected_model.h5, sim_model.h5 and PNGs into -o.");
  cmd->add_option("--sim", args->sim, "simulated sample set (.h5)")->required();
  cmd->add_option("--real", args->real, "real sample set (.h5)")->required();
  cmd->add_option("-o,--output", args->out, "output folder")->required();
  cmd->add_option("--seed", args->seed, "seed of folds, bootstrap and permutations")->capture_default_str();
  cmd->add_option("--sim-config", args->sim_config, "simulation config of the sim set (JSON)");
  cmd->add_option("--effects", args->effects,
                  "restrict the data-level effect library to these keys (comma-separated), e.g. "
                  "bias,noise")
      ->delimiter(',');
  cmd->add_option("--cache", args->cache,
                  "folder of cached knob simulations (default $XDG_CACHE_HOME/dgmm or ~/.cache/dgmm; - for none)");
  cmd->add_option("--signature-placements", args->signature_placements,
                  "placements per knob simulation (paper protocol: >= 78 covers every command 3 times)")
      ->capture_default_str()->check(CLI::Range(3, 10000));
  cmd->add_option("--bootstrap", args->bootstrap, "bootstrap resamples of the effect selection")
      ->capture_default_str()->check(CLI::Range(0, 1000));
  cmd->add_option("--permutations", args->permutations, "permutations per two-sample test")
      ->capture_default_str()->check(CLI::Range(1, 100000));
  cmd->add_flag("--no-figures", args->no_figures, "skip the PNG figures");
  cmd->add_flag("--no-knobs", args->no_knobs,
                "with --sim-config, skip the simulator-knob analysis (the verdict then comes from the "
                "data-level effects)");
  cmd->add_flag("--no-experiment-check", args->no_experiment_check,
                "with --sim-config, do not simulate the discriminating experiment proposed for a tie of two "
                "simulator knobs (report.json verdict.ties[].experiment.checked_by_simulation stays false)");
  cmd->add_flag("--legacy-resim", args->legacy_resim,
                "with --sim-config, also run the scans of the data-level effects (friction, payload, "
                "leg gain; report.json \"recalibration\", recalibrated_config.json)");
  cmd->add_flag("--json", args->json, "print report.json to stdout instead of the conclusion");
  cmd->callback([args] { Run(*args); });
}

}  // namespace
DGMM_REGISTER_COMMAND("sim2real", Setup);
}  // namespace dgmm::app
