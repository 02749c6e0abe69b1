#include "sim2real/analysis.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <random>

#include "sim2real/sentence_format.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

using Clock = std::chrono::steady_clock;

double Since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The named simulator knobs at their values: one-parameter knobs, and the payload's mass with the
// position its refinement recorded (the nominal position when it was not refined).
std::vector<KnobValue> NamedKnobValues(const CandidateSet& set, const Refinement& r, const Verdict& v,
                                       const std::vector<int>& named) {
  std::vector<KnobValue> out;
  for (size_t j = 0; j < named.size() && j < v.named.size(); ++j) {
    const KnobCandidate& c = set.candidates[named[j]];
    if (c.knob_index >= 0) out.push_back({c.knob_index, v.named[j].value});
    if (c.key == "payload" && set.payload_knob[0] >= 0) {
      out.push_back({set.payload_knob[0], v.named[j].value});
      if (std::isfinite(r.payload_x)) out.push_back({set.payload_knob[1], r.payload_x});
      if (std::isfinite(r.payload_y)) out.push_back({set.payload_knob[2], r.payload_y});
    }
  }
  return out;
}

// A named gain of every servo (family actuator_gain, no leg, no side), which a side's could stand in for.
bool NamesAWholeRobotGain(const Analysis& a) {
  return std::any_of(a.naming.named.begin(), a.naming.named.end(), [&](int k) {
    const KnobCandidate& c = a.candidates.candidates[k];
    return c.simulated && c.family == "actuator_gain" && c.WholeRobot();
  });
}

// A challenge of named knobs (LegSearchOptions::challenge_named): on a plane (on uneven ground the
// runoff scores contenders by their own models), knobs named, none of them a leg's, and the
// corrected model still below the real-trained ceiling, closing little of the gap, or named with
// little agreement between the resamples; a named side's or every servo's gain always
// (challenge_side, challenge_whole).
bool WantChallenge(const Analysis& a, const LegSearchOptions& options) {
  if (!options.challenge_named || a.baseline.permute_placements) return false;
  const bool unsure = std::any_of(a.verdict.named.begin(), a.verdict.named.end(), [&](const VerdictNamed& n) {
    return n.inclusion >= 0 && n.inclusion < options.challenge_inclusion;
  });
  const bool short_of_it =
      a.adequacy.below_ceiling || a.adequacy.gap_closed < options.challenge_gap_closed || unsure || a.posture.left_out;
  const auto named_where = [&](auto part) {
    return std::any_of(a.naming.named.begin(), a.naming.named.end(),
                       [&](int c) { return !(a.candidates.candidates[c].*part).empty(); });
  };
  if (named_where(&KnobCandidate::leg)) return false;
  if (options.challenge_side && named_where(&KnobCandidate::side)) return true;
  if (options.challenge_whole && NamesAWholeRobotGain(a)) return true;
  return !(a.verdict.status == "explained" && !a.posture.left_out) && short_of_it;
}

}  // namespace

bool WantLegSearch(const Analysis& a, const LegSearchOptions& options) {
  if (!options.enabled) return false;
  if (!a.naming.named.empty()) return WantChallenge(a, options);
  if (a.verdict.status != "unexplained") return false;
  const auto& in = a.adequacy.residual.structured_in;
  return !options.only_with_tails || std::find(in.begin(), in.end(), "tails") != in.end();
}

