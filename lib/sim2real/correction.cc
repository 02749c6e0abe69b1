#include "sim2real/correction.h"

#include <memory>

namespace dgmm::sim2real {

Eigen::MatrixXd Correction::Covariance(const Eigen::MatrixXd& sigma) const {
  Eigen::MatrixXd out = std::exp(2 * log_tau) * sigma;
  if (log_var.size() != sigma.rows()) return out;
  const Eigen::VectorXd s = (0.5 * log_var).array().exp();
  return s.asDiagonal() * out * s.asDiagonal();
}

Eigen::VectorXd Correction::Shift(int command, const Eigen::VectorXd& z, double first, int dx) const {
  return shift ? shift(command, z, first) : Eigen::VectorXd::Zero(dx);
}

Correction MakeCorrection(const AnalysisInputs& in, const Baseline& base, const CandidateSet& set,
                          const EffectFit& fit) {
  Correction out;
  out.log_tau = fit.log_tau;
  out.log_var = fit.log_var;
  struct Mean {
    ExternalCandidate external;
    Eigen::VectorXd theta;
  };
  auto means = std::make_shared<std::vector<Mean>>();
  for (size_t j = 0; j < fit.effects.size(); ++j) {
    const int k = fit.effects[j];
    out.terms.push_back({set.library[k].key, fit.theta[j]});
    if (!set.library[k].is_noise) means->push_back({set.externals[k], fit.theta[j]});
  }
  if (means->empty()) return out;
  auto shifts = std::make_shared<std::vector<PairedShift>>(set.shifts);
  auto model = std::make_shared<LinearGaussianModel>(base.sim_model);
  const PoseLayout layout = in.layout;
  const int dx = in.real.pose_dim();
  out.shift = [means, shifts, model, layout, dx](int c, const Eigen::VectorXd& z, double f) {
    Eigen::VectorXd s = Eigen::VectorXd::Zero(dx);
    for (const Mean& m : *means) s += ExternalDesign(m.external, *shifts, *model, layout, dx, c, z, f) * m.theta;
    return s;
  };
  return out;
}

}  // namespace dgmm::sim2real
