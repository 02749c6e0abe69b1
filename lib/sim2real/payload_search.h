#pragma once
// Stage 8c of the analysis (analysis.h; on by default since 2026-12-07): a search of a payload's mass
// and position, run when the stages before (the leg search too) named nothing for a located
// mismatch, or as the challenger of a leg the leg search named (PayloadVersusLeg). The probes read a payload linearly from three recordings (mass at the middle, ahead,
// to the left), but a payload off the middle can change the gait's posture far from linearly: on
// the hexapod on its 10° slope 0.88 kg 2.2 cm behind the middle sits the robot back 74 mrad in
// pitch, 75 nats per real sample below the real-trained ceiling, which the probes' reading
// fitted 1.2 of (docs/sim2real.md, "Payload offsets on the hexapod, simulated since 2026-12-05").
// Here the payload is recorded in columns, each at masses `masses` times the mass probe: a column
// keeps the moment of a position at the probe mass (forward offsets `forward` times the x probe's
// offset, and sideways `sideways` times the y probe's, at forward 0), so a payload of mass m sits
// at nominal + (position - nominal) probe / m. The data fix a payload's moment far better than its
// mass or its offset (refine_payload.cc: on the hexapod 0.48 kg 5.9 cm ahead fitted a real payload
// of 0.76 kg 3.7 cm ahead best on a grid of fixed offsets), and a grid of fixed offsets crosses
// that ridge between its points. Then `position_steps` rounds of half-steps around the best column
// along its line; every recording scored by a model of its own as the leg search
// scores a leg (leg_search.h, SearchOwnModels: the same z over the nominal, misfit gate and
// half-step refinement of the mass in the best column):
//   l(m, x, y) = sum_i log p_{m,x,y}(x_i | c_i, z_i, f_i).
// Positions whose best point fits as well as the best column's are listed: the data fix the mass
// better than where it sits. With `challenge_named` it also runs where the probes named knobs that
// the leg search challenged and did not replace (short of the ceiling, or seldom agreed on: a
// payload off the middle read as a small payload and a tracker offset on the planar quadruped,
// pair 59000), and names its payload only when it beats their correction as a leg would
// (PayloadSearchChallenge). The likelihood fixes the moment only so far: where several columns fit
// as well, the torso's posture (posture.h), which a payload's moment tilts, chooses among them
// when the analysis gives it (PostureLeft): the column whose best point leaves the least posture.
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "sim2real/leg_search.h"
#include "sim2real/verdict.h"