namespace {

// Stage 3 (the candidates' signatures) on the inputs and baseline in `a`. A run again on only some
// knobs keeps the other candidates of `first_look` (their signatures as recorded then) as
// competitors, and returns how many it kept.
template <typename Stage>
int RecordCandidates(const KnobSimulator& simulator, const AnalysisOptions& options, const Stage& stage, Analysis* a,
                     const CandidateSet* first_look = nullptr) {
  const auto t = Clock::now();
  stage("candidates (knob signatures)");
  a->candidates = BuildCandidates(simulator, a->inputs, a->baseline, options.candidates);
  int kept = 0;
  if (first_look && options.candidates.only_knobs) {
    kept = KeepFirstLookCandidates(*first_look, *options.candidates.only_knobs, &a->candidates);
  }
  a->seconds.candidates += Since(t);
  return kept;
}

// Stages 4 to 8 (selection and refinement to verdict) on the candidates in `a`.
template <typename Stage>
void SelectToVerdict(const KnobSimulator& simulator, const AnalysisOptions& options, const Stage& stage, Analysis* a) {
  auto t = Clock::now();
  stage("selection and refinement");
  a->refinement = SelectAndRefine(simulator, a->inputs, a->baseline, options.candidates, options.refine, &a->candidates);
  a->seconds.refine += Since(t), t = Clock::now();
  stage("confidence (bootstrap)");
  std::mt19937_64 rng(options.seed + 1);
  a->confidence = AssessConfidence(a->candidates, a->refinement, rng);
  a->seconds.confidence += Since(t), t = Clock::now();
  stage("adequacy");
  a->adequacy = AssessAdequacy(a->inputs, a->baseline, a->null_shortfall, a->candidates, a->refinement, options.adequacy);
  a->naming = DecideNamed(a->candidates, a->refinement, a->confidence, a->adequacy, options.verdict);
  a->seconds.adequacy += Since(t), t = Clock::now();
  stage("ties and experiment checks");
  a->ties = FindTies(&simulator, a->inputs, a->baseline, a->candidates, a->refinement, a->naming.named, options.ties);
  a->seconds.ties += Since(t);
  a->verdict = ComposeVerdict(a->baseline, a->candidates, a->refinement, a->confidence, a->adequacy, a->naming,
                              a->ties, options.verdict);
}

// The runoff runs on uneven ground when the stages before left a mismatch: something named but
// not explained, or nothing named for a located mismatch.
bool WantRunoff(const Analysis& a, const RunoffOptions& options) {
  if (!options.enabled || a.ground.search.named) return false;
  if (options.only_on_uneven_ground && !a.baseline.permute_placements) return false;
  return a.verdict.status == "partly_explained" || a.verdict.status == "unexplained";
}

// A search by models of their own (the runoff's or the leg search's) with the analysis's model,
// its ground and the seed of its recordings at other places.
LegSearchOptions OwnModels(LegSearchOptions o, const AnalysisOptions& options) {
  o.model = options.locate.model;
  o.misfit_elsewhere = options.locate.uneven_ground;
  o.elsewhere_seed = options.seed + 17;
  o.chance = options.candidates.chance;
  return o;
}

// The payload search (stage 8c) runs on a plane where neither the ground's search nor the runoff
// named anything: as the challenger of a leg the leg search named (PayloadSearchOptions::
// challenge_leg), or, enabled or where the posture is left out (PostureCheck), when the stages before
// either left a located mismatch with nothing named or named knobs the leg search was to challenge
// (`challenge`, WantChallenge before it ran).
bool WantPayloadSearch(const Analysis& a, const PayloadSearchOptions& options, bool challenge) {
  if (a.baseline.permute_placements || a.ground.search.named || a.runoff.search.named) return false;
  if (a.leg_search.named) return options.challenge_leg;
  if (!options.enabled && !(options.on_posture && a.posture.left_out)) return false;
  if (!a.naming.named.empty()) return options.challenge_named && challenge;
  return a.verdict.status == "unexplained" && a.verdict.named.empty();
}

// The knobs the probes named, as the verdict says them.
std::vector<std::string> NamedKnobs(const Analysis& a) {
  std::vector<std::string> named;
  for (const VerdictNamed& n : a.verdict.named) named.push_back(n.knob);
  return named;
}

// "the named correction (floor.friction.sliding 0.708, tracker_bias)" or "nothing named".
std::string CorrectionWords(const Verdict& v) {
  std::vector<std::string> words;
  for (const VerdictNamed& n : v.named) words.push_back(n.knob + (std::isfinite(n.lo) ? Fmt(" %.3g", n.value) : ""));
  return words.empty() ? "nothing named" : "the named correction (" + JoinWords(words) + ")";
}

// The posture options of the analysis's checks (their own seed).
PostureOptions NamedPostureOptions(const AnalysisOptions& options) {
  PostureOptions o = options.posture;
  o.seed = options.seed + 19;
  return o;
}

// The posture check (posture.h) of the simulator knobs `values` and the IMU offset `imu`.
PostureCheck CheckNamedPosture(const KnobSimulator& simulator, const AnalysisOptions& options, const Analysis& a,
                               const std::vector<KnobValue>& values, const Eigen::Vector2d& imu) {
  return CheckPosture(simulator, a.inputs, a.candidates.nominal, a.candidates.recording, options.candidates.recording,
                      values, imu, CorrectionWords(a.verdict), NamedPostureOptions(options));
}

// The posture each payload column's best point leaves (PostureLeft), against one comparison of the
// real set with the sim set (the same as CheckNamedPosture's, measured once for every column).
PostureLeft PayloadPostureLeft(const KnobSimulator& simulator, const AnalysisOptions& options, const Analysis& a) {
  const PostureOptions o = NamedPostureOptions(options);
  const PostureCheck compared = ComparePosture(a.inputs, GroundOf(simulator), o);
  return [&simulator, &options, &a, compared, o](const std::vector<KnobValue>& values) {
    const PostureCheck c = CheckCorrectionPosture(compared, simulator, a.inputs, a.candidates.nominal,
                                                  a.candidates.recording, options.candidates.recording, values,
                                                  Eigen::Vector2d::Zero(), CorrectionWords(a.verdict), o);
    return c.ran ? c.z_left : NAN;
  };
}

// The ground's standing tilt (stage 8a) on a height field.
void SearchTheGround(const KnobSimulator& simulator, const AnalysisOptions& options, Analysis* a) {
  const auto t = Clock::now();
  GroundSearchOptions ground = options.ground;
  ground.search = OwnModels(ground.search, options);
  ground.seed = options.seed + 23;
  a->ground = SearchGround(simulator, a->inputs, a->candidates, options.candidates, ground);
  AddGroundSearch(simulator, a->ground, &a->verdict);
  a->seconds.ground += Since(t);
}

// Stages 8a to 8d: the ground on a height field, the runoff on uneven ground, then the leg search
// when still nothing is named, then the payload search.
template <typename Stage>
void SearchByOwnModels(const KnobSimulator& simulator, const AnalysisOptions& options, const Stage& stage, Analysis* a) {
  const bool challenge = !a->naming.named.empty() && WantChallenge(*a, options.legs);
  const std::vector<std::string> named = NamedKnobs(*a);
  if (options.ground.enabled && !simulator.plane_ground()) {
    stage("ground (the standing tilt's spread)");
    SearchTheGround(simulator, options, a);
  }
  if (WantRunoff(*a, options.runoff)) {
    const auto t = Clock::now();
    stage("runoff (contenders scored by models of their own)");
    RunoffOptions runoff = options.runoff;
    runoff.search = OwnModels(runoff.search, options);
    a->runoff = RunRunoff(simulator, a->inputs, a->candidates, a->refinement, options.candidates, runoff);
    AddRunoff(simulator, &a->runoff, &a->verdict);
    a->seconds.runoff += Since(t);
  }
  if (!a->ground.search.named && !a->runoff.search.named && WantLegSearch(*a, options.legs)) {
    const auto t = Clock::now();
    const LegSearchOptions legs = OwnModels(options.legs, options);
    const bool sides = options.legs.challenge_whole && NamesAWholeRobotGain(*a);
    stage(sides ? "leg search (every leg's and every side's gain)" : "leg search (every leg's gain)");
    a->leg_search = SearchLegGains(simulator, a->inputs, a->candidates, options.candidates, legs, sides);
    if (!a->naming.named.empty()) {
      LegSearchChallenge(a->inputs, named, a->refinement.selection.heldout_corrected, legs, &a->leg_search);
    }
    a->seconds.legs += Since(t);
  }
  if (WantPayloadSearch(*a, options.payload, challenge)) {
    const auto t = Clock::now();
    stage(a->leg_search.named ? "payload search (its mass and position, against the named leg)"
                              : "payload search (its mass and position)");
    PayloadSearchOptions payload = options.payload;
    payload.search = OwnModels(payload.search, options);
    a->payload_search = SearchPayload(simulator, a->inputs, a->candidates, options.candidates, payload,
                                      PayloadPostureLeft(simulator, options, *a));
    if (!a->naming.named.empty()) {
      PayloadSearchChallenge(a->inputs, named, a->refinement.selection.heldout_corrected, payload, &a->payload_search);
    }
    PayloadVersusLeg(a->inputs, payload, &a->leg_search, &a->payload_search);
    a->seconds.payload += Since(t);
  }
  AddLegSearch(a->leg_search, &a->verdict);  // after the payload search, which can take the leg's name
  AddPayloadSearch(a->payload_search, &a->verdict);
}

// The leg and payload searches' best points that named nothing, for the advice of more placements.
std::vector<SearchNearMiss> SearchNearMisses(const Analysis& a, const AnalysisOptions& options) {
  std::vector<SearchNearMiss> near;
  const auto add = [&near](const LegSearch& s, const std::string& by, const std::string& family,
                           const std::string& said, double bar) {
    if (!s.ran || s.named || s.best < 0 || !std::isfinite(s.nominal_score)) return;
    near.push_back({by, s.knob, family, said, BestScore(s) - s.nominal_score, s.draws.chance, s.z_vs_nominal, bar,
                    static_cast<int>(s.best_rows.size())});
  };
  const LegSearch& legs = a.leg_search;
  add(legs, "the leg search", "actuator_gain", "a weak " + LegSaid(legs), options.legs.z);
  if (a.payload_search.ran) {
    add(a.payload_search.search, "the payload search", "payload", PayloadSaid(a.payload_search), options.payload.search.z);
  }
  return near;
}

// The knobs the runoff, the leg search or the payload search recorded without naming them.
std::vector<std::string> SearchedWithoutName(const Analysis& a) {
  std::vector<std::string> knobs;
  for (const LegSearch* s : {&a.ground.search, &a.runoff.search, &a.leg_search, &a.payload_search.search}) {
    if (!s->ran || s->named) continue;
    for (const LegSearchPoint& p : s->points) AddUnique(&knobs, p.knob);
  }
  return knobs;
}

// "; recorded again: the 4 of 23 knobs the first look screened in (held-out z >= 0.8 and >= 0.25 of
// the step's best at some step, selected or confusable): a, b, c, d; 9 other candidates kept their
// first-look signatures".
std::string ScreenedPart(const KnobSimulator& simulator, const std::vector<int>& knobs, const AnalysisOptions& options,
                         int kept) {
  std::string names;
  for (int k : knobs) names += (names.empty() ? "" : ", ") + simulator.knobs()[k].name;
  return Fmt("; recorded again: the %.0f", static_cast<double>(knobs.size())) +
         Fmt(" of %.0f knobs the first look screened in", static_cast<double>(simulator.knobs().size())) +
         Fmt(" (held-out z >= %.3g", options.confirm_screen_z) +
         Fmt(" and >= %.3g of the step's best at some step, selected or confusable): ", options.confirm_screen_share) +
         (names.empty() ? "none" : names) +
         Fmt("; %.0f other candidates kept their first-look signatures", kept);
}

// The adequacy's null shortfall, drawn or recorded (AnalysisOptions::null_source).
NullShortfall MeasureNull(const KnobSimulator& simulator, const AnalysisInputs& in, const Baseline& base,
                          const AnalysisOptions& options) {
  const bool recorded = options.null_source == NullSource::kRecorded ||
                        (options.null_source == NullSource::kAuto && options.locate.uneven_ground);
  if (!recorded) return MeasureNullShortfall(in, base, options.locate.model, options.adequacy);
  RecordedNullOptions o = options.recorded_null;
  o.seed = options.seed + 13;
  o.folds = options.locate.folds;
  o.model = options.locate.model;
  o.recording = options.candidates.recording;
  return RecordNullShortfall(simulator, in, base, o);
}

// The recordings an analysis's candidates and refinement made and read from the cache, to count
// those of a run again beside the first run's.
struct RecordingCounts {
  int recorded = 0, from_cache = 0, requests = 0, refined = 0, refined_from_cache = 0;
  static RecordingCounts Of(const Analysis& a) {
    return {a.candidates.recorded, a.candidates.from_cache, a.candidates.requests, a.refinement.recorded,
            a.refinement.from_cache};
  }
  void AddTo(Analysis* a) const {
    a->candidates.recorded += recorded, a->candidates.from_cache += from_cache, a->candidates.requests += requests;
    a->refinement.recorded += refined, a->refinement.from_cache += refined_from_cache;
  }
};

// Stages 3 to 8 again with signatures of every execution (Analysis::every_execution_because), on
// the knobs the first look screened in when options.confirm_screened_only.
template <typename Stage>
void RunAgainWithEveryExecution(const KnobSimulator& simulator, const AnalysisOptions& options, const Stage& stage,
                                Analysis* a) {
  AnalysisOptions every = options;
  every.candidates.executions_per_placement = RealExecutionsPerPlacement(a->inputs);
  if (options.confirm_screened_only) {
    every.candidates.only_knobs =
        ScreenedKnobs(a->candidates, a->refinement.selection, options.confirm_screen_z, options.confirm_screen_share);
  }
  const RecordingCounts first = RecordingCounts::Of(*a);  // the recordings of both runs are counted
  const CandidateSet first_look = std::move(a->candidates);
  const int kept = RecordCandidates(simulator, every, stage, a, &first_look);
  SelectToVerdict(simulator, every, stage, a);
  if (every.candidates.only_knobs) {
    a->every_execution_because += ScreenedPart(simulator, *every.candidates.only_knobs, options, kept);
  }
  first.AddTo(a);
}

// The IMU offset the verdict names (rad, pitch and roll; zero when none is named).
Eigen::Vector2d NamedImuOffset(const Analysis& a) {
  const std::vector<int>& selected = a.refinement.selection.selected;
  for (int k : a.naming.named) {
    const auto it = std::find(selected.begin(), selected.end(), k);
    if (a.candidates.candidates[k].family != "imu_bias" || it == selected.end()) continue;
    const Eigen::VectorXd& theta = a.refinement.selection.fit.theta[it - selected.begin()];
    if (theta.size() >= 2) return theta.head<2>();
  }
  return Eigen::Vector2d::Zero();
}

// The correction of what is named at the end (a search's recording when a search named it, else the
// knobs' fit), its simulator knobs' values, and the posture check of a search's name; then the
// posture in the verdict.
void CorrectAndCheckPosture(const KnobSimulator& simulator, const AnalysisOptions& options, Analysis* a) {
  if (const LegSearch* own = NamedByOwnModels(*a)) {
    a->correction = LegSearchCorrection(*own);
    a->named_values = {{own->knob_index, own->value}};
    a->named_values.insert(a->named_values.end(), own->also.begin(), own->also.end());
    const auto t = Clock::now();
    a->posture = CheckNamedPosture(simulator, options, *a, a->named_values, Eigen::Vector2d::Zero());
    a->seconds.posture += Since(t);
  } else {
    a->correction = MakeCorrection(a->inputs, a->baseline, a->candidates, a->refinement.selection.fit);
  }
  AddPostureCheck(a->posture, options.posture.z, &a->verdict);
}

}  // namespace

