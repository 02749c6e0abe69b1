#include "sim2real/recorded_null.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "sim2real/selection.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

// ceiling - sim model on one re-recording, nats per sample, and its SE clustered by placement;
// false when it has too few samples.
bool Shortfall(const Samples& s, const Baseline& base, const RecordedNullOptions& options, std::mt19937_64& rng,
               double* mean, double* se) {
  if (s.size() < 10) return false;
  std::vector<int> rows(s.size());
  for (int i = 0; i < s.size(); ++i) rows[i] = i;
  const std::vector<int> fold = MakeFolds(s.episode, s.command, rows, options.folds, rng);
  const Eigen::VectorXd d = FitCeiling(s, options.model, fold, base.sim_model).heldout - base.sim_model.LogLikelihood(s);
  ClusteredMean(d, s.episode, mean, se);
  return std::isfinite(*mean);
}

}  // namespace

Samples RealCommandsOf(const SampleSet& set, const AnalysisInputs& in) {
  std::vector<int> map(set.num_commands(), -1);
  for (int c : in.real_commands) {
    if (c < set.num_commands()) map[c] = c;
  }
  return MakeSamples(set, map);
}

bool RecordedNullOptions::IsValid(std::string* error) const {
  if (draws < 2 || folds < 2) {
    if (error) *error = "recorded null: draws >= 2 and folds >= 2";
    return false;
  }
  return recording.IsValid(error);
}

Recording RealDesign(const AnalysisInputs& in, std::uint64_t seed) {
  Recording r;
  r.protocol = in.recording.protocol;
  r.seed = seed;  // never the sim set's own recording, nor the real set's
  while (r.seed == in.recording.seed || r.seed == in.real_seed) ++r.seed;
  const PlacementCount count = RealPlacements(in);
  r.placements = count.placements;
  r.executions_per_placement = count.executions_per_placement;
  return r;
}

NullShortfall RecordNullShortfall(const KnobSimulator& simulator, const AnalysisInputs& in, const Baseline& base,
                                  const RecordedNullOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "recorded null options", error);
  std::mt19937_64 rng(options.seed);
  std::vector<double> s;
  double se2 = 0;
  NullShortfall out;
  out.recorded = true;
  for (int d = 0; d < options.draws; ++d) {
    const RecordingBatch batch = RecordBatch(simulator, RealDesign(in, rng() % 2000000000ull), {{}}, options.recording);
    out.recordings += batch.recorded, out.from_cache += batch.from_cache;
    double mean = 0, se = 0;
    if (Shortfall(RealCommandsOf(batch.sets[0], in), base, options, rng, &mean, &se)) {
      s.push_back(mean);
      se2 += se * se;
    }
  }
  out.draws = static_cast<int>(s.size());
  if (s.empty()) return out;
  double sum = 0, sum2 = 0;
  for (double v : s) sum += v, sum2 += v * v;
  const double n = static_cast<double>(s.size());
  out.mean = sum / n;
  const double spread = n > 1 ? std::sqrt(std::max(0.0, (sum2 - n * out.mean * out.mean) / (n - 1))) : 0.0;
  // A few draws can put their SD near 0 by chance: at least their own clustered SE.
  out.sd = std::max(spread, std::sqrt(se2 / n));
  out.mean_se = out.sd / std::sqrt(n);
  return out;
}

}  // namespace dgmm::sim2real
