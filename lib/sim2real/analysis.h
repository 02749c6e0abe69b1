#pragma once
// dgmm sim2real: why a simulation disagrees with the real robot (docs/sim2real.md), as a short
// sequence of named stages, each in its own file:
//   1. inputs      (inputs.h)        the two sets in raw units, commands aligned, the sim recording;
//   2. baseline    (baseline.h)      locate: where the sim model fails, against a real-trained ceiling;
//   3. candidates  (candidates.h)    the simulator's knobs' signatures and the measurement effects;
//   4. refine      (refine.h)        selection by held-out likelihood, refined by re-recording;
//   5. confidence  (confidence.h)    bootstrap inclusion per family, the values' intervals;
//   6. adequacy    (adequacy.h)      locate again on the correction, the fit against the ceiling
//                                    less its null (once per analysis: drawn from the
//                                    sim model, or recorded on uneven ground),
//                                    values pinned or impossible, residual structure and drift;
//   7. ties        (ties.h)          what the data cannot tell apart, and the experiment that would;
//   8. verdict     (verdict_stage.h) named knobs, status, doubts and the sentence; 3-8 once more
//                                    with every execution's signatures when an effect's size
//                                    varied with the execution index;
//      ground      (ground_search.h) on a height field: does the real robot stand tilted as variously as
//                                    the simulated one? If not, the ground knobs recorded until one
//                                    gives the real spread, its recording scored by its own model;
//      runoff      (runoff.h)        on uneven ground with a mismatch left: the first step's contenders
//                                    recorded again, each recording scored by its own model;
//      legs        (leg_search.h)    when nothing is named for a located mismatch: every leg's gain
//                                    searched, each recording scored by its own model;
//      posture     (posture.h)       on a plane, level or a slope: does the named physics give the
//                                    real torso's posture (pitch, roll)? Checked before the searches (a posture
//                                    left out lets them challenge the names) and on the final names;
//                                    a named IMU offset it contradicts: 3-8 again without one;
//      payload     (payload_search.h) on a plane when still nothing is named, or the posture is left
//                                    out (else experimental): a payload's mass and position searched likewise;
//      more data   (more_data.h)     when still nothing is named but a knob came near: how many
//                                    placements the real set would need to decide it;
//   9. report      (report.h)        report.json, report.html, the stdout summary (in the app).
// Without a simulator the analysis stops after stage 2 and says so.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "sim2real/correction.h"
#include "sim2real/ground_search.h"
#include "sim2real/leg_search.h"
#include "sim2real/more_data.h"
#include "sim2real/payload_search.h"
#include "sim2real/posture.h"
#include "sim2real/recorded_null.h"
#include "sim2real/runoff.h"
#include "sim2real/verdict_stage.h"