bool AnalysisOptions::IsValid(std::string* error) const {
  if (std::isnan(every_execution_from_z)) {
    *error = "every_execution_from_z: a number expected (infinity: near misses are not confirmed)";
    return false;
  }
  if (std::isnan(confirm_screen_z) || !(confirm_screen_share >= 0 && confirm_screen_share <= 1)) {
    *error = "confirm_screen_z a number (-infinity: every knob the first look scored), confirm_screen_share in [0, 1]";
    return false;
  }
  return locate.IsValid(error) && candidates.IsValid(error) && refine.IsValid(error) && adequacy.IsValid(error) &&
         recorded_null.IsValid(error) &&
         ties.IsValid(error) && verdict.IsValid(error) && legs.IsValid(error) &&
         ground.IsValid(error) && runoff.IsValid(error) && payload.IsValid(error) && posture.IsValid(error) &&
         more_data.IsValid(error);
}

const LegSearch* NamedByOwnModels(const Analysis& a) {
  if (a.ground.search.named) return &a.ground.search;
  if (a.runoff.search.named) return &a.runoff.search;
  if (a.leg_search.named) return &a.leg_search;
  return a.payload_search.search.named ? &a.payload_search.search : nullptr;
}

std::vector<int> ScreenedKnobs(const CandidateSet& set, const SelectionResult& selection, double from_z,
                               double share) {
  std::vector<int> effects = selection.selected;
  for (const SelectionStep& step : selection.steps) {
    double best = -std::numeric_limits<double>::infinity();
    for (const CandidateScore& c : step.candidates) best = std::max(best, c.z);
    const double z = std::max(from_z, share * best);
    for (const CandidateScore& c : step.candidates) {
      if (c.z >= z) effects.push_back(c.effect);
    }
    effects.insert(effects.end(), step.confusable.begin(), step.confusable.end());
  }
  std::vector<int> knobs;
  if (set.tracker_knob >= 0) knobs.push_back(set.tracker_knob);
  for (int e : effects) {
    const KnobCandidate& c = set.candidates.at(e);
    if (c.knob_index >= 0) knobs.push_back(c.knob_index);
    if (c.key == "payload") knobs.insert(knobs.end(), std::begin(set.payload_knob), std::end(set.payload_knob));
  }
  std::sort(knobs.begin(), knobs.end());
  knobs.erase(std::unique(knobs.begin(), knobs.end()), knobs.end());
  return knobs;
}