namespace dgmm::sim2real {

struct PayloadSearchOptions {
  // On by default since 2026-12-07 (`dgmm sim2real --no-payload-search` turns it off): over the
  // hexapod's blind ranges it named payloads the probes missed and gave none to a null or an
  // out-of-library pair (docs/sim2real.md, "The payload search on by default").
  bool enabled = true;
  // Run also when the torso's posture is left out by the named physics (posture.h), enabled or not.
  bool on_posture = true;
  bool challenge_named = true;  // also challenge named knobs the leg search challenged
  // Also challenge a leg the leg search named, enabled or not (`--no-payload-vs-leg` turns it off): a
  // payload off the middle loads the legs nearest it and can pass for one weak leg (the hexapod's
  // 65138: 0.62 kg 4.4 cm behind the middle read as a weak rear_right leg, z 3.0 over the nominal;
  // the payload search fitted its moment within 6%, 0.94 nats per real sample above the leg). The
  // better of the two best points keeps its name (PayloadVersusLeg).
  bool challenge_leg = true;
  std::vector<double> masses = {1.0, 2.0};                   // of the mass knob's probe
  std::vector<double> forward = {-1.0, -0.5, 0.0, 0.5, 1.0};  // of the x probe's offset, sideways 0
  std::vector<double> sideways = {-1.0, 1.0};                 // of the y probe's offset, forward 0
  // Rounds of half-steps of the position around the best column, along its line (two columns each).
  int position_steps = 1;
  // Among the columns that fit as well as the best, name the one whose best point leaves the least
  // of the real torso's posture (PostureLeft), where the analysis can check the posture; one that,
  // refined, fits no better than the nominal gives way to the next, the likelihood's best last.
  // Off by default since 2026-12-08: on fresh pairs it changed two names, both for the worse
  // (docs/sim2real.md, "The posture chooses along the moment").
  bool posture_chooses = false;
  LegSearchOptions search;  // the scoring and naming rules (its factors unused; the analysis's model)
  PayloadSearchOptions() { search.refine_steps = 2; }  // the best column's mass, to a quarter of a step
  bool IsValid(std::string* error) const;
};

struct PayloadColumn {
  double x = 0, y = 0;          // the payload's position at the mass probe (m, the knobs' frame)
  double mass = 0;              // its best mass (kg) ...
  double best_x = 0, best_y = 0;  // ... and where the column places that mass (its moment kept)
  double score = -INFINITY;     // that point's mean log-likelihood per real sample
  bool fits_as_well = false;    // within z SE of the best column's best (placements as units)
  double posture_z = NAN;       // the posture its best point leaves (PostureLeft; NaN: not checked)
};

// The real torso's posture a correction of simulator knobs leaves, in standard errors
// (PostureCheck::z_left; NaN where it cannot be checked).
using PostureLeft = std::function<double(const std::vector<KnobValue>& values)>;

struct PayloadSearch {
  bool ran = false;
  std::string why;                     // why it did not run or names nothing
  std::vector<PayloadColumn> columns;  // every position searched
  int best_column = -1;
  int likelihood_best = -1;            // the best column by likelihood alone (best_column unless the posture chose)
  LegSearch search;                    // the best column's search (its `also`: the position)
  double x = NAN, y = NAN;             // where the named mass sits
  double x_nominal = 0, y_nominal = 0; // the knobs' nominal position (the middle)
  std::string leg_challenged;          // the named leg it challenged ("rear_right leg (gain 0.35)"), or empty
  bool refused_fits_better = false;    // refused by its own gates, yet better than the named leg by the bar
  double seconds = 0;
};

// The best point in words: "a payload of 0.85 kg 3.4 cm ahead of the middle".
std::string PayloadSaid(const PayloadSearch& search);

// The named (best) payload's moment about the knobs' nominal position, forward and left (kg m).
std::pair<double, double> PayloadMoment(const PayloadSearch& search);

// The payload's knobs in `simulator` (mass, x, y; -1 when missing).
struct PayloadKnobs {
  int mass = -1, x = -1, y = -1;
  bool found() const { return mass >= 0 && x >= 0 && y >= 0; }
};
PayloadKnobs FindPayloadKnobs(const KnobSimulator& simulator);

PayloadSearch SearchPayload(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateSet& set,
                            const CandidateOptions& recording, const PayloadSearchOptions& options,
                            const PostureLeft& posture_left = nullptr);

// The search as a challenger of the knobs `named` before it (LegSearchChallenge): its payload keeps
// its name only when it fits the real samples better than their correction `corrected` by the
// search's z; `why` then says so.
void PayloadSearchChallenge(const AnalysisInputs& in, const std::vector<std::string>& named,
                            const Eigen::VectorXd& corrected, const PayloadSearchOptions& options, PayloadSearch* search);

// The search as a challenger of the leg the leg search named (PayloadSearchOptions::challenge_leg):
// their best points' scores per real sample compared, placements as units, the walk's own chance
// of either search counted (NominalDraws),
//   z = sum_i (score_payload,i - score_leg,i) / sqrt(SE^2 + (n chance)^2).
// A named payload with z >= options.search.z takes the leg's name (the leg search names nothing and
// its `why` says so); under it the payload names nothing, a rival of the leg when z > 0. A payload
// its own gates refused takes nothing, but where it fits better by the bar (`refused_fits_better`)
// the verdict doubts the leg (AddPayloadSearch).
void PayloadVersusLeg(const AnalysisInputs& in, const PayloadSearchOptions& options, LegSearch* leg,
                      PayloadSearch* search);

// The search's answer in the verdict: a named payload replaces the verdict (an `unexplained` one
// that named nothing, or the challenged knobs; status partly_explained, with the doubts of a search
// without bootstrap); otherwise the sentence says what the search found and why it names nothing,
// and a doubt when its payload fits as well as the challenged knobs, or when its gates refused a
// payload that fits better than the named leg.
void AddPayloadSearch(const PayloadSearch& search, Verdict* verdict);

}  // namespace dgmm::sim2real
