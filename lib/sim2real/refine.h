#pragma once
// Stage 4 of the analysis (analysis.h): selection by held-out real likelihood (selection.h, with
// the backward pass), then refinement by re-recording. The payload (mass at the centre, x and y
// directions) is found by a likelihood search over its mass and forward offset
// (refine_payload.cc); then the most important selected one-parameter knobs, at most
// `refine_knobs`, each by a likelihood search over its value (refine_knob.cc). A search scores a
// recording by the real log-likelihood with its shift at face value (refine_search.h): its best
// recording is the knob's own effect at that value, not a linear extrapolation from a probe, and
// becomes the signature; the selection reruns.
// A selected noise scale is the tracker's only when the selected knobs' own simulated spread
// change does not account for it (spread.h); its scale is then refined by re-recording too.
#include <cmath>
#include <string>
#include <vector>

#include "sim2real/candidates.h"
#include "sim2real/search_span.h"
#include "sim2real/spread.h"

namespace dgmm::sim2real {

struct RefineOptions {
  std::uint64_t seed = 1;
  SelectionOptions selection;     // the backward pass is always on
  int refine_iterations = 3;      // a search's steps beyond its first grid (0: no refinement)
  int refine_knobs = 2;           // knobs refined at most (most important first)
  // The payload search's grids beyond its first, at most, while its best lies on a grid's edge (a
  // walk stops once centred): up to 1.6^6 = 17 times the probes' linear reading, which read 0.195
  // kg for a 2.49 kg payload on the mammal-shaped quadruped (docs/robots-sim2real-history.md).
  int payload_rounds = 6;
  // Then the mass is recorded half a grid step either side of the best point, at its forward
  // offset, and at the maximum of a quadratic in log mass through the points there (refine_payload.cc):
  // a grid of factor 1.6 alone left values up to a quarter off (false: the grid's best stands).
  bool payload_half_steps = true;
  // The first grid on the middle line (refine_payload.cc) beyond its centre is recorded unless that
  // centre fits worse than the other way's point at the same mass and offset by at least this many
  // standard errors (infinity: always recorded, as before 2026-12-03).
  double payload_middle_line_z = 3.0;
  double converged_within = 0.1;  // |coefficient - 1| of a converged tracker-noise refinement
  // The payload is searched (refine_payload.cc) when selected, or when it is a contender: at the
  // first selection step significant with at least this share of the best candidate's gain (its
  // linear probe design can lose to a knob whose effect is linear when its own is not).
  double payload_contender_share = 0.5;
  // A searched point fits as well as the best when its deficit is under this many SEs (refine_search.h).
  double as_well_z = 2.0;
  SpreadOptions spread;
  bool IsValid(std::string* error) const;
};

struct RefineStep {
  std::string knob;
  double value = 0, coefficient = 0;  // value recorded, fitted coefficient of its signature (NaN: not fitted)
  // A likelihood search's score (log-likelihood per real sample; NaN: the tracker noise's secant step).
  double score = NAN;
};

// One refined knob, the payload's mass or the tracker noise: did the search bracket its best value
// (the tracker noise: did its coefficient reach about 1)?
struct KnobRefinement {
  int candidate = -1;
  std::string knob;
  double value = 0;         // the value of the best signature
  double coefficient = 0;   // its fitted coefficient (1: the signature is the knob's own effect)
  bool converged = false;   // bracketed (tracker noise: |coefficient - 1| < converged_within)
  bool recorded = false;    // the best signature is a new recording (not the probe's)
  std::string why;          // why it did not converge, in words (empty: the coefficient's distance from 1)
  SearchSpan as_well;       // the search's points that fit as well as its best (no search: empty)
  // Empty when the search's scores rise to one peak; else, in words, the point that fits worse than
  // a point on either side of it in value by more than as_well_z SEs: recordings at nearby values
  // then differ by chance (a chaotic walk) more than by the value, or two values fit, and the
  // value's interval (the real samples' resampling) does not hold that.
  std::string rugged;
};

struct Refinement {
  SelectionResult selection;            // the final one
  SelectionOptions selection_options;   // as used (backward pass on)
  FitProblem problem;                   // the candidates' designs, refined where recorded again
  std::vector<int> rows;                // 0 .. n - 1
  std::vector<double> signature_at;     // per candidate: the value its signature was recorded at (NaN: none)
  double payload_mass = NAN;            // the payload's refined signature mass (NaN: the probe's)
  double payload_x = NAN, payload_y = NAN;  // and position
  std::vector<bool> searched;           // per candidate: its signature comes from a likelihood search
  SpreadTest spread;
  double tracker_scale = NAN;           // NaN: the tracker noise is not needed
  std::vector<RefineStep> trace;
  std::vector<KnobRefinement> refined;
  int recorded = 0, from_cache = 0;
  double seconds = 0;
};

Refinement SelectAndRefine(const KnobSimulator& simulator, const AnalysisInputs& in, const Baseline& base,
                           const CandidateOptions& recording, const RefineOptions& options, CandidateSet* set);

// The spread part of the stage (refine_spread.cc): tests the tracker noise beyond the selected
// knobs' own simulated spread change when the noise scale was selected and a tracker knob exists,
// and refines its scale by re-recording; fills r->spread, r->tracker_scale and the trace.
void RefineTrackerSpread(const KnobSimulator& simulator, const AnalysisInputs& in, const Baseline& base,
                         const CandidateOptions& recording, const RefineOptions& options, CandidateSet* set,
                         Refinement* r);

// Is the payload (library index `pay`) searched: selected, or at the first selection step
// significant (z at the step's threshold or above) with at least `share` of the best gain?
bool PayloadIsAContender(const SelectionResult& sel, int pay, double share);

// The payload part of the stage (refine_payload.cc): when the payload is selected, or a contender
// at the first selection step, and reads heavier than nominal, a likelihood search over its mass
// and forward offset from the probes' linear reading; fills r->payload_mass/x/y, the trace and
// r->refined, and reruns the selection with r->selection_options. Runs before the knobs'
// refinement.
void RefinePayload(const KnobSimulator& simulator, const AnalysisInputs& in, const Baseline& base,
                   const CandidateOptions& recording, const RefineOptions& options, CandidateSet* set,
                   Refinement* r);

// The likelihood search over one-parameter knob candidate k's value (refine_knob.cc), its probe's
// linear reading at coefficient a0: every candidate of that knob takes the best recording as its
// signature; appends to r->refined and r->trace, and reruns the selection.
void SearchKnob(const KnobSimulator& simulator, const AnalysisInputs& in, const Baseline& base,
                const CandidateOptions& recording, const RefineOptions& options, CandidateSet* set, Refinement* r,
                int k, double a0);

// The value in the knob's unit of candidate k at coefficient(s) theta (unclamped: the fit's own
// reading, which may lie outside the knob's range). A searched knob's or payload's: the searched
// value at the final fit's coefficient, its deviation scaled by theta's coefficient relative to it
// elsewhere. Measurement effects: their own parameter.
double CandidateValue(const CandidateSet& set, const Refinement& r, int k, const Eigen::VectorXd& theta);

}  // namespace dgmm::sim2real
