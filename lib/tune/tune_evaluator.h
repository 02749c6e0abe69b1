#pragma once
// Internal to lib/tune. The cached evaluations of `dgmm tune` (lib/tune/tune_k.h): one
// cross-validation per distinct (k, f, nu0), all with the same folds and random numbers (common
// random numbers: the CvOptions seed does not depend on the settings), so L(a) - L(b) is a
// low-noise comparison.
#include <string>
#include <utility>
#include <vector>

#include "core/sample_set.h"
#include "tune/cross_validation.h"
#include "tune/tune_k.h"

namespace dgmm {

// One evaluation per (k, f, nu0): CrossValidate with the same folds and random numbers.
class TuneEvaluator {
 public:
  TuneEvaluator(const SampleSet& set, CvOptions cv, const TuneKOptions& options,
                TuneKSummary* summary)
      : set_(set), cv_(std::move(cv)), options_(options), summary_(summary) {}
  DgmmOptions& dgmm() { return cv_.dgmm; }
  // The cached evaluation at (k, f, nu0) (equal to within a relative 1e-9, so a design point
  // computed as exp(log k + step) finds the grid's k), else a new cross-validation.
  TuneKPoint operator()(double k, const char* role);
  // Every evaluation so far, in order.
  const std::vector<TuneKPoint>& all() const { return cache_; }
  // The plateau tolerance for `pts`: the option, else one standard error of their best.
  double Tolerance(const std::vector<TuneKPoint>& pts) const;

 private:
  const SampleSet& set_;
  CvOptions cv_;
  const TuneKOptions& options_;
  TuneKSummary* summary_;
  std::vector<TuneKPoint> cache_;
};

// v printed with the stream's default precision (6 significant digits), for report sentences.
std::string ShortNumber(double v);

}  // namespace dgmm
