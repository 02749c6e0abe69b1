#include "sim2real/pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <random>
#include <set>

#include "sim2real/sentence_format.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

// Cross-fitted whitened residuals of the sim samples under sim models fitted without their fold.
Eigen::MatrixXd CrossFittedResiduals(const Samples& sim, const LinearGaussianOptions& options,
                                     int folds, std::mt19937_64& rng) {
  std::map<int, std::vector<int>> episodes_of_command;
  std::set<int> seen;
  for (int i = 0; i < sim.size(); ++i) {
    if (seen.insert(sim.episode[i]).second) episodes_of_command[sim.command[i]].push_back(sim.episode[i]);
  }
  std::map<int, int> fold_of;
  int offset = 0;
  for (auto& [c, eps] : episodes_of_command) {
    std::shuffle(eps.begin(), eps.end(), rng);
    for (size_t k = 0; k < eps.size(); ++k) fold_of[eps[k]] = (offset + k) % folds;
    offset += static_cast<int>(eps.size());
  }
  Eigen::MatrixXd r(sim.size(), sim.pose_dim());
  for (int f = 0; f < folds; ++f) {
    std::vector<int> train, test;
    for (int i = 0; i < sim.size(); ++i) (fold_of[sim.episode[i]] == f ? test : train).push_back(i);
    if (test.empty()) continue;
    LinearGaussianModel m = LinearGaussianModel::Fit(sim, options, train);
    Eigen::MatrixXd rt = m.WhitenedResiduals(SubsetSamples(sim, test));
    for (size_t k = 0; k < test.size(); ++k) r.row(test[k]) = rt.row(k);
  }
  return r;
}

// Held-out log-likelihood of each real sample under a real-trained model (same folds), with the
// sim model as a prior of strength `prior_count` (0: real data only).
Eigen::VectorXd RealTrainedHeldout(const Samples& real, const LinearGaussianOptions& options,
                                   const std::vector<int>& fold, const LinearGaussianModel& sim_model,
                                   double prior_count) {
  Eigen::VectorXd ll(real.size());
  const int folds = *std::max_element(fold.begin(), fold.end()) + 1;
  for (int f = 0; f < folds; ++f) {
    std::vector<int> train, test;
    for (int i = 0; i < real.size(); ++i) (fold[i] == f ? test : train).push_back(i);
    if (test.empty()) continue;
    LinearGaussianModel m =
        LinearGaussianModel::FitWithPrior(real, options, train, sim_model, prior_count);
    Eigen::VectorXd t = m.LogLikelihood(SubsetSamples(real, test));
    for (size_t k = 0; k < test.size(); ++k) ll(test[k]) = t(k);
  }
  return ll;
}

Eigen::MatrixXd HeatMap(const std::vector<Region>& regions, const std::vector<int>& commands, int terrains) {
  Eigen::MatrixXd h = Eigen::MatrixXd::Constant(commands.size(), std::max(1, terrains), NAN);
  for (const auto& r : regions) {
    if (r.family != "cell") continue;
    auto it = std::find(commands.begin(), commands.end(), r.command);
    if (it != commands.end()) h(it - commands.begin(), r.terrain) = r.deficit;
  }
  return h;
}

