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

// The spread signature of a column of the (column-scaled) parameters: s += theta'_col / scale * v.
struct SpreadColumn {
  int col;
  Eigen::VectorXd v;  // already divided by the column's scale
};

// s (dx) at scaled parameters theta'; `inside` marks the axes not clamped at +-max.
Eigen::VectorXd SpreadAt(const std::vector<SpreadColumn>& spread, const double* theta, int dx, double max,
                         Eigen::VectorXd* inside) {
  Eigen::VectorXd s = Eigen::VectorXd::Zero(dx);
  for (const SpreadColumn& c : spread) s += theta[c.col] * c.v;
  if (inside) *inside = (s.array().abs() < max).cast<double>().matrix();
  return s.cwiseMax(-max).cwiseMin(max);
}

// The -log likelihood with spread signatures (effect_fit.h), on raw residuals r_i and raw designs
// D_i (rows of m = rows x dx), each row whitened by its own L_i after S^-1. With a = L^-T e,
// e = L^-1 S^-1 (r - D theta): d/dtheta' of 1/2 |e|^2 is -D^T (S^-1 a) for the mean and
// -1/2 sum_d v_d a_d y_d for the spread (y = S^-1 (r - D theta)), plus 1/2 n v_d from log det.
class SpreadNegLogLikelihood : public ceres::FirstOrderFunction {
 public:
  SpreadNegLogLikelihood(Eigen::MatrixXd d, Eigen::VectorXd r, std::vector<const Eigen::MatrixXd*> chol,
                         std::vector<SpreadColumn> spread, bool with_noise, double ridge, double max)
      : d_(std::move(d)), r_(std::move(r)), chol_(std::move(chol)), spread_(std::move(spread)),
        with_noise_(with_noise), ridge_(ridge), max_(max) {}
  int NumParameters() const override { return static_cast<int>(d_.cols()) + (with_noise_ ? 1 : 0); }
  bool Evaluate(const double* parameters, double* cost, double* gradient) const override {
    const int p = static_cast<int>(d_.cols()), rows = static_cast<int>(chol_.size());
    const int dx = rows > 0 ? static_cast<int>(r_.size()) / rows : 0;
    Eigen::Map<const Eigen::VectorXd> theta(parameters, p);
    const double t = with_noise_ ? parameters[p] : 0.0;
    if (!std::isfinite(t) || std::abs(t) > 20) return false;
    Eigen::VectorXd inside;
    const Eigen::VectorXd s = SpreadAt(spread_, parameters, dx, max_, &inside);
    const Eigen::VectorXd inv = (-0.5 * s).array().exp();
    const Eigen::VectorXd y_all = inv.replicate(rows, 1).cwiseProduct(r_ - d_ * theta);
    double rss = 0;
    Eigen::VectorXd g_mean = Eigen::VectorXd::Zero(p), g_spread = Eigen::VectorXd::Zero(dx);
    for (int k = 0; k < rows; ++k) {
      const auto l = chol_[k]->triangularView<Eigen::Lower>();
      const Eigen::VectorXd y = y_all.segment(k * dx, dx);
      const Eigen::VectorXd e = l.solve(y);
      rss += e.squaredNorm();
      if (!gradient) continue;
      const Eigen::VectorXd a = l.transpose().solve(e);
      g_mean -= d_.middleRows(k * dx, dx).transpose() * inv.cwiseProduct(a);
      g_spread -= 0.5 * a.cwiseProduct(y);
    }
    const double w = std::exp(-2 * t);
    *cost = 0.5 * w * rss + r_.size() * t + 0.5 * rows * s.sum() + 0.5 * ridge_ * theta.squaredNorm();
    if (gradient) {
      Eigen::Map<Eigen::VectorXd> grad(gradient, NumParameters());
      grad.head(p) = w * g_mean + ridge_ * theta;
      for (const SpreadColumn& c : spread_) {
        grad(c.col) += (w * g_spread + 0.5 * rows * Eigen::VectorXd::Ones(dx)).cwiseProduct(inside).dot(c.v);
      }
      if (with_noise_) grad(p) = -w * rss + r_.size();
    }
    return std::isfinite(*cost);
  }

 private:
  Eigen::MatrixXd d_;
  Eigen::VectorXd r_;
  std::vector<const Eigen::MatrixXd*> chol_;
  std::vector<SpreadColumn> spread_;
  bool with_noise_;
  double ridge_, max_;
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
  fp.raw.resize(fp.n, fp.dx);
  fp.log_norm.resize(fp.n);
  fp.log_var.assign(library.size(), Eigen::VectorXd());
  fp.episode = real.episode;
  fp.command = real.command;
  for (const auto& e : library) {
    fp.g.emplace_back(Eigen::MatrixXd::Zero(fp.n * fp.dx, e.num_params()));
    fp.d.emplace_back(Eigen::MatrixXd::Zero(fp.n * fp.dx, e.num_params()));
  }
  for (int i = 0; i < fp.n; ++i) {
    Prediction p = sim_model.Predict(real.command[i], real.z.row(i).transpose(), real.first_execution[i]);
    auto l = p.chol.triangularView<Eigen::Lower>();
    fp.raw.row(i) = (real.x.row(i).transpose() - p.mean).transpose();
    fp.r0.row(i) = l.solve(fp.raw.row(i).transpose()).transpose();
    fp.log_norm(i) = -0.5 * (fp.dx * std::log(2 * std::numbers::pi) + p.log_det);
    fp.chol.push_back(p.chol);
  }
  return fp;
}