// The largest execution index of a placement in the real set, plus one (0 without sequence data).
int RealExecutionsPerPlacement(const AnalysisInputs& in) {
  const std::vector<int> step = RealSteps(in);
  return step.empty() ? 0 : *std::max_element(step.begin(), step.end()) + 1;
}

namespace {

// Do the signatures record fewer executions per placement than the real set has (0: the
// protocol's own number, all of them)?
bool SignaturesMissExecutions(const AnalysisInputs& in, const AnalysisOptions& options) {
  const int signature = options.candidates.executions_per_placement;
  return signature > 0 && RealExecutionsPerPlacement(in) > signature;
}

}  // namespace

bool FirstLookIsAScreen(const AnalysisInputs& in, const AnalysisOptions& options) {
  return options.every_execution_to_confirm && SignaturesMissExecutions(in, options);
}

std::string EveryExecutionBecause(const Analysis& a, const AnalysisOptions& options) {
  if (!SignaturesMissExecutions(a.inputs, options)) return "";
  const int signature = options.candidates.executions_per_placement;
  const int real = RealExecutionsPerPlacement(a.inputs);
  const std::string of_real = std::to_string(signature) + " of the real set's " + std::to_string(real) +
                              " executions per placement";
  for (const VerdictDrifting& d : a.verdict.drifting) {
    if (options.every_execution_on_step_drift && d.along == "execution index") {
      return d.knob + "'s fitted size varied with the execution index, and the signatures had recorded " + of_real;
    }
  }
  if (!options.every_execution_to_confirm) return "";
  const std::string look =
      FirstLookIsAScreen(a.inputs, options) ? "a first look without likelihood searches" : "a first look";
  std::string named;
  for (const VerdictNamed& n : a.verdict.named) named += (named.empty() ? "" : ", ") + n.knob;
  if (!named.empty()) {
    return look + " named " + named + " from signatures of " + of_real + "; a name is confirmed with every execution";
  }
  const std::vector<SelectionStep>& steps = a.refinement.selection.steps;
  const CandidateScore* best = FirstStepBest(a.refinement.selection);
  if (!best || !(best->z >= options.every_execution_from_z)) return "";
  const std::string& key = a.candidates.candidates.at(best->effect).key;
  const std::string z = Fmt("held-out z %.2f", best->z) + Fmt(", significant from %.2f", steps[0].threshold_z);
  if (best->z >= steps[0].threshold_z) {
    return look + " from signatures of " + of_real + " selected " + key + " (" + z + ") but did not name it";
  }
  return look + " from signatures of " + of_real + " came near: " + key + " reached " + z;
}