std::string Conclude(const Sim2RealResult& r) {
  std::string s;
  if (!r.significant_mismatch && r.effects.empty()) {
    return Fmt("No significant mismatch: the sim-trained model explains the %.0f real samples "
               "(held-out %.3f nats per sample against a real-trained ceiling of %.3f), no region "
               "of terrain, sequence or command differs significantly after Benjamini-Hochberg "
               "control, and no effect of the library improves the held-out real likelihood.",
               r.n_real, r.ll_sim, r.ll_ceiling);
  }
  // Headline: the significant terrain/sequence/command region with the largest deficit, then
  // the worst command x terrain cell.
  const Region* top = nullptr;
  const Region* cell = nullptr;
  for (const auto& g : r.before) {
    if (!g.significant) continue;
    const bool coarse = g.family == "terrain" || g.family == "sequence" || g.family == "command";
    if (coarse && (!top || g.deficit > top->deficit)) top = &g;
    if (g.family == "cell" && (!cell || g.deficit > cell->deficit)) cell = &g;
  }
  if (top) {
    s += "The simulation misses the real robot most in " + top->label +
         Fmt(" (%.2f nats per sample below a real-trained model, q = %.3g)", top->deficit, top->q_value);
    if (cell) s += "; the worst cell is " + cell->label + Fmt(" (%.2f nats per sample)", cell->deficit);
    s += ". ";
  }
  s += Fmt("A per-command comparison of x alone flags %.0f command(s); the terrain/sequence-aware "
           "residual tests flag %.0f region(s). ", r.pooled_x_flagged, r.conditional_flagged);
  if (r.effects.empty()) {
    s += "No effect of the library explains it: the mismatch is reported as unexplained.";
    return s;
  }
  s += "What the simulation left out, in order of evidence: ";
  for (size_t k = 0; k < r.effects.size(); ++k) {
    const auto& e = r.effects[k];
    s += Fmt("(%.0f) ", k + 1.0) + e.spec.title + " - " + e.sentence +
         (r.bootstrap_resamples > 0 ? Fmt(" [inclusion %.0f%%]", 100 * e.inclusion)
                                    : std::string(" [inclusion not computed: --bootstrap 0]"));
    if (!e.confusable_with.empty()) {
      s += " (cannot be told apart from:";
      for (const auto& c : e.confusable_with) s += " " + c;
      s += ")";
    }
    s += " ";
  }
  if (!r.dropped_commands.empty()) {
    s += Fmt("%.0f real sample(s) of %.0f command(s) with no sim counterpart were dropped. ",
             r.dropped_samples, r.dropped_commands.size());
  }
  if (std::isfinite(r.gap_closed)) {
    s += Fmt("The corrected model raises the held-out real log-likelihood from %.3f to %.3f nats "
             "per sample (real-trained ceiling %.3f): ", r.ll_sim, r.ll_corrected, r.ll_ceiling) +
         Fmt("%.0f%% of the gap closed.", 100 * r.gap_closed);
  }
  if (!r.unexplained.empty()) {
    s += " Unexplained mismatch remains in " + r.unexplained.front().label + ".";
  }
  return s;
}

}  // namespace

bool Sim2RealOptions::IsValid(std::string* error) const {
  if (terrain_regions < 1 || sim_residual_folds < 2) {
    if (error) *error = "terrain_regions >= 1 and sim_residual_folds >= 2";
    return false;
  }
  return model.IsValid(error) && selection.IsValid(error) && locate.IsValid(error);
}

