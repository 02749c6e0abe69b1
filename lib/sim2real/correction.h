#pragma once
// The knob correction as a predictor of the real samples: the sim model moved by the named
// candidates' fitted shifts and its covariance scaled by the fitted noise,
//   p(x | c, z, f) = N(u_c(z, f) + sum_e D_e(c, z, f) theta_e, tau^2 S Sigma_c(z, f) S),
// with D_e the candidates' designs (knob_design.h). The corrected model file (corrected_model.h)
// and the figures draw from it.
#include <Eigen/Dense>
#include <functional>
#include <string>
#include <vector>

#include "sim2real/candidates.h"

namespace dgmm::sim2real {

struct Correction {
  // sum_e D_e(c, z, f) theta_e (dx); empty function: no mean shift.
  std::function<Eigen::VectorXd(int command, const Eigen::VectorXd& z, double first)> shift;
  double log_tau = 0;
  Eigen::VectorXd log_var;  // per axis log variance ratio s (empty: none): covariance S Sigma S, S = diag(exp(s / 2))
  struct Term {
    std::string key;
    Eigen::VectorXd theta;
  };
  std::vector<Term> terms;  // what was fitted, for the model file's metadata

  // The mean shift at (c, z, f) (zero when there is none), dx.
  Eigen::VectorXd Shift(int command, const Eigen::VectorXd& z, double first, int dx) const;
  // tau^2 S Sigma S of a sim covariance Sigma.
  Eigen::MatrixXd Covariance(const Eigen::MatrixXd& sigma) const;
};

// The correction of `fit` (effects indexing set.library); keeps copies of the designs' inputs.
Correction MakeCorrection(const AnalysisInputs& in, const Baseline& base, const CandidateSet& set, const EffectFit& fit);

}  // namespace dgmm::sim2real
