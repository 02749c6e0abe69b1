#include "core/data_scale.h"

#include <cassert>
#include <cmath>
#include <cstdio>

namespace dgmm {
namespace {

void Welford(long long* n, Eigen::VectorXd* mean, Eigen::VectorXd* m2,
             const Eigen::Ref<const Eigen::VectorXd>& y) {
  if (*n == 0) {
    *mean = Eigen::VectorXd::Zero(y.size());
    *m2 = Eigen::VectorXd::Zero(y.size());
  }
  ++*n;
  const double count = static_cast<double>(*n);
  double* mu = mean->data();
  double* s = m2->data();
  for (Eigen::Index j = 0; j < y.size(); ++j) {  // no temporaries: this runs once per sample
    const double delta = y[j] - mu[j];
    mu[j] += delta / count;
    s[j] += delta * (y[j] - mu[j]);
  }
}

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

}  // namespace

DataScaleAccumulator::DataScaleAccumulator(int dim) : dim_(dim) { assert(dim > 0); }

void DataScaleAccumulator::Add(int command, const Eigen::Ref<const Eigen::VectorXd>& y) {
  assert(y.size() == dim_);
  Moments& m = by_command_[command];
  Welford(&m.n, &m.mean, &m.m2, y);
  Welford(&total_.n, &total_.mean, &total_.m2, y);
  ++samples_;
}

Eigen::VectorXd DataScaleAccumulator::PooledVariance() const {
  Eigen::VectorXd within = Eigen::VectorXd::Zero(dim_);
  long long dof = 0;
  for (const auto& [command, m] : by_command_) {
    within += m.m2;
    dof += m.n - 1;
  }
  Eigen::VectorXd v(dim_);
  for (int j = 0; j < dim_; ++j) {
    double value = dof > 0 ? within[j] / static_cast<double>(dof) : 0.0;
    if (!(value > 0) && total_.n > 1) value = total_.m2[j] / static_cast<double>(total_.n - 1);
    v[j] = value > 0 && std::isfinite(value) ? value : 1.0;
  }
  return v;
}

Eigen::VectorXd PooledWithinCommandVariance(const SampleSet& set, bool with_terrain) {
  const bool terrain = with_terrain && set.terrain_dim() > 0;
  const int dx = set.pose_dim(), dz = terrain ? set.terrain_dim() : 0;
  DataScaleAccumulator acc(dx + dz);
  Eigen::VectorXd y(dx + dz);
  for (int i = 0; i < set.size(); ++i) {
    y.head(dx) = set.x.row(i).transpose();
    if (terrain) y.tail(dz) = set.z.row(i).transpose();
    acc.Add(set.command[i], y);
  }
  return acc.PooledVariance();
}

DgmmOptions ResolveDgmmOptions(const DgmmOptions& options, const Eigen::VectorXd& v,
                               const std::vector<std::string>& names, std::string* warning) {
  assert(options.IsValid(nullptr));
  const int d = static_cast<int>(v.size());
  DgmmOptions o = options;
  using Rule = DgmmOptions::InitialCovarianceRule;
  switch (o.initial_covariance_rule) {
    case Rule::kData:
      o.initial_covariance_diagonal = o.initial_covariance_fraction * v;
      break;
    case Rule::kIdentity:
      o.initial_covariance_diagonal = Eigen::VectorXd::Ones(d);
      break;
    case Rule::kUser:
      assert(o.initial_covariance_diagonal.size() == d);
      break;
  }
  if (o.covariance_floor_relative > 0)
    o.covariance_floor = o.covariance_floor_relative * v.minCoeff();
  if (warning) {
    warning->clear();
    if (o.initial_covariance_rule != Rule::kData) {
      int worst = -1;
      double worst_log = std::log(kScaleWarningRatio);
      int far = 0;
      for (int j = 0; j < d; ++j) {
        const double l = std::abs(std::log(o.initial_covariance_diagonal[j] / v[j]));
        if (l > std::log(kScaleWarningRatio)) ++far;
        if (l > worst_log) worst_log = l, worst = j;
      }
      if (worst >= 0) {
        const double ratio = o.initial_covariance_diagonal[worst] / v[worst];
        const std::string name = worst < static_cast<int>(names.size())
                                     ? names[worst]
                                     : "dimension " + std::to_string(worst);
        *warning = std::string("initial covariance (") +
                   InitialCovarianceRuleName(o.initial_covariance_rule) + ") is " + Num(ratio) +
                   "x the pooled within-command variance of " + name + " (" +
                   Num(o.initial_covariance_diagonal[worst]) + " vs " + Num(v[worst]) + "), " +
                   std::to_string(far) + " of " + std::to_string(d) + " dimensions are more than " +
                   Num(kScaleWarningRatio) + "x off; " +
                   (ratio > 1 ? "new components will swallow every sample"
                              : "new components will be needles") +
                   " (--init-cov data follows the data's scale)";
      }
    }
  }
  return o;
}

}  // namespace dgmm