namespace dgmm::sim2real {

struct AnalysisOptions {
  std::uint64_t seed = 1;  // of folds, bootstrap, permutations and k-means (stages copy it)
  BaselineOptions locate;
  CandidateOptions candidates;
  RefineOptions refine;
  AdequacyOptions adequacy;
  TieOptions ties;
  VerdictOptions verdict;
  LegSearchOptions legs;   // its model options are the baseline's (locate.model)
  RunoffOptions runoff;    // likewise
  GroundSearchOptions ground;  // likewise (seed: the analysis's)
  PayloadSearchOptions payload;  // likewise; off by default
  PostureOptions posture;        // the torso's posture beside the motion (a plane, level or a slope; seed: the analysis's)
  // When an effect fits on average but its size varies with the execution index and the
  // signatures recorded fewer executions per placement than the real set has, stages 3-8 run
  // again with signatures of every execution (Analysis::every_execution_because).
  bool every_execution_on_step_drift = true;
  // When a knob is named from signatures of fewer executions per placement than the real set has,
  // stages 3-8 run again with every execution before the name stands: two executions decide
  // near-ties worse (on the octopod a stiffer servo was named as a lighter robot, docs/sim2real.md).
  bool every_execution_to_confirm = true;
  // ... and when the first look names nothing but its best candidate at the first selection step
  // reached this held-out z (significance starts at the step's threshold, about 2.8): a near miss
  // that less noisy signatures may settle (the hexapod's payloads, z 2.4-2.7 from 2 executions).
  double every_execution_from_z = 2.0;
  // The run again records only the knobs the first look screened in (ScreenedKnobs: at some step a
  // held-out z of at least confirm_screen_z and confirm_screen_share of the step's best); the other
  // candidates stay as competitors with their first-look signatures (KeepFirstLookCandidates).
  // false: every knob recorded again.
  bool confirm_screened_only = true;
  // Two executions can underrate an effect that acts differently in a placement's later executions
  // by a factor of about 3 (octopod 38007: servo kp z 2.9 from 2 executions, 9.7 from 5, beside a
  // lighter robot's 8.9 and 9.0): a knob significant (about 2.8) from every execution may score 0.8
  // from two, and one that may overtake the best scores at least a quarter of the best's z.
  double confirm_screen_z = 0.8;
  double confirm_screen_share = 0.25;
  // Where the adequacy's null shortfall comes from: drawn from the sim model (ceiling.h) or
  // recorded by the simulator (recorded_null.h). kAuto: recorded on uneven ground
  // (locate.uneven_ground), where the drawn null falls short of what null pairs measure, else drawn.
  NullSource null_source = NullSource::kAuto;
  RecordedNullOptions recorded_null;  // seed, folds, model and recording: the analysis's
  MoreDataOptions more_data;          // the advice where the evidence stops short of a name
  std::function<void(const std::string&)> on_stage;  // progress: called with each stage's name
  bool IsValid(std::string* error) const;
};

// Wall seconds per stage, summed over every run of it (a run again with every execution, a refit).
struct StageTimes {
  double locate = 0, candidates = 0, refine = 0, confidence = 0, adequacy = 0, ties = 0, ground = 0, runoff = 0, legs = 0,
         payload = 0, posture = 0, total = 0;
};

struct Analysis {
  AnalysisInputs inputs;
  Baseline baseline;
  bool knobs_analysed = false;     // false: locate only (no simulator)
  std::string locate_only_because;
  // Why stages 3-8 ran again with signatures of every execution per placement (empty: they did
  // not); the stages' results are the second run's.
  std::string every_execution_because;
  NullShortfall null_shortfall;    // the adequacy's null, measured once (MeasureNullShortfall)
  CandidateSet candidates;
  Refinement refinement;
  Confidence confidence;
  Adequacy adequacy;
  Naming naming;
  TieResult ties;
  Verdict verdict;
  GroundSearch ground;             // compared on a height field with ground knobs (GroundSearch::ran)
  Runoff runoff;                   // ran only on uneven ground with a mismatch left (Runoff::ran)
  LegSearch leg_search;            // ran only when nothing was named (LegSearch::ran)
  PayloadSearch payload_search;    // ran only when enabled and still nothing was named (PayloadSearch::ran)
  PostureCheck posture;            // does the named physics give the real torso's posture (a plane, level or a slope)
  // A first fit's IMU offset the posture contradicted (refitted: the stages from the candidates ran
  // again without an IMU offset, and every result here but this is the second run's).
  ContradictedImu imu_contradicted;
  MoreData more_data;              // how many placements would decide a near miss (MoreData::advised)
  Correction correction;           // the knob correction (empty without a simulator)
  std::vector<KnobValue> named_values;  // the named simulator knobs at their values (ConfigJson)
  StageTimes seconds;
};

// `simulator` null: locate only, `no_simulator_reason` saying why. Throws InputError for sets
// that cannot be compared and for a simulator that cannot record the sim set's protocol.
// The search that named the verdict's knob by recordings scored with their own models (the ground
// search, else the runoff, else the leg search, else the payload search), or nullptr when the knob
// path's correction stands.
const LegSearch* NamedByOwnModels(const Analysis& a);

// Does the leg search run (stage 8b)? When the stages before named nothing for a located mismatch
// (with LegSearchOptions::only_with_tails, one whose residual has heavy tails), or as a challenge
// (challenge_named): on a plane, knobs named but no leg's, and the corrected model below the
// real-trained ceiling or closing under challenge_gap_closed of the gap (the verdict then not
// `explained`), or the torso's posture left out by the named physics (PostureCheck).
bool WantLegSearch(const Analysis& a, const LegSearchOptions& options);

// Why stages 3-8 run again with signatures of every execution of a placement (empty: they do
// not). Only when the signatures were recorded with fewer executions per placement than the real
// set has, and then (1) an effect fits on average but its size varies with the execution index: a
// knob can act differently in a placement's first executions than in its later ones (the
// hexapod's payload most in the first, docs/sim2real.md), and a signature that never saw the later
// ones reads that profile as a drift; (2) a knob is named: a name from fewer executions is
// confirmed with every one; or (3) the best candidate of the first selection step reached
// every_execution_from_z without being significant. The run again records as many executions as
// the real set has.
std::string EveryExecutionBecause(const Analysis& a, const AnalysisOptions& options);
// The simulator knobs (indices, sorted) a first look screened in for the run again with every
// execution: those of every candidate that at some selection step reached held-out z `from_z` and
// `share` of the step's best z, was selected or was confusable with a chosen one (a payload brings
// its mass and position knobs), and the tracker's spread probe. Measurement effects need no recording.
std::vector<int> ScreenedKnobs(const CandidateSet& set, const SelectionResult& selection, double from_z,
                               double share);
// The largest execution index of a placement in the real set, plus one (0 without sequence data).
int RealExecutionsPerPlacement(const AnalysisInputs& in);
// Is the first look a screen? When every_execution_to_confirm holds and the signatures record
// fewer executions per placement than the real set has, whatever the first look selects is
// recorded again with every execution: it is named (and confirmed), or selected without a name,
// at a z of at least the step's significance, above every_execution_from_z's default (2.0). The
// first look then runs no likelihood search (stage 4's payload, knob and spread searches; the
// run again does), and when it is not run again after all (every_execution_from_z raised above
// the significance), stages 4-8 run once more with the searches.
bool FirstLookIsAScreen(const AnalysisInputs& in, const AnalysisOptions& options);

Analysis Analyse(const SampleSet& sim, const SampleSet& real, const KnobSimulator* simulator,
                 const AnalysisOptions& options, const std::string& no_simulator_reason = "");

}  // namespace dgmm::sim2real