Sim2RealResult RunSim2Real(const SampleSet& sim_in, const SampleSet& real_in,
                           const Sim2RealOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "options", error);
  for (const auto* set : {&sim_in, &real_in}) {
    std::string problem = set->Validate();
    if (!problem.empty()) throw MakeInputError(set == &sim_in ? "--sim" : "--real", "", problem);
  }
  // The analysis works in raw units: undo each set's standardisation (refuses broken transforms).
  const SampleSet sim_set = ToRawUnits(sim_in, "--sim");
  const SampleSet real_set = ToRawUnits(real_in, "--real");
  std::vector<int> real_map = AlignCommands(sim_set, real_set);
  std::vector<int> identity(sim_set.num_commands());
  for (int c = 0; c < sim_set.num_commands(); ++c) identity[c] = c;
  Samples sim = MakeSamples(sim_set, identity);
  Samples real = MakeSamples(real_set, real_map);
  if (real.size() < 10) {
    throw MakeInputError("--real", "", "fewer than 10 real samples share a command with the sim set");
  }
  std::set<int> sim_commands(sim.command.begin(), sim.command.end());
  {
    std::vector<int> keep;
    for (int i = 0; i < real.size(); ++i) {
      if (sim_commands.count(real.command[i])) keep.push_back(i);
    }
    real = SubsetSamples(real, keep);
  }
  Sim2RealResult r;
  r.bootstrap_resamples = options.selection.bootstrap_selection;
  {
    std::set<int> dropped;
    for (int i = 0; i < real_set.size(); ++i) {
      const int c = real_set.command(i);
      if (real_map[c] < 0 || !sim_commands.count(real_map[c])) {
        dropped.insert(c);
        ++r.dropped_samples;
      }
    }
    for (int c : dropped) {
      r.dropped_commands.push_back(c < static_cast<int>(real_set.command_labels.size())
                                       ? real_set.command_labels[c] : std::to_string(c));
    }
  }
  std::mt19937_64 rng(options.seed);
  r.n_real = real.size();
  r.n_sim = sim.size();
  r.pose_dim = real.pose_dim();
  r.terrain_dim = real.terrain_dim();
  r.has_sequence = real.has_sequence;
  r.layout = DetectPoseLayout(sim_set);
  for (int c = 0; c < sim_set.num_commands(); ++c) {
    r.command_labels.push_back(c < static_cast<int>(sim_set.command_labels.size())
                                   ? sim_set.command_labels[c] : std::to_string(c));
  }
  std::set<int> rc(real.command.begin(), real.command.end());
  r.real_commands.assign(rc.begin(), rc.end());
  {
    std::vector<double> gh;
    for (int i = 0; i < real.size(); ++i) gh.push_back(real.gravity.row(i).head<2>().norm());
    std::nth_element(gh.begin(), gh.begin() + gh.size() / 2, gh.end());
    r.slope_sin = gh[gh.size() / 2];
  }
  double first = 0;
  for (int f : real.first_execution) first += f;
  r.first_execution_share = first / real.size();

  // Models: sim-trained, and the real folds shared by every held-out comparison.
  r.sim_model = LinearGaussianModel::Fit(sim, options.model);
  r.library = EffectLibrary(r.layout, r.pose_dim, r.terrain_dim > 0, real.has_sequence);
  if (!options.only_effects.empty()) {
    const auto all = EffectLibrary(PoseLayout{0, 1, 2, 3, 4, 5}, 6, true, true);
    std::string valid;
    for (const auto& e : all) valid += (valid.empty() ? "" : ", ") + e.key;
    for (const auto& key : options.only_effects) {
      if (std::none_of(all.begin(), all.end(), [&](const EffectSpec& e) { return e.key == key; })) {
        throw MakeInputError("--effects", key, "unknown effect; expected one of " + valid);
      }
    }
    std::vector<EffectSpec> kept;
    for (const auto& e : r.library) {
      if (std::find(options.only_effects.begin(), options.only_effects.end(), e.key) != options.only_effects.end()) {
        kept.push_back(e);
      }
    }
    if (kept.empty()) {
      throw MakeInputError("--effects", "", "none of the chosen effects is usable with these sets "
                                           "(terrain, sequence or pose dimensions missing)");
    }
    r.library = kept;
  }
  FitProblem problem = MakeFitProblem(real, r.sim_model, r.library, r.layout);
  std::vector<int> all_rows(real.size());
  for (int i = 0; i < real.size(); ++i) all_rows[i] = i;
  std::vector<int> fold = MakeFolds(problem, all_rows, options.selection.folds, rng);
  // The ceiling: the best held-out real-trained model, from real data alone (prior 0) to
  // real data with the sim model as a prior of growing strength.
  Eigen::VectorXd ceiling;
  for (double prior_count : {0.0, 3.0, 10.0, 30.0, 100.0}) {
    Eigen::VectorXd ll = RealTrainedHeldout(real, options.model, fold, r.sim_model, prior_count);
    if (prior_count == 0) r.ll_real_only = ll.mean();
    if (ceiling.size() == 0 || ll.mean() > ceiling.mean()) {
      ceiling = ll;
      r.ceiling_prior_count = prior_count;
    }
  }

  // 2. Effects.
  SelectionResult sel = ForwardSelect(problem, all_rows, fold, options.selection);
  BootstrapResult boot = Bootstrap(problem, sel, options.selection, rng);
  r.steps = sel.steps;
  r.inclusion = boot.inclusion;
  r.fit = sel.fit;
  for (size_t k = 0; k < sel.selected.size(); ++k) {
    EffectReport e;
    e.spec = r.library[sel.selected[k]];
    e.theta = sel.fit.theta[k];
    e.lower = boot.lower[k];
    e.upper = boot.upper[k];
    e.inclusion = boot.inclusion[sel.selected[k]];
    for (const auto& c : sel.steps[k].candidates) {
      if (c.effect == sel.selected[k]) {
        e.gain = c.gain;
        e.gain_se = c.se;
      }
    }
    for (int other : sel.steps[k].confusable) e.confusable_with.push_back(r.library[other].key);
    e.sentence = DescribeEffect(e.spec, e.theta, r.slope_sin);
    e.importance = sel.importance[k];
    e.selection_step = static_cast<int>(k) + 1;
    r.effects.push_back(e);
  }
  std::stable_sort(r.effects.begin(), r.effects.end(),
                   [](const EffectReport& a, const EffectReport& b) { return a.importance > b.importance; });

  // 1. Locate, before and after the correction.
  const int k_terrain = r.terrain_dim > 0 ? options.terrain_regions : 1;
  Eigen::MatrixXd z_all(real.size() + sim.size(), r.terrain_dim);
  if (r.terrain_dim > 0) z_all << real.z, sim.z;
  r.terrain_centres = TerrainClusters(z_all, k_terrain, rng);
  int pitch_col, roll_col;
  DetectTerrainColumns(real_set, &pitch_col, &roll_col);
  for (int t = 0; t < r.terrain_centres.rows(); ++t) {
    r.terrain_labels.push_back(r.terrain_dim > 0
                                   ? DescribeTerrain(r.terrain_centres.row(t).transpose(), pitch_col, roll_col)
                                   : "all terrain");
  }
  LocateInput in;
  in.real = &real;
  in.sim = &sim;
  in.sim_residuals = CrossFittedResiduals(sim, options.model, options.sim_residual_folds, rng);
  in.real_residuals = problem.r0;
  in.model_heldout = sel.heldout_sim;
  in.ceiling_heldout = ceiling;
  in.real_terrain = NearestCentre(real.z, r.terrain_centres);
  in.sim_terrain = NearestCentre(sim.z, r.terrain_centres);
  in.terrain_labels = r.terrain_labels;
  in.command_labels = r.command_labels;
  r.before = Locate(in, options.locate, rng);
  // After: residuals of the corrected model (fitted on all real samples), held-out likelihoods.
  Eigen::MatrixXd corrected_residuals = problem.r0;
  for (size_t k = 0; k < sel.fit.effects.size(); ++k) {
    Eigen::VectorXd shift = WhitenedShift(problem, sel.fit, static_cast<int>(k));
    corrected_residuals -= Eigen::Map<Eigen::MatrixXd>(shift.data(), r.pose_dim, real.size()).transpose();
  }
  corrected_residuals *= std::exp(-sel.fit.log_tau);
  in.real_residuals = corrected_residuals;
  in.model_heldout = sel.heldout_corrected;
  in.with_pooled_x = false;
  r.after = Locate(in, options.locate, rng);
  const int n_terrain = static_cast<int>(r.terrain_labels.size());
  r.heat_before = HeatMap(r.before, r.real_commands, n_terrain);
  r.heat_after = HeatMap(r.after, r.real_commands, n_terrain);
  for (const auto& g : r.before) {
    if (!g.significant) continue;
    if (g.family == "pooled_x") ++r.pooled_x_flagged;
    if (g.family == "terrain" || g.family == "sequence" || g.family == "command") {
      ++r.conditional_flagged;
      r.significant_mismatch = true;
    }
  }
  for (const auto& g : r.after) {
    if (g.significant && (g.family == "terrain" || g.family == "sequence" || g.family == "command")) {
      r.unexplained.push_back(g);
    }
  }

  // 4. The fit.
  r.ll_sim = sel.heldout_sim.mean();
  r.ll_corrected = sel.heldout_corrected.mean();
  r.ll_ceiling = ceiling.mean();
  const double gap = r.ll_ceiling - r.ll_sim;
  r.gap_closed = gap > 1e-9 ? (r.ll_corrected - r.ll_sim) / gap : NAN;
  r.conclusion = Conclude(r);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace dgmm::sim2real
