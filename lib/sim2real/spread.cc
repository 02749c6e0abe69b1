#include "sim2real/spread.h"

#include <algorithm>
#include <cmath>

#include "sim2real/selection.h"

namespace dgmm::sim2real {

bool SpreadOptions::IsValid(std::string* error) const {
  if (!(z >= 0) || !(min_gain_nats >= 0) || !(max_log_ratio > 0)) {
    if (error) *error = "spread: z >= 0, min_gain_nats >= 0 and max_log_ratio > 0";
    return false;
  }
  return true;
}

Eigen::VectorXd KnobSpread(const SpreadProblem& sp, const EffectFit& fit, const SpreadOptions& options) {
  Eigen::VectorXd log_k = Eigen::VectorXd::Zero(sp.fit->dx);
  for (size_t j = 0; j < fit.effects.size(); ++j) {
    const int e = fit.effects[j];
    if (e < static_cast<int>(sp.log_var.size()) && sp.log_var[e].size() == log_k.size() && fit.theta[j].size() > 0) {
      log_k += fit.theta[j](0) * sp.log_var[e];
    }
  }
  return log_k.cwiseMax(-options.max_log_ratio).cwiseMin(options.max_log_ratio).array().exp();
}

namespace {

// Raw residuals x_i - mean_i = L_i w_i (dx x rows) after the mean effects of `fit`.
Eigen::MatrixXd RawResiduals(const FitProblem& fp, const EffectFit& fit, const std::vector<int>& rows) {
  Eigen::MatrixXd raw(fp.dx, rows.size());
  for (size_t k = 0; k < rows.size(); ++k) {
    const int i = rows[k];
    Eigen::VectorXd w = fp.r0.row(i).transpose();
    for (size_t j = 0; j < fit.effects.size(); ++j) {
      if (fp.library[fit.effects[j]].is_noise) continue;
      w -= fp.g[fit.effects[j]].middleRows(i * fp.dx, fp.dx) * fit.theta[j];
    }
    raw.col(k) = fp.chol[i] * w;
  }
  return raw;
}

// log p of those residuals under S Sigma_i S, S = diag(sqrt(rho)).
Eigen::VectorXd ResidualLogLikelihood(const FitProblem& fp, const Eigen::MatrixXd& raw, const std::vector<int>& rows,
                                      const Eigen::VectorXd& rho) {
  const Eigen::VectorXd inv_sd = rho.cwiseMax(1e-12).cwiseSqrt().cwiseInverse();
  const double log_det = rho.cwiseMax(1e-12).array().log().sum();
  Eigen::VectorXd ll(rows.size());
  for (size_t k = 0; k < rows.size(); ++k) {
    const int i = rows[k];
    const Eigen::VectorXd u = raw.col(k).cwiseProduct(inv_sd);  // S^-1 (x - mean)
    ll(k) = fp.log_norm(i) - 0.5 * log_det - 0.5 * fp.chol[i].triangularView<Eigen::Lower>().solve(u).squaredNorm();
  }
  return ll;
}

}  // namespace

Eigen::VectorXd SpreadLogLikelihood(const SpreadProblem& sp, const EffectFit& fit, const Eigen::VectorXd& rho,
                                    const std::vector<int>& rows) {
  return ResidualLogLikelihood(*sp.fit, RawResiduals(*sp.fit, fit, rows), rows, rho);
}

double FitTrackerCoefficient(const SpreadProblem& sp, const EffectFit& fit, const Eigen::VectorXd& k,
                             const Eigen::VectorXd& t, const std::vector<int>& rows) {
  // rho = k + a t must stay positive: a above -k_d / t_d wherever t_d > 0.
  double lo = sp.a_lo, hi = sp.a_hi;
  for (int d = 0; d < t.size(); ++d) {
    if (t(d) > 0) lo = std::max(lo, -0.99 * k(d) / t(d));
  }
  if (!(lo < hi)) return std::clamp(0.0, sp.a_lo, sp.a_hi);
  const Eigen::MatrixXd raw = RawResiduals(*sp.fit, fit, rows);  // independent of a
  auto cost = [&](double a) { return -ResidualLogLikelihood(*sp.fit, raw, rows, k + a * t).sum(); };
  // Golden section (the likelihood is unimodal in a for a per-axis scale).
  const double g = (std::sqrt(5.0) - 1) / 2;
  double a = lo, b = hi, c = b - g * (b - a), d = a + g * (b - a);
  double fc = cost(c), fd = cost(d);
  for (int it = 0; it < 60 && b - a > 1e-4 * (1 + std::abs(c)); ++it) {
    if (fc < fd) {
      b = d, d = c, fd = fc, c = b - g * (b - a), fc = cost(c);
    } else {
      a = c, c = d, fc = fd, d = a + g * (b - a), fd = cost(d);
    }
  }
  return (a + b) / 2;
}

SpreadTest TestTrackerSpread(const SpreadProblem& sp, const std::vector<int>& effects, const std::vector<int>& rows,
                             const std::vector<int>& fold, const EffectFitOptions& fit_options,
                             const SpreadOptions& options) {
  const FitProblem& fp = *sp.fit;
  SpreadTest out;
  if (sp.tracker.size() != fp.dx || sp.tracker.maxCoeff() <= 0) return out;
  out.tested = true;
  auto fit_on = [&](const std::vector<int>& train) {
    return effects.empty() ? EffectFit{} : FitEffects(fp, effects, train, fit_options);
  };
  const EffectFit all = fit_on(rows);
  const Eigen::VectorXd k_all = KnobSpread(sp, all, options);
  out.knob_log_ratio = k_all.array().log();
  out.a = FitTrackerCoefficient(sp, all, k_all, sp.tracker, rows);
  Eigen::VectorXd diff = Eigen::VectorXd::Zero(rows.size());
  const int folds = fold.empty() ? 0 : *std::max_element(fold.begin(), fold.end()) + 1;
  for (int f = 0; f < folds; ++f) {
    const FoldSplit split = SplitFold(rows, fold, f);
    if (split.test.empty() || split.train.empty()) continue;
    const EffectFit fit = fit_on(split.train);
    const Eigen::VectorXd k = KnobSpread(sp, fit, options);
    const double a = FitTrackerCoefficient(sp, fit, k, sp.tracker, split.train);
    const Eigen::VectorXd d = SpreadLogLikelihood(sp, fit, k + a * sp.tracker, split.test) -
                              SpreadLogLikelihood(sp, fit, k, split.test);
    for (size_t q = 0; q < split.test.size(); ++q) diff(split.test_pos[q]) = d(q);
  }
  std::vector<int> cluster;
  for (int r : rows) cluster.push_back(fp.episode[r]);
  ClusteredMean(diff, cluster, &out.gain, &out.se);
  out.z = out.se > 0 ? out.gain / out.se : 0.0;
  out.tracker_needed = out.z > options.z && out.gain > options.min_gain_nats && out.a > 0;
  return out;
}

}  // namespace dgmm::sim2real
