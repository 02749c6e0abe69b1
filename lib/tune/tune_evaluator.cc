#include "tune/tune_evaluator.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace dgmm {
namespace {

TuneKPoint ToPoint(const DgmmOptions& o, const CvScore& score, const char* role) {
  return {o.k,
          score.mean,
          score.sd,
          score.standard_error,
          role,
          score.mean_components,
          o.initial_covariance_fraction,
          o.prior_pseudo_count};
}

}  // namespace

std::string ShortNumber(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

TuneKPoint TuneEvaluator::operator()(double k, const char* role) {
  cv_.dgmm.k = k;
  const double f = cv_.dgmm.initial_covariance_fraction, nu = cv_.dgmm.prior_pseudo_count;
  auto same = [](double a, double b) { return std::abs(a - b) <= 1e-9 * std::abs(b); };
  for (const TuneKPoint& p : cache_) {
    if (same(p.k, k) && same(p.init_scale, f) && same(p.prior_count, nu)) return p;
  }
  if (options_.progress) options_.progress(static_cast<int>(cache_.size()), -1);
  const CvSummary result = CrossValidate(set_, cv_);
  summary_->folds = result.folds;
  summary_->repeats = result.repeats;
  summary_->samples = result.samples;
  summary_->folds_by = result.folds_by;
  summary_->evaluations = static_cast<int>(cache_.size()) + 1;
  cache_.push_back(ToPoint(
      cv_.dgmm, summary_->with_terrain ? result.dgmm_with_terrain : result.dgmm_without_terrain,
      role));
  return cache_.back();
}

double TuneEvaluator::Tolerance(const std::vector<TuneKPoint>& pts) const {
  if (options_.plateau_tolerance > 0) return options_.plateau_tolerance;
  return std::max(pts[FindPlateau(pts, 0.0).best].standard_error, 1e-9);
}

}  // namespace dgmm
