#include "sim2real/baseline.h"

#include <algorithm>
#include <map>
#include <set>

#include "sim2real/ceiling.h"
#include "sim2real/selection.h"
#include "sim2real/sentence_format.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

// Cross-fitted whitened residuals of the sim samples under sim models fitted without their fold.
Eigen::MatrixXd CrossFittedResiduals(const Samples& sim, const LinearGaussianOptions& options, int folds,
                                     std::mt19937_64& rng) {
  std::vector<int> rows(sim.size());
  for (int i = 0; i < sim.size(); ++i) rows[i] = i;
  const std::vector<int> fold = MakeFolds(sim.episode, sim.command, rows, folds, rng);
  Eigen::MatrixXd r(sim.size(), sim.pose_dim());
  for (int f = 0; f < folds; ++f) {
    const FoldSplit split = SplitFold(rows, fold, f);
    if (split.test.empty()) continue;
    const LinearGaussianModel m = LinearGaussianModel::Fit(sim, options, split.train);
    const Eigen::MatrixXd rt = m.WhitenedResiduals(SubsetSamples(sim, split.test));
    for (size_t k = 0; k < split.test.size(); ++k) r.row(split.test[k]) = rt.row(k);
  }
  return r;
}

// The ceiling (ceiling.h) on the real samples with the baseline's folds and sim model.
void Ceiling(const AnalysisInputs& in, const BaselineOptions& options, Baseline* b) {
  const CeilingFit c = FitCeiling(in.real, options.model, b->fold, b->sim_model);
  b->heldout_ceiling = c.heldout;
  b->ceiling_prior_count = c.prior_count;
  b->ll_real_only = c.ll_real_only;
  b->ll_ceiling = c.heldout.mean();
}

// Held-out log-likelihood of the sim model itself (nothing fitted on the real samples).
Eigen::VectorXd SimHeldout(const Samples& real, const LinearGaussianModel& model) { return model.LogLikelihood(real); }

void TerrainRegions(const AnalysisInputs& in, const BaselineOptions& options, std::mt19937_64& rng, Baseline* b) {
  const int dz = in.real.terrain_dim();
  Eigen::MatrixXd z_all(in.real.size() + in.sim.size(), dz);
  if (dz > 0) z_all << in.real.z, in.sim.z;
  b->terrain_centres = TerrainClusters(z_all, dz > 0 ? options.terrain_regions : 1, rng);
  for (int t = 0; t < b->terrain_centres.rows(); ++t) {
    b->terrain_labels.push_back(dz > 0 ? DescribeTerrain(b->terrain_centres.row(t).transpose(), in.pitch_col, in.roll_col)
                                       : "all terrain");
  }
  b->real_terrain = NearestCentre(in.real.z, b->terrain_centres);
  b->sim_terrain = NearestCentre(in.sim.z, b->terrain_centres);
}

// Deficit per command x terrain region: the "cell" regions; with a single terrain region (a set
// without terrain) Locate makes no cells, and the one column is each command's own deficit.
Eigen::MatrixXd HeatMap(const std::vector<Region>& regions, const std::vector<int>& commands, int terrains) {
  Eigen::MatrixXd h = Eigen::MatrixXd::Constant(commands.size(), std::max(1, terrains), NAN);
  const bool one_column = terrains <= 1;
  for (const auto& r : regions) {
    if (r.family != (one_column ? "command" : "cell")) continue;
    auto it = std::find(commands.begin(), commands.end(), r.command);
    if (it != commands.end()) h(it - commands.begin(), one_column ? 0 : r.terrain) = r.deficit;
  }
  return h;
}

}  // namespace

bool BaselineOptions::IsValid(std::string* error) const {
  if (folds < 2 || terrain_regions < 1 || sim_residual_folds < 2) {
    if (error) *error = "folds >= 2, terrain_regions >= 1 and sim_residual_folds >= 2";
    return false;
  }
  return model.IsValid(error) && locate.IsValid(error) && placement.IsValid(error);
}

LocateSummary LocateModel(const AnalysisInputs& in, const Baseline& base, const Eigen::MatrixXd& real_residuals,
                          const Eigen::VectorXd& heldout, bool with_pooled_x, const LocateOptions& options,
                          std::mt19937_64& rng) {
  LocateInput li;
  li.real = &in.real;
  li.sim = &in.sim;
  li.sim_residuals = base.sim_residuals;
  li.real_residuals = real_residuals;
  li.model_heldout = heldout;
  li.ceiling_heldout = base.heldout_ceiling;
  li.real_terrain = base.real_terrain;
  li.sim_terrain = base.sim_terrain;
  li.terrain_labels = base.terrain_labels;
  li.command_labels = in.command_labels;
  li.with_pooled_x = with_pooled_x;
  LocateOptions o = options;
  o.permute_placements = options.permute_placements || base.permute_placements;
  LocateSummary s;
  s.regions = Locate(li, o, rng);
  s.heat = HeatMap(s.regions, in.real_commands, static_cast<int>(base.terrain_labels.size()));
  for (const auto& g : s.regions) {
    if (!g.significant) continue;
    if (g.family == "pooled_x") ++s.pooled_x_flagged;
    if (g.family == "terrain" || g.family == "sequence" || g.family == "command") {
      ++s.conditional_flagged;
      s.significant.push_back(g);
    }
  }
  return s;
}

Baseline LocateMismatch(const AnalysisInputs& in, const BaselineOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "locate options", error);
  std::mt19937_64 rng(options.seed);
  Baseline b;
  b.sim_model = LinearGaussianModel::Fit(in.sim, options.model);
  std::vector<int> rows(in.real.size());
  for (int i = 0; i < in.real.size(); ++i) rows[i] = i;
  b.fold = MakeFolds(in.real.episode, in.real.command, rows, options.folds, rng);
  b.heldout_sim = SimHeldout(in.real, b.sim_model);
  b.ll_sim = b.heldout_sim.mean();
  Ceiling(in, options, &b);
  TerrainRegions(in, options, rng, &b);
  b.sim_residuals = CrossFittedResiduals(in.sim, options.model, options.sim_residual_folds, rng);
  b.real_residuals = b.sim_model.WhitenedResiduals(in.real);
  // Each set's residuals under its own fit: what z and the command leave, nothing of the mismatch.
  b.sim_own_residuals = b.sim_model.WhitenedResiduals(in.sim);
  const LinearGaussianModel real_own = LinearGaussianModel::Fit(in.real, options.model);
  b.placement = TestPlacementDependence(in.sim, b.sim_own_residuals, in.real,
                                        real_own.WhitenedResiduals(in.real), options.placement, options.seed);
  b.permute_placements = options.uneven_ground || b.placement.dependent;
  if (options.uneven_ground) {
    b.permute_why = "the simulator's ground is a height field: where a placement stands shapes its executions";
  } else if (b.placement.dependent) {
    b.permute_why = Fmt("the executions at one placement are not independent: placement test p = %.3g",
                        b.placement.p_value);
  }
  b.before = LocateModel(in, b, b.real_residuals, b.heldout_sim, true, options.locate, rng);
  b.significant_mismatch = b.before.conditional_flagged > 0;
  return b;
}

}  // namespace dgmm::sim2real
