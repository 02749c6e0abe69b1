#pragma once
// The data's scale, from which the DGMM's initial covariance S0 and covariance floor are resolved
// (docs/dgmm.md, "Scale and covariance rules"):
//   v_j = sum_c sum_{i in c} (y_ij - mean_cj)^2 / (N - C),
// the pooled within-command variance of dimension j of y (N samples, C commands with samples),
// computed in one streaming pass (Welford per command) before the DGMM pass.
#include <Eigen/Dense>
#include <map>
#include <string>
#include <vector>

#include "core/dgmm_options.h"
#include "core/sample_set.h"

namespace dgmm {

// Accumulates v over samples (command, y), y of `dim` entries.
class DataScaleAccumulator {
 public:
  explicit DataScaleAccumulator(int dim);
  void Add(int command, const Eigen::Ref<const Eigen::VectorXd>& y);
  long long samples() const { return samples_; }
  // v (dim entries, all > 0): a dimension whose pooled variance is not > 0 (N <= C, or constant
  // within every command) takes the total variance over all samples, and 1 when that is 0 too.
  Eigen::VectorXd PooledVariance() const;

 private:
  struct Moments {
    long long n = 0;
    Eigen::VectorXd mean, m2;
  };
  int dim_;
  long long samples_ = 0;
  std::map<int, Moments> by_command_;
  Moments total_;
};

// v for y = x || z (with_terrain and the set has terrain) or x alone, in the set's stored units.
Eigen::VectorXd PooledWithinCommandVariance(const SampleSet& set, bool with_terrain);

// A user's S0 entry farther than this factor from v_j (either way) draws a warning.
constexpr double kScaleWarningRatio = 100.0;

// Options with S0 and the floor resolved against v (d entries):
//   kData:     S0 = initial_covariance_fraction * v;
//   kIdentity: S0 = 1 (stored explicitly); kUser: as given (a single given value is not
//              expanded here: the diagonal must have d entries);
//   covariance_floor = covariance_floor_relative * min_j v_j when the relative floor is > 0.
// *warning (if given) is set to one line when S0_j / v_j is outside [1/100, 100] for some j
// (kIdentity or kUser), naming the worst dimension (names[j] when given), else cleared.
// Throws nothing; the options must be valid apart from resolution (asserted).
DgmmOptions ResolveDgmmOptions(const DgmmOptions& options, const Eigen::VectorXd& v,
                               const std::vector<std::string>& names = {},
                               std::string* warning = nullptr);

}  // namespace dgmm