void SetDesign(FitProblem* fp, int k, int i, const Eigen::MatrixXd& d) {
  fp->d[k].middleRows(i * fp->dx, fp->dx) = d;
  fp->g[k].middleRows(i * fp->dx, fp->dx) = fp->chol[i].triangularView<Eigen::Lower>().solve(d);
}

namespace {

// The spread columns of a set of effects (scaled column, v / scale), empty when none carries one.
std::vector<SpreadColumn> SpreadColumns(const FitProblem& fp, const std::vector<int>& effects,
                                        const Eigen::VectorXd& scale) {
  std::vector<SpreadColumn> out;
  int col = 0;
  for (int e : effects) {
    if (fp.library[e].is_noise) continue;
    if (e < static_cast<int>(fp.log_var.size()) && fp.log_var[e].size() == fp.dx) {
      out.push_back({col, fp.log_var[e] / scale(col)});
    }
    col += fp.library[e].num_params();
  }
  return out;
}

// Rows' stacked designs (m x p) of the mean effects: whitened (fp.g) or raw (fp.d).
Eigen::MatrixXd StackDesigns(const FitProblem& fp, const std::vector<int>& effects, const std::vector<int>& rows,
                             int p, bool whitened) {
  Eigen::MatrixXd out(static_cast<int>(rows.size()) * fp.dx, p);
  int col = 0;
  for (int e : effects) {
    if (fp.library[e].is_noise) continue;
    const int pe = fp.library[e].num_params();
    const Eigen::MatrixXd& src = whitened ? fp.g[e] : fp.d[e];
    for (size_t k = 0; k < rows.size(); ++k) out.block(k * fp.dx, col, fp.dx, pe) = src.middleRows(rows[k] * fp.dx, fp.dx);
    col += pe;
  }
  return out;
}

}  // namespace

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
  const Eigen::MatrixXd g = StackDesigns(fp, effects, rows, p, true);
  // Column scaling so that every parameter moves the likelihood on a comparable scale.
  Eigen::VectorXd scale = (g.colwise().norm().transpose() / std::sqrt(std::max(1, m))).cwiseMax(1e-12);
  const std::vector<SpreadColumn> spread = SpreadColumns(fp, effects, scale);
  std::vector<double> params(p + (with_noise ? 1 : 0), 0.0);
  ceres::FirstOrderFunction* cost = nullptr;
  if (spread.empty()) {
    Eigen::VectorXd r0(m);
    for (size_t k = 0; k < rows.size(); ++k) r0.segment(k * fp.dx, fp.dx) = fp.r0.row(rows[k]).transpose();
    cost = new NegLogLikelihood(g * scale.cwiseInverse().asDiagonal(), r0, with_noise, options.ridge * m);
  } else {
    Eigen::VectorXd raw(m);
    std::vector<const Eigen::MatrixXd*> chol;
    for (size_t k = 0; k < rows.size(); ++k) {
      raw.segment(k * fp.dx, fp.dx) = fp.raw.row(rows[k]).transpose();
      chol.push_back(&fp.chol[rows[k]]);
    }
    cost = new SpreadNegLogLikelihood(StackDesigns(fp, effects, rows, p, false) * scale.cwiseInverse().asDiagonal(),
                                      raw, chol, spread, with_noise, options.ridge * m, fp.max_log_ratio);
  }
  ceres::GradientProblem problem(cost);
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
  if (!spread.empty()) fit.log_var = SpreadAt(spread, params.data(), fp.dx, fp.max_log_ratio, nullptr);
  int col = 0;
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
  const bool spread = fit.log_var.size() == fp.dx;
  const Eigen::VectorXd inv = spread ? Eigen::VectorXd((-0.5 * fit.log_var).array().exp()) : Eigen::VectorXd();
  const double half_log_det = spread ? 0.5 * fit.log_var.sum() : 0.0;
  for (size_t k = 0; k < rows.size(); ++k) {
    const int i = rows[k];
    Eigen::VectorXd e = spread ? Eigen::VectorXd(fp.raw.row(i).transpose()) : Eigen::VectorXd(fp.r0.row(i).transpose());
    for (size_t j = 0; j < fit.effects.size(); ++j) {
      const int eff = fit.effects[j];
      if (fp.library[eff].is_noise) continue;
      const Eigen::MatrixXd& design = spread ? fp.d[eff] : fp.g[eff];
      e -= design.middleRows(i * fp.dx, fp.dx) * fit.theta[j];
    }
    if (spread) e = fp.chol[i].triangularView<Eigen::Lower>().solve(inv.cwiseProduct(e));
    ll(k) = fp.log_norm(i) - fp.dx * fit.log_tau - half_log_det - 0.5 * w * e.squaredNorm();
  }
  return ll;
}

Eigen::VectorXd WhitenedShift(const FitProblem& fp, const EffectFit& fit, int k) {
  const int eff = fit.effects[k];
  if (fp.library[eff].is_noise) return Eigen::VectorXd::Zero(fp.n * fp.dx);
  return fp.g[eff] * fit.theta[k];
}

}  // namespace dgmm::sim2real
