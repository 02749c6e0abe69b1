#include "sim2real/effect_fit.h"

#include <ceres/first_order_function.h>
#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>

#include <cmath>
#include <numbers>

namespace dgmm::sim2real {
namespace {

// -log likelihood of the whitened problem in column-scaled parameters theta' = scale .* theta,
// plus (optionally) s = log tau as the last parameter.
class NegLogLikelihood : public ceres::FirstOrderFunction {
 public:
  NegLogLikelihood(Eigen::MatrixXd g, Eigen::VectorXd r0, bool with_noise, double ridge)
      : g_(std::move(g)), r0_(std::move(r0)), with_noise_(with_noise), ridge_(ridge) {}
  int NumParameters() const override { return static_cast<int>(g_.cols()) + (with_noise_ ? 1 : 0); }
  bool Evaluate(const double* parameters, double* cost, double* gradient) const override {
    const int p = static_cast<int>(g_.cols());
    Eigen::Map<const Eigen::VectorXd> theta(parameters, p);
    const double s = with_noise_ ? parameters[p] : 0.0;
    if (!std::isfinite(s) || std::abs(s) > 20) return false;
    Eigen::VectorXd e = r0_ - g_ * theta;
    const double rss = e.squaredNorm(), w = std::exp(-2 * s);
    *cost = 0.5 * w * rss + r0_.size() * s + 0.5 * ridge_ * theta.squaredNorm();
    if (gradient) {
      Eigen::Map<Eigen::VectorXd> grad(gradient, NumParameters());
      grad.head(p) = -w * (g_.transpose() * e) + ridge_ * theta;
      if (with_noise_) grad(p) = -w * rss + r0_.size();
    }
    return std::isfinite(*cost);
  }

