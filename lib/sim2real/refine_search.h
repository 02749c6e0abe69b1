#pragma once
// The score of stage 4's likelihood searches (refine.h): a recording taken at face value as
// candidate k's signature,
//   l = max_theta log p(real | sim model + s + D_others theta),
// its paired shift s at coefficient 1, the other selected effects (less `skip`) refit on what is
// left. A knob whose effect is far from linear in its value (friction with a threshold, a payload's
// position) is found where its own recording fits the real samples best, not where a linear
// extrapolation from a probe says.
#include <algorithm>
#include <string>
#include <vector>

#include "sim2real/refine.h"
#include "sim2real/units.h"

namespace dgmm::sim2real {

// What a likelihood search of stage 4 reads and writes: the simulator it records with, the
// analysis's inputs and baseline, how candidates are recorded, the refinement's options, the
// candidate set it adds recordings to and the refinement it traces into. The payload's search
// (refine_payload.cc) and a parameter knob's (refine_knob.cc) each extend it.
struct SearchContext {
  const KnobSimulator& simulator;
  const AnalysisInputs& in;
  const Baseline& base;
  const CandidateOptions& recording;
  const RefineOptions& options;
  CandidateSet* set;
  Refinement* r;
};

// `shifts`: candidate k's external shifts with the searched recording first (the payload keeps its
// x and y probes after it). Returns log-likelihood summed over the real samples; `rows` (if given)
// receives it per real sample.
double FaceValueScore(const AnalysisInputs& in, const Baseline& base, CandidateSet* set, const Refinement& r, int k,
                      const std::vector<int>& shifts, const std::vector<int>& skip, const RefineOptions& options,
                      Eigen::VectorXd* rows = nullptr);

// D = sum_i (a_i - b_i) and its standard error, the per-placement sums S_g of the differences taken
// as independent (placements are, samples of a placement are not):
//   SE(D)^2 = G / (G - 1) sum_g (S_g - D / G)^2.
// se is 0 when there are fewer than 2 placements or the lengths differ.
struct PairedSum {
  double sum = 0;
  double se = 0;
};
PairedSum PairedDifference(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const UnitIds& placements);

// Does b fit the real samples as well as a? Its deficit D = sum_i (a_i - b_i) lies under z times
// its standard error (PairedDifference). `untold` is the answer where that cannot be told: the
// lengths differ, fewer than 2 placements, or D or z SE is not a number (z = inf with SE 0).
bool FitsAsWellAs(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const UnitIds& placements, double z,
                  bool untold);

// Which searched points fit the real samples as well as the best one (`best`, included): those
// whose deficit D = sum_i (l_best,i - l_i) is below z times its standard error (PairedDifference).
// The recordings' own simulation noise is not counted, so the set errs on the narrow side.
std::vector<bool> FitAsWellAsTheBest(const std::vector<Eigen::VectorXd>& rows, int best,
                                     const std::vector<int>& placement, double z);

// The span of those points: the range of their `values` and, when `x` is given (the payload's
// forward offsets, one per point), of their x.
SearchSpan FitAsWellSpan(const std::vector<Eigen::VectorXd>& rows, int best, const std::vector<double>& values,
                         const std::vector<double>& x, const std::vector<int>& placement, double z);

// The deepest dip in a search's scores: the point `at` that fits worse than the best point below it
// (`left`) and the best point above it (`right`) in value, each deficit D above z times its
// standard error (PairedDifference), the smaller of the two deficits the dip's depth. at = -1: the
// scores rise to one peak within their errors. A likelihood in a knob's value may have two peaks;
// recordings of a chaotic walk also give dips, each value's recording off by its own chance.
struct ScoreDip {
  int at = -1, left = -1, right = -1;
  PairedSum below, above;  // at's deficits against left and right
  bool Found() const { return at >= 0; }
  double Depth() const { return std::min(below.sum, above.sum); }
};
ScoreDip DeepestDip(const std::vector<Eigen::VectorXd>& rows, const std::vector<double>& values,
                    const std::vector<int>& placement, double z);

// "(by 0.12 and 0.30 nats per real sample, z 2.4 and 5.1)": a dip's deficits over `real_samples`.
std::string DipDeficits(const ScoreDip& dip, int real_samples);

}  // namespace dgmm::sim2real
