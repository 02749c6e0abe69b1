#pragma once
// How far below a real-trained model a model of the real samples stands, and how far the finite
// sim set alone puts the sim model there:
//   ceiling = max over prior strengths k of the held-out log-likelihood of a real-trained model
//             with the sim model as a prior of k samples (k = 0: real data alone);
//   null shortfall = the same gap where the sim model is the truth: sim and real sets with the
//             sets' own commands, terrain and sequence, x drawn from the fitted sim model, the sim
//             model refitted on the drawn sim set (a parametric bootstrap of the whole
//             comparison); where the executions of a placement are dependent, each placement's
//             draws share a part of their noise (the sim set's intraclass correlation,
//             placement_dependence.h).
// Where real and sim physics agree, the real-trained ceiling still beats the sim model by the sim
// model's own estimation error (it sees more data); the adequacy test (adequacy.h) counts only
// what lies beyond this null.
#include <Eigen/Dense>
#include <cstdint>
#include <vector>

#include "sim2real/linear_gaussian.h"
#include "sim2real/samples.h"

namespace dgmm::sim2real {

struct CeilingFit {
  Eigen::VectorXd heldout;    // per real sample, the best prior strength's held-out values
  double prior_count = 0;     // that strength
  double ll_real_only = 0;    // mean held-out value of real data alone (prior 0)
};

// The ceiling on `real` with folds `fold` (per sample) and `sim_model` as the prior.
CeilingFit FitCeiling(const Samples& real, const LinearGaussianOptions& options, const std::vector<int>& fold,
                      const LinearGaussianModel& sim_model);

struct NullShortfallOptions {
  int draws = 20;   // parametric bootstrap draws (0: not measured)
  std::uint64_t seed = 1;
  // Per whitened pose entry, the share of the noise a placement's executions share (empty: none).
  Eigen::VectorXd placement_correlation;
  bool IsValid(std::string* error) const;
};

struct NullShortfall {
  double mean = 0;  // expected ceiling - sim model when the physics agree, nats per real sample
  double sd = 0;    // its spread over the draws (sim model's estimation and real sampling)
  int draws = 0;    // 0: not measured; mean and sd are 0
  // The SE of `mean` itself: recorded nulls (recorded_null.h) have few draws; the parametric
  // null's 20 draws leave it 0 (sd / sqrt(20) would widen the excess's SE by 2.5%).
  double mean_se = 0;
  bool recorded = false;  // recorded by the simulator (recorded_null.h), not drawn from the sim model
  int recordings = 0, from_cache = 0;  // the recorded null's re-recordings: recorded, read from the cache
};

// The null shortfall of the comparison of `sim_model` (fitted on `sim` with `model`) with `real`
// under the real folds `fold`.
NullShortfall SimNullShortfall(const LinearGaussianModel& sim_model, const Samples& sim, const Samples& real,
                               const std::vector<int>& fold, const LinearGaussianOptions& model,
                               const NullShortfallOptions& options);

}  // namespace dgmm::sim2real