 private:
  Eigen::MatrixXd g_;
  Eigen::VectorXd r0_;
  bool with_noise_;
  double ridge_;
};

std::vector<int> AllRows(int n) {
  std::vector<int> rows(n);
  for (int i = 0; i < n; ++i) rows[i] = i;
  return rows;
}

}  // namespace

bool EffectFitOptions::IsValid(std::string* error) const {
  if (max_iterations < 1 || !(ridge >= 0)) {
    if (error) *error = "max_iterations must be >= 1 and ridge >= 0";
    return false;
  }
  return true;
}

FitProblem MakeFitProblem(const Samples& real, const LinearGaussianModel& sim_model,
                          const std::vector<EffectSpec>& library) {
  FitProblem fp;
  fp.n = real.size();
  fp.dx = real.pose_dim();
  fp.library = library;
  fp.r0.resize(fp.n, fp.dx);
  fp.log_norm.resize(fp.n);
  fp.episode = real.episode;
  fp.command = real.command;
  for (const auto& e : library) {
    fp.g.emplace_back(Eigen::MatrixXd::Zero(fp.n * fp.dx, e.num_params()));
    fp.d.emplace_back(Eigen::MatrixXd::Zero(fp.n * fp.dx, e.num_params()));
  }
  for (int i = 0; i < fp.n; ++i) {
    Prediction p = sim_model.Predict(real.command[i], real.z.row(i).transpose(), real.first_execution[i]);
    auto l = p.chol.triangularView<Eigen::Lower>();
    fp.r0.row(i) = l.solve(real.x.row(i).transpose() - p.mean).transpose();
    fp.log_norm(i) = -0.5 * (fp.dx * std::log(2 * std::numbers::pi) + p.log_det);
    fp.chol.push_back(p.chol);
  }
  return fp;
}

void SetDesign(FitProblem* fp, int k, int i, const Eigen::MatrixXd& d) {
  fp->d[k].middleRows(i * fp->dx, fp->dx) = d;
  fp->g[k].middleRows(i * fp->dx, fp->dx) = fp->chol[i].triangularView<Eigen::Lower>().solve(d);
}

EffectFit FitEffects(const FitProblem& fp, const std::vector<int>& effects,
                     const std::vector<int>& rows_in, const EffectFitOptions& options) {
  const std::vector<int> rows = rows_in.empty() ? AllRows(fp.n) : rows_in;
  EffectFit fit;
  fit.effects = effects;
  bool with_noise = false;
  int p = 0;
  for (int e : effects) {
    if (fp.library[e].is_noise) with_noise = true;
    else p += fp.library[e].num_params();
  }
  const int m = static_cast<int>(rows.size()) * fp.dx;
  Eigen::MatrixXd g(m, p);
  Eigen::VectorXd r0(m);
  for (size_t k = 0; k < rows.size(); ++k) r0.segment(k * fp.dx, fp.dx) = fp.r0.row(rows[k]).transpose();
  int col = 0;
  for (int e : effects) {
    if (fp.library[e].is_noise) continue;
    const int pe = fp.library[e].num_params();
    for (size_t k = 0; k < rows.size(); ++k) {
      g.block(k * fp.dx, col, fp.dx, pe) = fp.g[e].middleRows(rows[k] * fp.dx, fp.dx);
    }
    col += pe;
  }
  // Column scaling so that every parameter moves the likelihood on a comparable scale.
  Eigen::VectorXd scale = (g.colwise().norm().transpose() / std::sqrt(std::max(1, m))).cwiseMax(1e-12);
  Eigen::MatrixXd g_scaled = g * scale.cwiseInverse().asDiagonal();
  std::vector<double> params(p + (with_noise ? 1 : 0), 0.0);
  ceres::GradientProblem problem(new NegLogLikelihood(g_scaled, r0, with_noise, options.ridge * m));
  ceres::GradientProblemSolver::Options solver_options;
  solver_options.line_search_direction_type = ceres::LBFGS;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = 1e-12;
  solver_options.gradient_tolerance = 1e-10;
  solver_options.parameter_tolerance = 1e-12;
  solver_options.logging_type = ceres::SILENT;
  ceres::GradientProblemSolver::Summary summary;
  ceres::Solve(solver_options, problem, params.data(), &summary);
  fit.converged = summary.IsSolutionUsable();
  fit.iterations = static_cast<int>(summary.iterations.size());
  fit.log_tau = with_noise ? params[p] : 0.0;
  col = 0;
  for (int e : effects) {
    if (fp.library[e].is_noise) {
      fit.theta.push_back(Eigen::VectorXd::Constant(1, fit.log_tau));
      continue;
    }
    const int pe = fp.library[e].num_params();
    Eigen::VectorXd t(pe);
    for (int j = 0; j < pe; ++j) t(j) = params[col + j] / scale(col + j);
    fit.theta.push_back(t);
    col += pe;
  }
  fit.train_log_likelihood = CorrectedLogLikelihood(fp, fit, rows).sum();
  return fit;
}

Eigen::VectorXd CorrectedLogLikelihood(const FitProblem& fp, const EffectFit& fit,
                                       const std::vector<int>& rows_in) {
  const std::vector<int> rows = rows_in.empty() ? AllRows(fp.n) : rows_in;
  Eigen::VectorXd ll(rows.size());
  const double w = std::exp(-2 * fit.log_tau);
  for (size_t k = 0; k < rows.size(); ++k) {
    const int i = rows[k];
    Eigen::VectorXd e = fp.r0.row(i).transpose();
    for (size_t j = 0; j < fit.effects.size(); ++j) {
      const int eff = fit.effects[j];
      if (fp.library[eff].is_noise) continue;
      e -= fp.g[eff].middleRows(i * fp.dx, fp.dx) * fit.theta[j];
    }
    ll(k) = fp.log_norm(i) - fp.dx * fit.log_tau - 0.5 * w * e.squaredNorm();
  }
  return ll;
}

Eigen::VectorXd WhitenedShift(const FitProblem& fp, const EffectFit& fit, int k) {
  const int eff = fit.effects[k];
  if (fp.library[eff].is_noise) return Eigen::VectorXd::Zero(fp.n * fp.dx);
  return fp.g[eff] * fit.theta[k];
}

}  // namespace dgmm::sim2real
