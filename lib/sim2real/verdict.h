#pragma once
// Stage 8 of the analysis (analysis.h): what a user should believe, the `verdict` object of
// report.json (docs/sim2real.md, "report.json verdict"), in the fixed family vocabulary scored by
// scripts/sim2real_battery.py. A candidate is named when it is selected, constant over the session
// (drift.h), and its family's bootstrap inclusion is at least `min_inclusion`; its value is clamped
// to the knob's range and every doubt of the adequacy stage is stated. Status:
//   clean            no located mismatch and nothing named;
//   explained        named knobs, no doubt;
//   partly_explained named knobs with doubts (a value pinned or impossible, mismatch left, ...);
//   unexplained      a mismatch nothing named accounts for;
//   located          no simulator: the mismatch is located, no physics named.
#include <cmath>
#include <string>
#include <vector>

#include "sim2real/search_span.h"

namespace dgmm::sim2real {

struct VerdictExperiment {
  std::vector<std::string> commands;  // command labels
  std::vector<std::string> terrain;   // terrain region labels
  int executions = 0;                 // per cell, to separate the two at about 2.8 sigma
  bool checked_by_simulation = false;
  double separation = 0;              // squared whitened distance of the two predictions per execution
  // The check by simulation (experiment_check.h); meaningful when checked_by_simulation.
  bool confirmed = false;
  std::string not_checked_because;    // why not checked (empty when checked)
  std::vector<std::string> simulated_knobs;
  std::vector<double> simulated_values;
  int executions_simulated = 0, placements = 0;
  unsigned long long seed = 0;
  double heading_deg = 0;
  std::string placement;             // where the simulator stood the robot, in words
  double spread_scale = 1;            // simulated within-cell spread scaled by the fitted noise scale (>= 1)
  double simulated_separation = 0;    // d2 measured by simulation (same units as `separation`)
  double z = 0, z_required = 0, p_value = 1;
  int executions_needed = -1;         // by simulation; -1: no separation measured
  double seconds = 0;                 // wall time of the check
};

struct VerdictTie {
  // The named candidate's family first, then the tied ones'; one of its own family at another scope
  // as "family (knob)" (ties.h, TieScope).
  std::vector<std::string> families;
  std::string why;
  VerdictExperiment experiment;
};

struct VerdictNamed {
  std::string family, knob, unit;
  double value = 0, nominal = 0;
  double fitted = 0;                     // the fit's own reading (value is it clamped to the range)
  double lo = NAN, hi = NAN;             // the knob's range (NaN: a measurement effect)
  double value_lower = NAN, value_upper = NAN;  // 95% bootstrap interval of the value
  SearchSpan as_well;     // the likelihood search's values that fit as well as the named one
  double inclusion = -1;  // of the family, in [0, 1]; < 0: not computed (--bootstrap 0), written as null
  double candidate_inclusion = -1;       // of this candidate alone
  double scope_inclusion = -1;           // of its family at its scope (confidence.h)
  int tie_group = -1;     // index into ties, -1: null
  // "pinned_low", "pinned_high", "outside_range", "impossible", "unconverged", "not_single_peaked"
  std::vector<std::string> flags;
  std::vector<std::string> doubts;       // in words
};

// A selected candidate that is not named because its family's inclusion is below the threshold.
struct VerdictWeak {
  std::string family, knob;
  double value = 0, inclusion = 0;
};

// A named effect that is not a constant (drift.h): over the session (`first`/`last`: its value in
// the first and the last episodes, `gamma` the relative change between them) or with the
// execution index (`first`/`last`: its value at the steps where it is smallest and largest,
// `gamma` the relative RMS spread over steps). `value` is its fitted value over the whole set.
struct VerdictDrifting {
  std::string family, knob, unit;
  std::string along = "session order";  // or "execution index" (first/last: the lowest/highest step)
  double value = 0, nominal = 0, first = 0, last = 0, gamma = 0, p_value = 1;
  int first_step = -1, last_step = -1;  // execution index only
  double inclusion = -1;  // < 0: not computed
};
struct Verdict {
  std::string status = "clean";  // clean, explained, partly_explained, unexplained, cannot_compare
  std::vector<VerdictNamed> named;
  std::vector<VerdictTie> ties;
  std::vector<VerdictDrifting> drifting;  // effects that fit on average but drift (not named)
  std::vector<VerdictWeak> weak;          // selected but under the inclusion threshold (not named)
  double min_inclusion = 0;               // the threshold (family inclusion)
  std::vector<std::string> doubts;        // every doubt, in words (the named knobs' and the correction's)
  bool unexplained_present = false;
  bool uneven_ground = false;  // locate permuted whole placements (Baseline::permute_placements)
  std::vector<std::string> structured_in;
  double gap_closed = 0;  // NaN: no gap (null)
  std::string sentence;   // one plain-language paragraph for the conclusion
};

// The experiment in words, for the conclusion: "record command C on T about N times (checked by
// simulation, ...: the proposed experiment separates them / would not separate them ...; more
// executions needed: M)" or "(not checked by simulation: why)". Empty when no cell was proposed.
std::string DescribeExperiment(const VerdictExperiment& e);

// JSON text of the verdict object (contract of docs/sim2real.md).
std::string VerdictJson(const Verdict& v);

// A doubt a later stage adds to the verdict: `explained` becomes `partly_explained`, `clean`
// becomes `unexplained` (the sentence is left as it is).
void AddVerdictDoubt(const std::string& doubt, Verdict* v);

}  // namespace dgmm::sim2real
