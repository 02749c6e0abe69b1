// The improved single-pass ADDSAMPLE (DgmmOptions::Variant::kImproved; docs/reproduction.md,
// section old-faithful, has the evidence). Same spirit as Algorithm 2: one pass, no sample
// history, new components started by the paper's rule t = 1 - (1 - d) exp(-k n) with
// d = p(x) / max p, so k keeps its meaning and the number of Gaussians stays data-driven.
// Three changes address the contamination of components by early merges, which is what keeps the
// faithful variant's MISE high on Old Faithful:
//  1. The receiving component is the most likely one, argmax_i N_i(x) (normalised density, no
//     weight, no random draw). The paper's draw proportional to w_i exp(-1/2 m_i^2) ignores the
//     determinant and favours the heaviest component, so one broad early component keeps
//     absorbing samples of both clusters.
//  2. Recency weighting: the m-th sample a component receives has weight m, so the samples it got
//     while young (before it found its cluster) fade as (m / n)^2. With weights 1..n the
//     totals W = n(n+1)/2 and S2 = n(n+1)(2n+1)/6 follow from n, so the statistics stay
//     (count, mean, scatter): `mean` is the weighted mean, `scatter` = (n - 1) C_w where
//     C_w = M2_w / (W - S2 / W) is the (reliability-weighted, unbiased) weighted covariance.
//  3. The covariance is the options' covariance rule applied to M2 = (n - 1) C_w (version 1
//     hard-wired ((n - 1) C_w + S0) / n, which the `prior` rule with nu0 = 1 approximates as
//     ((n - 1) C_w + S0) / (n + 1)). Under `prior` or `blend` a component that received a few
//     close samples is never so tight that it stops winning samples of its own cluster.
// Mixture weights remain the sample counts n_i (eq. 3).
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/dgmm.h"

namespace dgmm {
AddSampleResult Dgmm::AddSampleImproved(const Eigen::Ref<const Eigen::VectorXd>& x,
                                        std::mt19937_64& rng) {
  // The decision to merge or start a Gaussian is Algorithm 2's (unchanged).
  AddSampleResult result = DecideMerge(x, rng);
  if (!result.merged) {
    result.component = StartComponent(x);
    ++num_samples_;
    return result;
  }
  // 1. The most likely component.
  int best = 0;
  double best_log_density = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < mixture_.size(); ++i) {
    const double l = mixture_.component(i).LogDensity(x);
    if (l > best_log_density) best_log_density = l, best = i;
  }
  result.component = best;

  // 2. Weighted Welford step with weight a = m for the m-th sample of the component.
  DgmmComponentStats& s = stats_[best];
  const double n = static_cast<double>(s.count), m = n + 1.0;
  const double w_prev = n * (n + 1.0) / 2.0, w_new = w_prev + m;
  const double s2_prev = n * (n + 1.0) * (2.0 * n + 1.0) / 6.0, s2_new = s2_prev + m * m;
  // M2_w from the stored (n - 1) C_w; zero for a single sample.
  Eigen::MatrixXd m2 = Eigen::MatrixXd::Zero(dim_, dim_);
  if (n > 1.0) m2 = s.scatter * ((w_prev - s2_prev / w_prev) / (n - 1.0));
  const Eigen::VectorXd delta = x - s.mean;
  s.mean += (m / w_new) * delta;
  m2.noalias() += (m * w_prev / w_new) * delta * delta.transpose();
  s.scatter = m2 * ((m - 1.0) / (w_new - s2_new / w_new));
  s.scatter = 0.5 * (s.scatter + s.scatter.transpose()).eval();
  s.count += 1;
  mixture_.SetWeight(best, static_cast<double>(s.count));

  // 3. Covariance by the options' rule, plus the floor.
  RefreshComponent(best);
  ++num_samples_;
  return result;
}

}  // namespace dgmm