namespace {

// Stages 3 to 8 and the posture on the inputs, baseline and null in `a`: the candidates (a first
// look, run again with every execution when EveryExecutionBecause says so), the posture of what
// they name, the searches by models of their own and the final correction. A second call starts
// afresh from the candidates and counts the recordings of both.
template <typename Stage>
void NameAndCheck(const KnobSimulator& simulator, const AnalysisOptions& options, const Stage& stage, Analysis* a) {
  const RecordingCounts before = RecordingCounts::Of(*a);
  a->ground = GroundSearch{}, a->runoff = Runoff{}, a->leg_search = LegSearch{}, a->payload_search = PayloadSearch{};
  // A first look whose selections will be recorded again with every execution is a screen: the
  // run again searches what it selects, so the first look searches nothing.
  AnalysisOptions first = options;
  const bool screen = FirstLookIsAScreen(a->inputs, options);
  if (screen) first.refine.refine_iterations = 0;
  RecordCandidates(simulator, first, stage, a);
  SelectToVerdict(simulator, first, stage, a);
  a->every_execution_because = EveryExecutionBecause(*a, options);
  if (!a->every_execution_because.empty()) {
    RunAgainWithEveryExecution(simulator, options, stage, a);
  } else if (screen && !a->refinement.selection.selected.empty()) {
    SelectToVerdict(simulator, options, stage, a);  // not looked at again (every_execution_from_z): searched now
  }
  const auto t = Clock::now();
  stage("posture (the named physics against the real torso's)");
  a->named_values = NamedKnobValues(a->candidates, a->refinement, a->verdict, a->naming.named);
  a->posture = CheckNamedPosture(simulator, options, *a, a->named_values, NamedImuOffset(*a));
  a->seconds.posture += Since(t);
  SearchByOwnModels(simulator, options, stage, a);
  CorrectAndCheckPosture(simulator, options, a);
  before.AddTo(a);
}

// When the posture contradicts the named IMU offset (the rest of the correction gives the real
// posture without it), stages 3 to 8 and the posture again without an IMU offset among the
// candidates (Analysis::imu_contradicted).
template <typename Stage>
void RefitWithoutContradictedImu(const KnobSimulator& simulator, const AnalysisOptions& options, const Stage& stage,
                                 Analysis* a) {
  if (!options.posture.refit_without_imu || NamedByOwnModels(*a) || !ContradictsNamedImu(a->posture, options.posture.z)) {
    return;
  }
  a->imu_contradicted = {true, NamedKnobs(*a), a->posture};
  AnalysisOptions without = options;
  without.candidates.imu_offset = false;
  stage("again without an IMU offset (the torso's posture contradicts the named one)");
  NameAndCheck(simulator, without, stage, a);
  a->verdict.sentence += ContradictedImuSentence(a->imu_contradicted);
}

}  // namespace

