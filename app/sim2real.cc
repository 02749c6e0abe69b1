// `dgmm sim2real`: where the simulation fails on real recordings, which simulator knobs (or
// measurement effects) explain it and how sure that is, the corrected model and the simulator
// config at the named values (lib/sim2real/analysis.h, docs/sim2real.md).
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/command.h"
#include "app/wiring/mujoco_knob_simulator.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "sim/sim_config.h"
#include "sim/simulator.h"
#include "sim2real/analysis.h"
#include "sim2real/corrected_model.h"
#include "sim2real/figures.h"
#include "sim2real/report.h"
#include "util/atomic_dir.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/output_guard.h"

namespace dgmm::app {
namespace {

struct Sim2RealArgs {
  std::string sim, real, out, sim_config, cache;
  int signature_placements = sim2real::CandidateOptions{}.placements;  // the library's defaults
  int signature_executions = sim2real::CandidateOptions{}.executions_per_placement;
  bool step_drift_recheck = sim2real::AnalysisOptions{}.every_execution_on_step_drift;
  bool payload_half_steps = sim2real::RefineOptions{}.payload_half_steps;
  double payload_middle_line_z = sim2real::RefineOptions{}.payload_middle_line_z;
  bool confirm_every_execution = sim2real::AnalysisOptions{}.every_execution_to_confirm;
  double confirm_from_z = sim2real::AnalysisOptions{}.every_execution_from_z;
  bool confirm_screened_only = sim2real::AnalysisOptions{}.confirm_screened_only;
  double confirm_screen_z = sim2real::AnalysisOptions{}.confirm_screen_z;
  double confirm_screen_share = sim2real::AnalysisOptions{}.confirm_screen_share;
  std::uint64_t seed = 1;
  int bootstrap = 20;
  int permutations = 1000;
  int threads = 0;
  bool json = false;
  bool no_figures = false;
  bool spread_signatures = false;
  bool every_leg = false;
  bool leg_search = true;
  bool payload_search = sim2real::PayloadSearchOptions{}.enabled;
  bool payload_on_posture = sim2real::PayloadSearchOptions{}.on_posture;
  bool payload_vs_leg = sim2real::PayloadSearchOptions{}.challenge_leg;
  bool payload_posture_chooses = sim2real::PayloadSearchOptions{}.posture_chooses;
  bool posture = sim2real::PostureOptions{}.enabled;
  double posture_z = sim2real::PostureOptions{}.z;
  bool refit_without_imu = sim2real::PostureOptions{}.refit_without_imu;
  bool runoff = true;
  bool ground_search = true;
  std::string null_corrected_gain = "off";  // auto: on a height field only (MakeOptions)
  std::string leg_search_score = "sag";
  int search_draws = 1;
  std::string leg_search_on = "remaining";
  double challenge_gap_closed = sim2real::LegSearchOptions{}.challenge_gap_closed;
  double challenge_inclusion = sim2real::LegSearchOptions{}.challenge_inclusion;
  bool leg_vs_side = sim2real::LegSearchOptions{}.challenge_side;
  bool leg_vs_whole = sim2real::LegSearchOptions{}.challenge_whole;
  bool leg_second_look = true;
  std::string null_source = "auto";
  int null_recordings = sim2real::RecordedNullOptions{}.draws;
  bool locate_only = false;
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
// inputs inside the output folder.
void CheckInputs(const Sim2RealArgs& args) {
  namespace fs = std::filesystem;
  if (SameFile(args.sim, args.real) || SameContent(args.sim, args.real)) {
    throw MakeInputError(args.real, "--real",
                         "is the same data as --sim " + args.sim + "; expected a real set to compare with the simulation");
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
                           "is inside the output folder " + args.out + ", which is replaced as a whole; move it or "
                           "choose another -o");
    }
  }
}

// The top-level keys (dotted for nested objects) where two configs differ.
std::string DifferingKeys(const std::string& a, const std::string& b) {
  const auto fa = nlohmann::json::parse(a).flatten(), fb = nlohmann::json::parse(b).flatten();
  std::string keys;
  for (const auto& [k, v] : fa.items()) {
    if (k == "/mjcf_path") continue;  // where the robot lives may differ; its text is in the fingerprint
    if (!fb.contains(k) || fb[k] != v) keys += (keys.empty() ? "" : ", ") + k.substr(1);
  }
  return keys;
}

// The simulator config: --sim-config, else the sim set's own (metadata "sim_config", written by
// `dgmm simulate`). Empty optional with *why when there is none.
std::optional<sim::SimConfig> ResolveConfig(const Sim2RealArgs& args, const SampleSet& sim, std::string* source,
                                            std::vector<std::string>* notes, std::string* why) {
  std::optional<sim::SimConfig> recorded;
  if (auto it = sim.metadata.find("sim_config"); it != sim.metadata.end()) {
    try {
      recorded = sim::SimConfigFromJson(it->second, args.sim + ": metadata sim_config");
    } catch (const InputError&) {
      if (!args.locate_only && args.sim_config.empty()) throw;  // the config the analysis needs
      notes->push_back(args.sim + ": its recorded sim_config cannot be read; not used");
    }
  }
  if (!args.sim_config.empty()) {
    sim::SimConfig config = sim::LoadSimConfig(args.sim_config);
    *source = "--sim-config " + args.sim_config;
    if (recorded) {
      const std::string keys = DifferingKeys(sim::SimConfigToJson(config), sim::SimConfigToJson(*recorded));
      if (!keys.empty()) {
        notes->push_back("--sim-config " + args.sim_config + " contradicts the config the sim set was recorded with (" +
                         keys + "); the analysis simulates with --sim-config as asked");
        Warn(notes->back());
      }
    }
    return config;
  }
  if (recorded) {
    *source = "the sim set's own recorded config (metadata sim_config of " + args.sim + ")";
    return recorded;
  }
  *why = "no simulator config: " + args.sim + " records none in its metadata and no --sim-config was given, so the "
         "analysis can only locate the mismatch (no physics named)";
  return std::nullopt;
}

// `uneven_ground`: the simulator config's ground is a height field.
sim2real::AnalysisOptions MakeOptions(const Sim2RealArgs& args, bool uneven_ground) {
  sim2real::AnalysisOptions o;
  o.locate.uneven_ground = uneven_ground;
  const int threads = args.threads > 0 ? args.threads : std::max(1u, std::thread::hardware_concurrency());
  o.seed = args.seed;
  o.locate.seed = args.seed;
  o.locate.locate.mmd.permutations = args.permutations;
  o.candidates.placements = args.signature_placements;
  o.candidates.executions_per_placement = args.signature_executions;
  o.every_execution_on_step_drift = args.step_drift_recheck;
  o.every_execution_to_confirm = args.confirm_every_execution;
  o.every_execution_from_z = args.confirm_from_z;
  o.confirm_screened_only = args.confirm_screened_only;
  o.confirm_screen_z = args.confirm_screen_z;
  o.confirm_screen_share = args.confirm_screen_share;
  o.candidates.spread_signatures = args.spread_signatures;
  o.candidates.legs_only_when_implicated = !args.every_leg;
  o.legs.enabled = args.leg_search;
  o.runoff.enabled = args.runoff;
  o.ground.enabled = args.ground_search;
  for (sim2real::LegSearchOptions* search : {&o.legs, &o.runoff.search, &o.payload.search, &o.ground.search}) {
    search->null_corrected_gain =
        args.null_corrected_gain == "on" || (args.null_corrected_gain == "auto" && uneven_ground);
    search->draws = args.search_draws;
  }
  o.payload.enabled = args.payload_search;
  o.payload.on_posture = args.payload_on_posture;
  o.payload.challenge_leg = args.payload_vs_leg;
  o.payload.posture_chooses = args.payload_posture_chooses;
  o.posture.enabled = args.posture;
  o.posture.z = args.posture_z;
  o.posture.refit_without_imu = args.refit_without_imu;
  o.payload.search.sag_mode = args.leg_search_score == "sag";
  o.legs.sag_mode = args.leg_search_score == "sag";
  o.legs.only_with_tails = args.leg_search_on == "tails";
  o.legs.challenge_named = args.leg_search_on == "remaining";
  o.legs.challenge_gap_closed = args.challenge_gap_closed;
  o.legs.challenge_inclusion = args.challenge_inclusion;
  o.legs.challenge_side = args.leg_vs_side;
  o.legs.challenge_whole = args.leg_vs_whole;
  o.legs.second_look_elsewhere = args.leg_second_look;
  o.payload.search.second_look_elsewhere = args.leg_second_look;
  o.candidates.recording.cache_dir = args.cache;
  o.candidates.recording.threads = threads;
  o.refine.seed = args.seed;
  o.refine.payload_half_steps = args.payload_half_steps;
  o.refine.payload_middle_line_z = args.payload_middle_line_z;
  o.refine.selection.bootstrap_selection = args.bootstrap;
  o.adequacy.seed = args.seed;
  o.null_source = args.null_source == "drawn"      ? sim2real::NullSource::kDrawn
                  : args.null_source == "recorded" ? sim2real::NullSource::kRecorded
                                                   : sim2real::NullSource::kAuto;
  o.recorded_null.draws = args.null_recordings;
  o.adequacy.locate.mmd.permutations = args.permutations;
  o.ties.experiment.enabled = !args.no_experiment_check;
  o.ties.experiment.seed = args.seed;
  o.ties.experiment.threads = std::min(threads, 2);
  o.on_stage = [](const std::string& stage) { ReportStage("sim2real: " + stage); };
  return o;
}

// The models, the config at the named values and the figures into `dir`; fills the context.
void WriteOutputs(const Sim2RealArgs& args, const sim2real::Analysis& a, const sim2real::KnobSimulator* simulator,
                  const std::filesystem::path& dir, sim2real::ReportContext* ctx) {
  ctx->sim_model_file = "sim_model.h5";
  WriteModel(sim2real::BuildSimModel(a.baseline.sim_model, a.inputs.first_execution_share, a.inputs.sim_set),
             (dir / ctx->sim_model_file).string());
  if (a.knobs_analysed) {
    ctx->corrected_model_file = "corrected_model.h5";
    WriteModel(sim2real::BuildCorrectedModel(a.baseline.sim_model, a.correction, a.inputs.first_execution_share,
                                             a.inputs.sim_set),
               (dir / ctx->corrected_model_file).string());
    ctx->recalibrated_config_file = "recalibrated_config.json";
    WriteText(dir / ctx->recalibrated_config_file, simulator->ConfigJson(a.named_values) + "\n");
  }
  if (args.no_figures) {
    ctx->notes.push_back("figures skipped: --no-figures");
  } else {
    std::string note;
    ctx->figures = sim2real::RenderFigures(a, dir, &note);
    if (!note.empty()) ctx->notes.push_back(note);
  }
}

// The analysis; when the simulator cannot re-record the sim set's recording (e.g. a protocol it
// does not know), the report says why and the analysis only locates.
// The ground as the posture comparison needs it where no simulator analyses (located only): the
// config's (unknown without one, or when its robot does not load: a note says why).
sim2real::PostureGround GroundOfConfig(const std::optional<sim::SimConfig>& config, sim2real::ReportContext* ctx) {
  if (!config) return {};
  try {
    const sim::Simulator robot(*config);
    return {true, robot.PlaneGround(), robot.LevelGround()};
  } catch (const InputError& e) {
    ctx->notes.push_back(std::string("the torso's posture was not compared: the simulator config's robot did not "
                                     "load (") + e.what() + ")");
    return {};
  }
}

sim2real::Analysis AnalyseOrLocate(const SampleSet& sim, const SampleSet& real, const Sim2RealArgs& args,
                                   const std::optional<sim::SimConfig>& config,
                                   std::unique_ptr<MujocoKnobSimulator>* simulator, std::string* why,
                                   sim2real::ReportContext* ctx) {
  sim2real::AnalysisOptions options = MakeOptions(args, config && config->terrain.has_value());
  if (!*simulator) {
    options.posture.ground = GroundOfConfig(config, ctx);
    return sim2real::Analyse(sim, real, nullptr, options, *why);
  }
  try {
    sim2real::Analysis a = sim2real::Analyse(sim, real, simulator->get(), options, *why);
    if (!a.candidates.unwalkable_probes.empty()) {
      std::string probes;
      for (const std::string& p : a.candidates.unwalkable_probes) probes += (probes.empty() ? "" : ", ") + p;
      ctx->notes.push_back("not candidates: " + probes + " (the robot fell in most placements at that value, too few "
                           "paired samples for a signature)");
    }
    if (!a.inputs.recording_from_metadata) {
      ctx->notes.push_back(args.sim + " records no protocol and seed (metadata): the signatures re-record protocol "
                           "paper with --seed " + std::to_string(args.seed) + ", not the sim set's own recording");
    }
    return a;
  } catch (const InputError& e) {
    *why = std::string("the simulator could not re-record the sim set (") + e.what() + "): located only";
    Warn(*why);
    ctx->notes.push_back(*why);
    options.posture.ground = sim2real::GroundOf(**simulator);
    simulator->reset();
    return sim2real::Analyse(sim, real, nullptr, options, *why);  // set errors throw again here
  }
}

// A note the user hears at once (stderr) and finds in the report.
void WarnAndNote(const std::string& note, sim2real::ReportContext* ctx) {
  if (note.empty()) return;
  Warn(note);
  ctx->notes.push_back(note);
}

// What the set's recording warned of (a tilted torso, self-contact, ...).
void RelayRecordingWarnings(const SampleSet& set, const std::string& path, sim2real::ReportContext* ctx) {
  for (const std::string& note : sim2real::RecordingNotes(set, path)) WarnAndNote(note, ctx);
}

void Run(const Sim2RealArgs& args) {
  const SampleSet sim = ReadSampleSet(args.sim);
  const SampleSet real = ReadSampleSet(args.real);
  if (sim.pose_dim() != real.pose_dim() || sim.terrain_dim() != real.terrain_dim()) {
    throw MakeInputError(args.real, sim.pose_dim() != real.pose_dim() ? "x" : "z",
                         fmt::format("{} pose and {} terrain dimensions; expected those of --sim {} ({} and {})",
                                     real.pose_dim(), real.terrain_dim(), args.sim, sim.pose_dim(), sim.terrain_dim()));
  }
  CheckInputs(args);
  sim2real::ReportContext ctx;
  ctx.sim_path = args.sim;
  ctx.real_path = args.real;
  RelayRecordingWarnings(sim, args.sim, &ctx);
  RelayRecordingWarnings(real, args.real, &ctx);
  std::string why;
  std::unique_ptr<MujocoKnobSimulator> simulator;
  const auto config = ResolveConfig(args, sim, &ctx.simulator_config_source, &ctx.notes, &why);
  if (args.locate_only) {
    why = "--locate-only: the analysis stops after locating the mismatch (no physics named)";
  } else if (config) {
    simulator = std::make_unique<MujocoKnobSimulator>(*config);  // a bad robot model is the user's error
    ctx.simulator_fingerprint = simulator->Fingerprint();
  }
  if (!simulator) ctx.notes.push_back(why);
  ReportStage("sim2real: analysing " + std::to_string(real.size()) + " real vs " + std::to_string(sim.size()) +
              " sim samples");
  const sim2real::Analysis a =
      AnalyseOrLocate(sim, real, args, config, &simulator, &why, &ctx);
  WarnAndNote(sim2real::SmallSimSetNote(a.inputs, args.sim), &ctx);
  if (a.baseline.permute_placements) {
    ctx.notes.push_back("locate's tests permute whole placements (" + a.baseline.permute_why +
                        "), so a region needs several placements on each side to be found");
  }
  // Everything is written into a sibling folder that replaces -o whole at the end.
  AtomicDir output(args.out, "report.json");
  WriteOutputs(args, a, simulator.get(), output.temp_path(), &ctx);
  const std::string json = sim2real::ReportJson(a, ctx);
  WriteText(output.temp_path() / "report.html", sim2real::ReportHtml(a, ctx, output.temp_path()));
  WriteText(output.temp_path() / "report.json", json);  // the marker of a complete result, last
  output.Commit();
  std::cout << (args.json ? json : sim2real::ReportSummary(a, ctx, (std::filesystem::path(args.out) / "report.html").string()));
}

// A threshold in standard errors: a number above `lower` (or equal to it when `inclusive`), or inf,
// which means `inf_means`; nan and text are refused.
CLI::Validator ZThreshold(double lower, bool inclusive, const std::string& inf_means) {
  const std::string bound = fmt::format("{} {}", inclusive ? ">=" : ">", lower);
  return CLI::Validator(
      [=](std::string& text) {
        char* end = nullptr;
        const double z = std::strtod(text.c_str(), &end);
        const bool number = end != text.c_str() && *end == 0;
        return number && (z > lower || (inclusive && z == lower))
                   ? std::string()
                   : fmt::format("a number {} expected (inf: {})", bound, inf_means);
      },
      "Z " + bound + " or inf");
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<Sim2RealArgs>();
  CLI::App* cmd = root.add_subcommand(
      "sim2real",
      "Compare a simulated and a real sample set: locate where the sim-trained model fails (terrain, sequence, "
      "command), name the simulator knobs (friction, contact, masses, payload, actuator gains, damping, latency, "
      "backlash, ...) or measurement effects (tracker bias and noise, IMU bias, heading drift) that explain it, by "
      "re-simulating the sim set's own recording at other knob values; say how sure that is (inclusion, ties, the "
      "experiment that would separate them, doubts) and how much of the gap the correction closes. The simulator "
      "config is the sim set's own (recorded by dgmm simulate) unless --sim-config is given; without one the tool "
      "only locates. Writes report.html, report.json, sim_model.h5, corrected_model.h5, recalibrated_config.json and "
      "PNGs into -o.");
  cmd->add_option("--sim", args->sim, "simulated sample set (.h5)")->required();
  cmd->add_option("--real", args->real, "real sample set (.h5)")->required();
  cmd->add_option("-o,--output", args->out, "output folder")->required();
  cmd->add_option("--seed", args->seed, "seed of folds, bootstrap and permutations")->capture_default_str();
  cmd->add_option("--sim-config", args->sim_config,
                  "simulation config (JSON) to re-simulate with; default: the one the sim set records (a different "
                  "one is reported)");
  cmd->add_flag("--locate-only", args->locate_only,
                "only locate the mismatch (no re-simulation, no physics named; the torso's posture against the sim "
                "set's where the simulator config tells the ground is a plane)");
  cmd->add_option("--threads", args->threads, "threads for the recordings and the experiment check (0: all cores)")
      ->capture_default_str()->check(CLI::Range(0, 1024));
  cmd->add_option("--cache", args->cache,
                  "folder of cached recordings (default $XDG_CACHE_HOME/dgmm or ~/.cache/dgmm; - for none)");
  cmd->add_option("--signature-placements", args->signature_placements,
                  "placements per recording (paper protocol: >= 78 covers every command 3 times)")
      ->capture_default_str()->check(CLI::Range(3, 10000));
  cmd->add_option("--signature-executions", args->signature_executions,
                  "executions per placement of a signature recording (2: 0.44 of the paper protocol's 5 in "
                  "time; 5 decides near-ties between knobs better, docs/sim2real.md)")
      ->capture_default_str()->check(CLI::Range(2, 100));
  cmd->add_flag("--step-drift-recheck,!--no-step-drift-recheck", args->step_drift_recheck,
                "when an effect fits on average but its size varies with the execution index and the signatures "
                "recorded fewer executions per placement than the real set has, record them again with every "
                "execution and analyse once more (on by default; docs/sim2real.md)");
  cmd->add_flag("--payload-half-steps,!--no-payload-half-steps", args->payload_half_steps,
                "after the payload's grid search, record its best mass half a grid step either side and at the "
                "quadratic's maximum between (on by default; docs/sim2real.md)");
  cmd->add_option("--payload-middle-line-z", args->payload_middle_line_z,
                  "record the payload's first grid on the middle line beyond its centre unless that centre fits "
                  "worse than the other way at its mass and offset by this many standard errors (inf: always; "
                  "docs/sim2real.md)")
      ->capture_default_str()->check(ZThreshold(0.0, false, "always"));
  cmd->add_flag("--confirm-every-execution,!--no-confirm-every-execution", args->confirm_every_execution,
                "when a knob is named from signatures of fewer executions per placement than the real set has, "
                "record them again with every execution and analyse once more before naming it (on by default; "
                "--no-confirm-every-execution keeps the first look; docs/sim2real.md)");
  cmd->add_option("--confirm-from-z", args->confirm_from_z,
                  "... and when nothing is named but the first look's best candidate reached this held-out z "
                  "(a near miss; significance starts near 2.8; inf: never)")
      ->capture_default_str()->check(ZThreshold(0.0, true, "never"));
  cmd->add_flag("--confirm-screened-only,!--confirm-all-knobs", args->confirm_screened_only,
                "the run again with every execution records only the knobs the first look screened in (held-out z "
                "of at least --confirm-screen-z and --confirm-screen-share of the step's best at some selection "
                "step, selected or confusable; the others keep "
                "their first-look signatures; on by default); --confirm-all-knobs records every knob again");
  cmd->add_option("--confirm-screen-z", args->confirm_screen_z,
                  "... the held-out z a knob needs at some step of the first look to be recorded again (two "
                  "executions can underrate an effect about threefold)")
      ->capture_default_str()->check(CLI::Range(-1e9, 1e9));
  cmd->add_option("--confirm-screen-share", args->confirm_screen_share,
                  "... and the share of the step's best held-out z it needs")
      ->capture_default_str()->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--null", args->null_source,
                  "where the null shortfall (how far below the real-trained ceiling the sim model stands when the "
                  "physics agree) comes from: drawn from the sim model, recorded (the nominal re-recorded with the "
                  "real set's design, --null-recordings times), or auto: recorded on uneven ground, drawn elsewhere")
      ->capture_default_str()->check(CLI::IsMember({"auto", "drawn", "recorded"}));
  cmd->add_option("--null-recordings", args->null_recordings, "re-recordings of the nominal for a recorded null")
      ->capture_default_str()->check(CLI::Range(2, 100));
  cmd->add_flag("--every-leg", args->every_leg,
                "probe every leg's gain (default: only the legs of a side the first pass implicates)");
  cmd->add_flag("--leg-search,!--no-leg-search", args->leg_search,
                "when a mismatch is left that no leg explains (see --leg-search-on), search every leg's gain with "
                "recordings scored by their own model (three per leg and two more, 5 executions per placement; on "
                "by default, --no-leg-search turns it off; docs/sim2real.md)");
  cmd->add_flag("--payload-search,!--no-payload-search", args->payload_search,
                "on a plane, when nothing is named for a located mismatch after the leg search or the leg search "
                "challenged the named knobs and kept them, search a payload's mass and position (named only when it "
                "beats a challenged name's correction by 2 SE; 7 columns at 2 masses, a column keeping its moment as "
                "the mass changes; then half-steps of the best column and its mass; each recording scored by its own "
                "model, 5 executions per placement; on by default since 2026-12-07, --no-payload-search turns it off "
                "but for --payload-on-posture and --payload-vs-leg; docs/sim2real.md)");
  cmd->add_flag("--payload-on-posture,!--no-payload-on-posture", args->payload_on_posture,
                "run the payload search also when the named physics leaves the torso's posture out (--posture; on "
                "by default)");
  cmd->add_flag("--payload-vs-leg,!--no-payload-vs-leg", args->payload_vs_leg,
                "when the leg search names a weak leg, run the payload search too: a payload off the middle can pass "
                "for one weak leg, and the better of the two (by 2 SE) keeps the name (on by default; docs/sim2real.md)");
  cmd->add_flag("--payload-posture-chooses,!--no-payload-posture-chooses", args->payload_posture_chooses,
                "where several of the payload search's positions fit the real samples as well, name the one whose "
                "payload leaves the least of the real torso's posture (--posture; off by default; docs/sim2real.md)");
  cmd->add_flag("--posture,!--no-posture", args->posture,
                "on a plane (level, or a slope: the radial part of pitch and roll), check that the named physics "
                "gives the real torso's mean pitch and roll (its recording at the sim set's places); a posture it "
                "leaves out is a doubt and lets the leg and payload searches challenge the names; located only, "
                "the real posture against the sim set's (on by default; docs/sim2real.md)");
  cmd->add_option("--posture-z", args->posture_z,
                  "standard errors (placements resampled) a posture left out must reach to be a doubt")
      ->capture_default_str()->check(CLI::PositiveNumber);
  cmd->add_flag("--refit-without-contradicted-imu,!--keep-contradicted-imu", args->refit_without_imu,
                "when the torso's posture contradicts a named IMU offset (the rest of the correction gives the real "
                "posture without it), analyse again from the candidates without an IMU offset (--posture; "
                "docs/sim2real.md); --keep-contradicted-imu keeps it named, with the doubt");
  cmd->add_flag("--ground-search,!--no-ground-search", args->ground_search,
                "on a height field with ground knobs: compare the spread of the real robot's standing tilt with the "
                "simulated one's and, where it moved, record the ground's knobs until one gives it (on by default; "
                "docs/sim2real.md, \"The ground's own knobs\")");
  cmd->add_option("--null-corrected-gain", args->null_corrected_gain,
                  "experimental: a search's best point must also fit the real samples better than the nominal by "
                  "more than its model fits the nominal's own recording at other places; auto: on a height field only "
                  "(docs/sim2real.md, \"The ground's own knobs\")")
      ->capture_default_str()->check(CLI::IsMember({"auto", "on", "off"}));
  cmd->add_flag("--runoff,!--no-runoff", args->runoff,
                "on uneven ground (locate permuted whole placements), when a mismatch is left: record the first "
                "selection step's contending knobs again and score each recording by its own model (on by default; "
                "docs/sim2real.md)");
  cmd->add_option("--search-draws", args->search_draws,
                  "experimental: recordings per point of the searches by models of their own (leg, payload, runoff, "
                  "ground), each a negligible payload heavier, their scores averaged: on a chaotic walk the chance in "
                  "a point's score shrinks as 1/sqrt(N), at N times the recordings (docs/sim2real.md, \"The nominal "
                  "drawn twice\")")
      ->capture_default_str()->check(CLI::Range(1, 16));
  cmd->add_option("--leg-search-score", args->leg_search_score,
                  "how the leg search scores a recording: sag (its sags as a mode of their own beside its core) or "
                  "robust (its own model with a broad component; docs/sim2real.md)")
      ->capture_default_str()->check(CLI::IsMember({"robust", "sag"}));
  cmd->add_option("--leg-search-on", args->leg_search_on,
                  "when the leg search runs: remaining (nothing named and a located mismatch left, or, on a plane, "
                  "knobs but no leg named and the corrected model below the ceiling: a leg then replaces them only "
                  "when it fits better), unexplained (only when nothing is named) or tails (only when nothing is "
                  "named and the residual has heavy tails)")
      ->capture_default_str()->check(CLI::IsMember({"tails", "unexplained", "remaining"}));
  cmd->add_option("--challenge-gap-closed", args->challenge_gap_closed,
                  "... and also when the named knobs' correction closed less than this share of the gap between "
                  "the sim model and the ceiling")
      ->capture_default_str()->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--challenge-inclusion", args->challenge_inclusion,
                  "... and also when a named family's bootstrap inclusion is under this (0: never; "
                  "docs/sim2real.md)")
      ->capture_default_str()->check(CLI::Range(0.0, 1.0));
  cmd->add_flag("--leg-vs-side,!--no-leg-vs-side", args->leg_vs_side,
                "... and always when a side's gain is named: one weak leg of that side is the finer physics it "
                "stands in for (on by default; docs/sim2real.md)");
  cmd->add_flag("--side-vs-whole,!--no-side-vs-whole", args->leg_vs_whole,
                "when every servo's gain is named, search every side's gain with every leg's: a whole side's weak "
                "servos read as a weak robot; a side or leg that fits better by 2 SE replaces it (on by default)");
  cmd->add_flag("--leg-second-look,!--no-leg-second-look", args->leg_second_look,
               "on a plane, a point the leg or payload search's misfit gate refuses is looked at again against "
               "recordings at other places, the uneven ground's gate (on by default since 2026-12-05; "
               "docs/sim2real.md)");
  cmd->add_flag("--spread-signatures", args->spread_signatures,
               "experimental: a knob's coefficient also scales the corrected covariance by the spread change of "
               "its recording (a weak leg widens the motion more than it shifts it; docs/sim2real.md)");
  cmd->add_option("--bootstrap", args->bootstrap, "bootstrap resamples of the selection (inclusion; 0: not computed)")
      ->capture_default_str()->check(CLI::Range(0, 1000));
  cmd->add_option("--permutations", args->permutations, "permutations per two-sample test")
      ->capture_default_str()->check(CLI::Range(1, 100000));
  cmd->add_flag("--no-figures", args->no_figures, "skip the PNG figures");
  cmd->add_flag("--no-experiment-check", args->no_experiment_check,
                "do not record the discriminating experiment proposed for a tie of two knobs");
  cmd->add_flag("--json", args->json, "print report.json to stdout instead of the summary");
  cmd->callback([args] { Run(*args); });
}

}  // namespace
DGMM_REGISTER_COMMAND("sim2real", Setup);
}  // namespace dgmm::app
