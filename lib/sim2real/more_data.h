#pragma once
// Stage 8's advice where the evidence stops short of a name (docs/sim2real.md, "When the evidence
// stops short"): a mismatch nothing named accounts for (`unexplained`), on a plane, and either a knob that forward selection took but the bootstrap
// resamples did not agree on (its family's inclusion p under the threshold), or the first
// selection step's best candidate short of significance by a near miss (held-out z >= from_z).
// A held-out z grows with the square root of the real set's placements (the units of its folds):
//   n_needed = ceil(n ((z_sig + margin) / z_eff)^2),  z_eff = z (near miss) or z_sig - Q(p) (weak knob),
// Q the standard normal's upper quantile (selection in a resample read as z* ~ N(z_eff, 1) passing
// z_sig); margin 1 is about 84% power at the effect's present size, which a near miss tends to
// overstate. Beyond max_factor n the advice says so: for a near miss the effect is too small for
// this protocol; for a selected knob the resamples disagree too often for more placements alone to
// settle it (hexapod pair 45006: a payload selected at z 3.2, held in no resample).
// Failing those, a search by models of their own (the leg search, the payload search) whose best
// point beat the nominal by z >= search_from_z but under its bar: its gain G per real sample over
// n samples, with the walk's own chance c (NominalDraws), gives z = n G / sqrt(SE^2 + (n c)^2), so
// at n' samples z' = G / sqrt(SE^2 / (n n') + c^2), which tends to G / c: the placements needed
//   n_needed = n SE^2 / (n^2 (G^2 / T^2 - c^2)),  T = bar + margin,
// and none where G / c <= T (the walk's chance bounds the z; more placements alone cannot decide).
#include <cmath>
#include <string>
#include <vector>

#include "sim2real/candidates.h"
#include "sim2real/inputs.h"
#include "sim2real/refine.h"
#include "sim2real/verdict_stage.h"

namespace dgmm::sim2real {

struct MoreDataOptions {
  bool enabled = true;
  double from_z = 2.0;      // a near miss: the first step's best held-out z at least this
  double margin = 1.0;      // z aimed at: significance + margin
  double max_factor = 16;   // more placements than this many times the real set's: too small
  // On uneven ground the first step's near misses are no evidence: on rough pairs 540-559 a null
  // and a pair of higher stones came near (backlash, z 2.29 and 2.55), and the weak legs came
  // near as backlash, the wrong physics (docs/sim2real.md).
  bool on_uneven_ground = false;
  // A search's near miss: its best point's z over the nominal at least this (its bar is 2). 1.5:
  // three quarters of the bar, as from_z is of the selection's significance (2.0 of 2.7-2.9).
  double search_from_z = 1.5;
  bool IsValid(std::string* error) const;
};

// A search's best point that named nothing (leg_search.h): what it is, in words and as a knob, its
// mean gain per real sample over the nominal, the walk's own chance, its z and the search's bar.
struct SearchNearMiss {
  std::string by;     // "the leg search", "the payload search"
  std::string knob, family;
  std::string said;   // "a weak rear_right leg (gain 0.5)", "a payload of 0.483 kg 3 cm ahead of the middle"
  double gain = NAN;  // nats per real sample
  double chance = 0;  // nats per real sample (NominalDraws::chance)
  double z = NAN, bar = NAN;
  int samples = 0;    // real samples scored
};

struct MoreData {
  bool advised = false;
  std::string knob, family;
  std::string reason;        // "inclusion" (selected, resamples disagree), "near_miss" or "search_near_miss"
  std::string said;          // search_near_miss: the search and its best point, in words
  double chance = 0;         // search_near_miss: the walk's own chance (nats per real sample)
  double z = NAN;            // held-out z at the step that chose it (inclusion) or the first step's best
  double z_required = NAN;   // that step's significance
  double inclusion = NAN;    // the family's (inclusion only)
  double z_effective = NAN;  // the z the advice scales from
  bool sequence = true;      // false: no sequence data, every sample its own placement
  int placements = 0, executions_per_placement = 0;  // the real set's
  int placements_needed = 0;  // -1: more than max_factor times the placements
  double max_factor = 0;      // the options'
};

// `v` is the final verdict (after the runoff and the leg search): advice only when it is
// `unexplained` (nothing named; a clean verdict has no mismatch for a near miss to explain).
// `searched`: knobs a search scored by models of their own (runoff, leg search) recorded without
// naming them; a closer look has spoken there, so they are not advised (on hexapod pair 45007 a
// leg's gain came near by its mean shift where the leg search had just found that leg's recording
// no better than the nominal's).
// `near`: the searches' best points that named nothing (advised only when the selection gives no
// advice, the one nearest its bar).
MoreData AdviseMoreData(const AnalysisInputs& in, const CandidateSet& set, const Refinement& r, const Naming& naming,
                        const Verdict& v, const std::vector<std::string>& searched, const MoreDataOptions& options,
                        const std::vector<SearchNearMiss>& near = {});

// " The evidence stops short of a name: ... would decide it ..." ("" when not advised).
std::string MoreDataSentence(const MoreData& m);

}  // namespace dgmm::sim2real