Analysis Analyse(const SampleSet& sim, const SampleSet& real, const KnobSimulator* simulator,
                 const AnalysisOptions& options, const std::string& no_simulator_reason) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "analysis options", error);
  auto stage = [&](const std::string& name) {
    if (options.on_stage) options.on_stage(name);
  };
  const auto start = Clock::now();
  Analysis a;
  stage("inputs and locate");
  a.inputs = PrepareInputs(sim, real, options.seed);
  a.baseline = LocateMismatch(a.inputs, options.locate);
  a.seconds.locate = Since(start);
  if (!simulator) {
    a.locate_only_because = no_simulator_reason;
    a.verdict = LocateOnlyVerdict(a.baseline, no_simulator_reason);
    stage("posture (the real torso's against the sim set's)");
    const auto posture_start = Clock::now();
    a.posture = ComparePosture(a.inputs, options.posture.ground, options.posture);
    AddPostureCheck(a.posture, options.posture.z, &a.verdict);
    a.seconds.posture = Since(posture_start);
    a.seconds.total = Since(start);
    return a;
  }
  a.knobs_analysed = true;
  const auto null_start = Clock::now();
  a.null_shortfall = MeasureNull(*simulator, a.inputs, a.baseline, options);
  a.seconds.adequacy += Since(null_start);
  NameAndCheck(*simulator, options, stage, &a);
  RefitWithoutContradictedImu(*simulator, options, stage, &a);
  a.more_data = AdviseMoreData(a.inputs, a.candidates, a.refinement, a.naming, a.verdict, SearchedWithoutName(a),
                               options.more_data, SearchNearMisses(a, options));
  a.verdict.sentence += MoreDataSentence(a.more_data);
  a.seconds.total = Since(start);
  return a;
}

}  // namespace dgmm::sim2real
