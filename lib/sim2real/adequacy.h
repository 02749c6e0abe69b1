#pragma once
// Stage 6 of the analysis (analysis.h): does the knob correction account for the mismatch, with
// values a robot can have? Asked of the correction before any verdict, each failure a doubt in
// words:
//   - locate again on the corrected model (baseline.h, LocateModel): a terrain, sequence or command
//     region still significant is mismatch the knobs leave;
//   - the held-out fit: shortfall = ceiling - corrected per real sample, with its standard error
//     clustered by episode; gap closed = (corrected - sim) / (ceiling - sim) with a delta-method SE;
//     less the null shortfall (ceiling.h: the sim model's own estimation error), an excess above
//     `shortfall_z` SE (the larger of the real SE and the null's spread) and `min_shortfall_nats`
//     is a doubt;
//   - each selected knob: its value (the fit's own reading) inside the knob's range, not pinned at
//     a limit, physically possible (>= physical_min; a gain or friction at 0 is not), its
//     refinement converged, its likelihood search rose to one peak (refine.h), and its signature
//     is not largely the simulated walk's own chance (walk_chance.h);
//   - the residual: structure within placements or in the tails (residual_structure.h), and
//     whether each effect is constant over the session and the execution index (drift.h).
#include <cmath>
#include <string>
#include <vector>

#include "sim2real/confidence.h"
#include "sim2real/drift.h"
#include "sim2real/residual_structure.h"

namespace dgmm::sim2real {

struct AdequacyOptions {
  std::uint64_t seed = 1;
  LocateOptions locate;
  ResidualStructureOptions residual;
  DriftOptions drift;
  double shortfall_z = 3.0;           // SEs below the ceiling that make a doubt ...
  double min_shortfall_nats = 0.05;   // ... when also this far below (nats per real sample)
  double pinned_within = 1e-3;        // share of the knob's range counted as "at the limit"
  // A named knob whose fitted effect the walk's own chance makes this much of is doubted
  // (walk_chance.h); so is a named measurement effect when the median simulator knob's probe's is.
  double max_chance_share = 0.5;
  NullShortfallOptions null_shortfall;  // seeded from seed + 11 (0 draws: the null is 0)
  bool IsValid(std::string* error) const;
};

struct KnobCheck {
  int candidate = -1;
  double fitted = 0;        // the fit's reading in the knob's unit (may lie outside the range)
  double value = 0;         // clamped to the knob's range
  bool outside_range = false, pinned_low = false, pinned_high = false, impossible = false;
  bool unconverged = false;
  bool rugged = false;      // its likelihood search does not rise to one peak (KnobRefinement::rugged)
  bool chaotic = false;     // its signature is largely the walk's chance (AdequacyOptions::max_chance_share)
  double chance_share = NAN;  // of a simulator knob's fitted effect (walk_chance.h, FittedChanceShare)
  std::vector<std::string> doubts;  // in words, naming the knob
};

struct EffectDriftTest {
  int candidate = -1;
  EffectDrift drift, step_variation;
};

struct Adequacy {
  Eigen::MatrixXd residuals;          // whitened real residuals of the corrected model (n x dx)
  LocateSummary after;                // locate on the corrected model
  std::vector<Region> remaining;      // its significant regions where it is below the ceiling
  double ll_corrected = 0;
  double shortfall = 0, shortfall_se = 0;  // ceiling - corrected, nats per real sample
  double excess_shortfall = 0, excess_shortfall_se = 0;  // less the null shortfall
  double gap_closed = NAN, gap_closed_se = NAN;
  bool below_ceiling = false;
  std::vector<KnobCheck> checks;      // per entry of the final selection
  ResidualStructure residual;
  std::vector<EffectDriftTest> drift_tests;  // per selected mean effect
  EffectDrift total_drift, total_step_variation;
  std::vector<std::string> doubts;    // about the correction as a whole, in words
};

// The null shortfall of this comparison (ceiling.h), measured once per analysis: where locate
// permutes whole placements, each placement's draws share the sim set's within-placement share of
// the noise (placement_dependence.h). `model` is the baseline's (BaselineOptions::model).
NullShortfall MeasureNullShortfall(const AnalysisInputs& in, const Baseline& base, const LinearGaussianOptions& model,
                                   const AdequacyOptions& options);

// `null` is MeasureNullShortfall's (a default NullShortfall: the whole shortfall counts).
Adequacy AssessAdequacy(const AnalysisInputs& in, const Baseline& base, const NullShortfall& null,
                        const CandidateSet& set, const Refinement& r, const AdequacyOptions& options);

// (corrected - sim) / (ceiling - sim) of per-sample held-out values, with its SE clustered by
// `cluster` (delta method). NaN when the ceiling is not above the sim model.
void GapClosed(const Eigen::VectorXd& sim, const Eigen::VectorXd& corrected, const Eigen::VectorXd& ceiling,
               const std::vector<int>& cluster, double* gap, double* se);

}  // namespace dgmm::sim2real
