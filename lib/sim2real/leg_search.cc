#include "sim2real/leg_search.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <optional>

#include "sim2real/recorded_null.h"
#include "sim2real/refine_search.h"
#include "sim2real/sag_mode.h"
#include "sim2real/selection.h"
#include "sim2real/sentence_format.h"
#include "sim2real/units.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

// A leg's or a side's gain (actuator_gain with a leg or a side), named by its part: "rear_left",
// "left side"; any other knob by its name.
bool IsPart(const Knob& k) { return k.family == "actuator_gain" && (!k.leg.empty() || !k.side.empty()); }
bool IsSideGain(const Knob& k) { return IsPart(k) && k.leg.empty(); }
std::string PartName(const Knob& k) {
  return !IsPart(k) ? k.name : !k.leg.empty() ? k.leg : k.side + " side";
}

using Clock = std::chrono::steady_clock;

// log(exp(a) + exp(b)) without overflow.
double LogAddExp(double a, double b) {
  const double top = std::max(a, b);
  return top + std::log(std::exp(a - top) + std::exp(b - top));
}

// log of (1 - e) N(x; m, S) + e N(x; m, k^2 S) for every sample of s.
Eigen::VectorXd RobustLogLikelihood(const LinearGaussianModel& model, const Samples& s, double e, double k) {
  Eigen::VectorXd out(s.size());
  const double d = s.pose_dim();
  for (int i = 0; i < s.size(); ++i) {
    const Prediction p = model.Predict(s.command[i], s.z.row(i).transpose(), s.first_execution[i]);
    const double m = p.chol.triangularView<Eigen::Lower>().solve(s.x.row(i).transpose() - p.mean).squaredNorm();
    const double base = -0.5 * (d * std::log(2 * M_PI) + p.log_det);
    const double core = std::log1p(-e) + base - 0.5 * m;
    const double broad = std::log(e) + base - d * std::log(k) - 0.5 * m / (k * k);
    out(i) = LogAddExp(core, broad);
  }
  return out;
}

// A recording's own model, fitted on some of its rows: the sag mode (sag_mode.h) when the search has
// a reference, else one model scored with a broad component.
struct OwnModel {
  std::optional<SagModel> sag;
  LinearGaussianModel plain;
  const LinearGaussianModel& model() const { return sag ? sag->core : plain; }
};

// A recording with its own model and the real samples' log-likelihood per sample under it.
struct Scored {
  Samples samples;
  Eigen::VectorXd rows;
  OwnModel own;
  bool walkable = true;
  const LinearGaussianModel& model() const { return own.model(); }
};

OwnModel FitOwnModel(const Samples& s, const std::vector<int>& rows, const LegSearchOptions& options,
                     const SagReference* ref) {
  OwnModel out;
  if (ref) out.sag = FitSagModel(s, rows, *ref, options.model, options.sag);
  else out.plain = LinearGaussianModel::Fit(s, options.model, rows);
  return out;
}

Eigen::VectorXd OwnLogLikelihood(const OwnModel& m, const Samples& s, const LegSearchOptions& options,
                                 const SagReference* ref) {
  if (m.sag) return SagLogLikelihood(*m.sag, *ref, s, options.sag);
  return RobustLogLikelihood(m.plain, s, options.outlier_share, options.outlier_scale);
}

// How much worse the real samples fit a recording's model than the recording's own unseen samples:
// the model fitted on the even executions of every placement (each placement stands for one
// command and heading, so every cell keeps samples on both sides), then per sample
//   misfit = mean robust l(odd executions) - mean robust l(real).
// About 0 when the real robot is that simulation; the nominal's misfit is the whole mismatch.
double Misfit(const Samples& recording, const AnalysisInputs& in, const LegSearchOptions& options,
              const SagReference* ref) {
  std::map<int, int> executions;  // per placement, seen so far
  std::vector<int> fit_rows, held;
  for (int i = 0; i < recording.size(); ++i) (executions[recording.episode[i]]++ % 2 == 0 ? fit_rows : held).push_back(i);
  if (fit_rows.empty() || held.empty()) return NAN;
  const OwnModel m = FitOwnModel(recording, fit_rows, options, ref);
  return OwnLogLikelihood(m, SubsetSamples(recording, held), options, ref).mean() -
         OwnLogLikelihood(m, in.real, options, ref).mean();
}

// The same with a recording of the point at other places as its unseen samples: `elsewhere` their
// log-likelihoods under the point's own model (fitted on all of its recording, as the score's is),
// `placement` their placements, `real_rows` the real samples' (the score's rows):
//   misfit = mean robust l(elsewhere) - mean robust l(real).
// Its SE from the two sets' placement-clustered SEs (independent recordings).
double MisfitElsewhere(const Eigen::VectorXd& elsewhere, const std::vector<int>& placement,
                       const Eigen::VectorXd& real_rows, const AnalysisInputs& in, double* se) {
  *se = NAN;
  if (elsewhere.size() == 0) return NAN;
  double own = 0, own_se = 0, real = 0, real_se = 0;
  ClusteredMean(elsewhere, placement, &own, &own_se);
  ClusteredMean(real_rows, in.real.episode, &real, &real_se);
  *se = std::hypot(own_se, real_se);
  return own - real;
}

Scored ScoreRecording(const SampleSet& recording, const AnalysisInputs& in, const LegSearchOptions& options,
                      int nominal_size, const SagReference* ref) {
  Scored out;
  out.samples = MakeSamples(recording);
  const Samples& s = out.samples;
  // A recording that lost most of its samples (the robot fell in most placements) is no model of a robot that walked.
  out.walkable = s.size() >= nominal_size / 2 && s.size() > 0;
  if (!out.walkable) {
    out.rows = Eigen::VectorXd::Constant(in.real.size(), -INFINITY);
    return out;
  }
  out.own = FitOwnModel(s, {}, options, ref);
  out.rows = OwnLogLikelihood(out.own, in.real, options, ref);
  return out;
}

// The per-axis variance of a recording's residuals under its own model.
Eigen::VectorXd ResidualVariance(const Scored& scored) {
  const Eigen::MatrixXd r = scored.model().Residuals(scored.samples);
  return (r.rowwise() - r.colwise().mean()).colwise().squaredNorm() / std::max(1.0, r.rows() - 1.0);
}

// The values to record for one knob: `factors` of its nominal, inside its range, distinct.
std::vector<double> GridValues(const Knob& k, const std::vector<double>& factors) {
  std::vector<double> out;
  for (double f : factors) {
    const double v = std::clamp(f * k.nominal, k.lo, k.hi);
    if (std::none_of(out.begin(), out.end(), [&](double u) { return std::fabs(u - v) < 1e-9 * std::fabs(k.nominal); })) {
      out.push_back(v);
    }
  }
  return out;
}

// The points' search state: what was recorded, with scores.
struct SearchState {
  std::vector<LegSearchPoint> points;
  std::vector<Scored> scored;
  Scored nominal;
  int nominal_size = 0;
  std::optional<SagReference> ref;  // with options.sag_mode
  const SagReference* Ref() const { return ref ? &*ref : nullptr; }
  AlsoAt also;  // other knob values of a point (may be empty)
};

Recording SearchRecording(const CandidateSet& set, const LegSearchOptions& options) {
  Recording r = set.recording;
  r.executions_per_placement = options.executions_per_placement;
  return r;
}

// The nominal's second draw `second` (a negligible payload `kg` heavier) beside the first: the one
// whose model fits the real samples better becomes the search's nominal.
void ChooseNominalDraw(Scored second, double kg, const AnalysisInputs& in, SearchState* state, LegSearch* out) {
  NominalDraws& d = out->draws;
  d.recorded = true, d.added_kg = kg;
  d.first = state->nominal.walkable ? state->nominal.rows.mean() : -INFINITY;
  d.second = second.walkable ? second.rows.mean() : -INFINITY;
  if (state->nominal.walkable && second.walkable) {
    const PairedSum p = PairedDifference(second.rows, state->nominal.rows, NumberUnits(in.real.episode));
    d.z_second = p.se > 0 ? p.sum / p.se : NAN;
    d.chance = std::sqrt(std::max(0.0, p.sum * p.sum - p.se * p.se)) / in.real.size();
  }
  d.second_is_nominal = d.second > d.first;
  if (d.second_is_nominal) state->nominal = std::move(second);
}

// The j-th draw of a request: itself for j = 0, else the same physics a negligible payload j delta
// heavier (`unit`: the payload knob at its nominal plus delta, ChanceRequest), added to the request's
// own payload mass when it has one.
std::vector<KnobValue> Draw(std::vector<KnobValue> request, int j, const std::vector<KnobValue>& unit,
                            const KnobSimulator& simulator) {
  if (j == 0 || unit.empty()) return request;
  const double delta = unit[0].value - simulator.knobs()[unit[0].knob].nominal;
  for (KnobValue& v : request) {
    if (v.knob == unit[0].knob) {
      v.value += j * delta;
      return request;
    }
  }
  request.push_back({unit[0].knob, unit[0].value + (j - 1) * delta});
  return request;
}

// One score of `draws` recordings of one physics (LegSearchOptions::draws): the first's model and
// samples, the real samples' rows averaged over the draws; not walkable when any draw fell
// (ScoreRecording: kept under half of `nominal_size` samples).
Scored ScoreDraws(std::vector<SampleSet>::iterator first, int draws, const AnalysisInputs& in,
                  const LegSearchOptions& options, int nominal_size, const SagReference* ref) {
  Scored out = ScoreRecording(*first, in, options, nominal_size, ref);
  for (int j = 1; j < draws && out.walkable; ++j) {
    const Scored more = ScoreRecording(*(first + j), in, options, nominal_size, ref);
    out.walkable = more.walkable;
    out.rows += more.rows;
  }
  if (out.walkable) out.rows /= draws;
  else out.rows.setConstant(-INFINITY);  // as ScoreRecording's for a recording that fell
  return out;
}

// Records the wanted (knob, value) points (and first the nominal twice, when `state` has none yet),
// each `options.draws` times, and scores them.
void RecordPoints(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateSet& set,
                  const CandidateOptions& recording, const LegSearchOptions& options,
                  const std::vector<std::pair<int, double>>& wanted, SearchState* state, LegSearch* out) {
  const bool need_nominal = state->nominal.rows.size() == 0;
  const std::vector<KnobValue> unit = ChanceRequest(simulator, options.chance);
  const int draws = unit.empty() ? 1 : options.draws;
  const int nominal_draws = need_nominal ? (unit.empty() ? 1 : 2 * draws) : 0;
  std::vector<std::vector<KnobValue>> requests;
  for (int j = 0; j < nominal_draws; ++j) requests.push_back(Draw({}, j, unit, simulator));
  for (const auto& [k, v] : wanted) {
    std::vector<KnobValue> request = {{k, v}};
    if (state->also) {
      const std::vector<KnobValue> extra = state->also(k, v);
      request.insert(request.end(), extra.begin(), extra.end());
    }
    for (int j = 0; j < draws; ++j) requests.push_back(Draw(request, j, unit, simulator));
  }
  RecordingBatch batch = RecordBatch(simulator, SearchRecording(set, options), requests, recording.recording);
  auto next = batch.sets.begin();
  if (need_nominal) {
    state->nominal_size = next->size();
    state->nominal = ScoreDraws(next, draws, in, options, state->nominal_size, state->Ref());
    next += draws;
  }
  if (nominal_draws > draws) {
    const double kg = draws * (unit[0].value - simulator.knobs()[unit[0].knob].nominal);
    ChooseNominalDraw(ScoreDraws(next, draws, in, options, state->nominal_size, state->Ref()), kg, in, state, out);
    next += draws;
  }
  out->recorded += batch.recorded;
  out->from_cache += batch.from_cache;
  const auto& knobs = simulator.knobs();
  for (size_t j = 0; j < wanted.size(); ++j, next += draws) {
    const Knob& knob = knobs[wanted[j].first];
    state->scored.push_back(ScoreDraws(next, draws, in, options, state->nominal_size, state->Ref()));
    const Scored& s = state->scored.back();
    state->points.push_back({PartName(knob), knob.name, wanted[j].first, wanted[j].second,
                             s.walkable ? s.rows.mean() : -INFINITY, false});
  }
}

int BestPoint(const SearchState& state) {
  int best = -1;
  for (size_t j = 0; j < state.points.size(); ++j) {
    if (std::isfinite(state.points[j].score) && (best < 0 || state.points[j].score > state.points[best].score)) {
      best = static_cast<int>(j);
    }
  }
  return best;
}

// Half-steps either side of the named leg's best gain (towards its neighbours among the recorded
// gains, or a grid step beyond the last), inside the range, not yet recorded.
std::vector<std::pair<int, double>> HalfSteps(const SearchState& state, int best, const Knob& knob, double step) {
  const LegSearchPoint& b = state.points[best];
  double below = b.value - 2 * step, above = b.value + 2 * step;
  for (const LegSearchPoint& p : state.points) {
    if (p.knob_index != b.knob_index) continue;
    if (p.value < b.value) below = std::max(below, p.value);
    if (p.value > b.value) above = std::min(above, p.value);
  }
  std::vector<std::pair<int, double>> out;
  for (double v : {0.5 * (b.value + below), 0.5 * (b.value + above)}) {
    if (v >= knob.lo && v <= knob.hi) out.push_back({b.knob_index, v});
  }
  return out;
}

// Whether any point is a side's gain.
bool SidesAmong(const std::vector<Knob>& knobs, const std::vector<LegSearchPoint>& points) {
  return std::any_of(points.begin(), points.end(), [&](const LegSearchPoint& p) {
    return IsSideGain(knobs[p.knob_index]);
  });
}

// "leg3 at gain 0.3", "left side at gain 0.5" or "floor.friction.sliding at 0.4".
std::string PointName(const Knob& k, double value) {
  return IsPart(k) ? PartName(k) + Fmt(" at gain %.3g", value) : k.name + Fmt(" at %.3g", value);
}

// "; two draws of the nominal (the second a payload 0.00093 kg heavier) score 1.12 nats per real
// sample apart (z 7.78): the walk's own chance, counted in the z", or "" when they score alike.
std::string ChancePart(const NominalDraws& d) {
  if (!(d.chance > 0)) return "";
  return Fmt("; two draws of the nominal (the second a payload %.2g kg heavier) score ", d.added_kg) +
         Fmt("%.3g nats per real sample apart", std::fabs(d.second - d.first)) +
         Fmt(" (z %.2f): the walk's own chance, counted in the z", d.z_second);
}

// Names the best point's leg (or knob), or says why not.
void Decide(const AnalysisInputs& in, const std::vector<Knob>& knobs,
            const LegSearchOptions& options, SearchState* state, LegSearch* out) {
  out->points = state->points;
  out->best = BestPoint(*state);
  out->named = false;
  if (out->best < 0) {
    out->why = "every recording lost most of its placements (the robot fell)";
    return;
  }
  std::vector<Eigen::VectorXd> rows;
  for (const Scored& s : state->scored) rows.push_back(s.rows);
  const std::vector<bool> as_well = FitAsWellAsTheBest(rows, out->best, in.real.episode, options.z);
  const LegSearchPoint& b = state->points[out->best];
  out->legs_as_well.clear();
  for (size_t j = 0; j < rows.size(); ++j) {
    out->points[j].fits_as_well = as_well[j];
    const std::string& leg = state->points[j].leg;
    if (as_well[j] && leg != b.leg &&
        std::find(out->legs_as_well.begin(), out->legs_as_well.end(), leg) == out->legs_as_well.end()) {
      out->legs_as_well.push_back(leg);
    }
  }
  const Eigen::VectorXd& best_rows = state->scored[out->best].rows;
  out->z_vs_nominal = PairedZ(best_rows, state->nominal.rows, in.real.episode, out->draws.chance * best_rows.size());
  out->leg = b.leg, out->knob = b.knob, out->knob_index = b.knob_index, out->value = b.value;
  out->also = state->also ? state->also(b.knob_index, b.value) : std::vector<KnobValue>{};
  const Knob& knob = knobs[b.knob_index];
  out->nominal = knob.nominal, out->lo = knob.lo, out->hi = knob.hi;
  std::vector<double> values;
  std::vector<Eigen::VectorXd> leg_rows;
  int leg_best = 0;
  for (size_t j = 0; j < rows.size(); ++j) {
    if (state->points[j].knob_index != b.knob_index) continue;
    if (static_cast<int>(j) == out->best) leg_best = static_cast<int>(values.size());
    values.push_back(state->points[j].value);
    leg_rows.push_back(rows[j]);
  }
  out->as_well = FitAsWellSpan(leg_rows, leg_best, values, {}, in.real.episode, options.z);
  out->side = IsSideGain(knobs[b.knob_index]);
  const bool legs = IsPart(knobs[b.knob_index]);
  const std::string at = PointName(knobs[b.knob_index], b.value);
  if (out->z_vs_nominal < options.z) {
    out->why = "the best point (" + at +
               Fmt(") fits the real samples no better than the nominal (z %.2f)", out->z_vs_nominal) +
               ChancePart(out->draws);
  } else if (!out->legs_as_well.empty()) {
    out->why = "the best point is " + at + (legs ? ", but weak " : ", but ") + out->legs_as_well[0] +
               (out->legs_as_well.size() > 1 ? Fmt(" (and %.0f more legs)", out->legs_as_well.size() - 1.0) : "") +
               " fits the real samples as well: these data do not tell " +
               (!legs ? "which knob" : SidesAmong(knobs, state->points) ? "which leg or side" : "which leg");
  } else {
    out->named = true;
    out->why = "";
  }
  out->best_model = state->scored[out->best].model();
  out->best_rows = state->scored[out->best].rows;
  out->best_plain = out->best_model.LogLikelihood(in.real).mean();
  out->log_var =
      (ResidualVariance(state->scored[out->best]).array() / ResidualVariance(state->nominal).array()).log().matrix();
}

// The mean of a - b per sample and its SE, placements as units.
std::pair<double, double> MeanGain(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const std::vector<int>& placement) {
  const PairedSum d = PairedDifference(a, b, NumberUnits(placement));
  return {d.sum / a.size(), d.se / a.size()};
}

// LegSearch::real_gain, null_gain and z_null_corrected (LegSearchOptions::null_corrected_gain):
// the best point's and the nominal's gains on the real samples (their scores' rows) and on the
// nominal's recording at other places (`best_null`, `nominal_null`: its samples under each own model).
void NullCorrectedGain(const AnalysisInputs& in, const Scored& best, const Scored& nominal,
                       const Eigen::VectorXd& best_null, const Eigen::VectorXd& nominal_null,
                       const std::vector<int>& null_placement, const LegSearchOptions& options, LegSearch* out) {
  if (best_null.size() == 0) return;
  const auto [real, real_se] = MeanGain(best.rows, nominal.rows, in.real.episode);
  const auto [gain, gain_se] = MeanGain(best_null, nominal_null, null_placement);
  out->real_gain = real, out->null_gain = gain;
  out->z_null_corrected = (real - gain) / std::hypot(real_se, gain_se);
  out->null_corrected_gate = options.null_corrected_gain;
}

// The nominal's and the best point's misfits against second recordings at other places.
void MisfitsElsewhere(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateOptions& recording,
                      const SearchState& state, const LegSearchOptions& options, LegSearch* out) {
  out->misfit_elsewhere = true;
  const Scored& best_scored = state.scored[out->best];
  if (!state.nominal.walkable || !best_scored.walkable) return;  // no own model: misfits stay NaN, nothing named
  std::vector<KnobValue> best = {{out->knob_index, out->value}};
  best.insert(best.end(), out->also.begin(), out->also.end());
  const RecordingBatch b =
      RecordBatch(simulator, RealDesign(in, options.elsewhere_seed), {{}, best}, recording.recording);
  out->recorded += b.recorded;
  out->from_cache += b.from_cache;
  // The own models and real rows are the scores' (ScoreRecording); each set scored once per model.
  const Samples null = RealCommandsOf(b.sets[0], in), elsewhere = RealCommandsOf(b.sets[1], in);
  const auto rows = [&](const Scored& s, const Samples& x) {
    return x.size() == 0 ? Eigen::VectorXd() : OwnLogLikelihood(s.own, x, options, state.Ref());
  };
  const Eigen::VectorXd nominal_null = rows(state.nominal, null);
  double se = NAN;
  out->nominal_misfit = MisfitElsewhere(nominal_null, null.episode, state.nominal.rows, in, &se);
  out->best_misfit =
      MisfitElsewhere(rows(best_scored, elsewhere), elsewhere.episode, best_scored.rows, in, &out->best_misfit_se);
  NullCorrectedGain(in, best_scored, state.nominal, rows(best_scored, null), nominal_null, null.episode, options, out);
}

// The gate at other places: the real samples fit the best point's model no worse than its own
// recording there, within z SE; else the point is not named.
void GateElsewhere(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateOptions& recording,
                   const SearchState& state, const LegSearchOptions& options, const Knob& knob, LegSearch* out) {
  MisfitsElsewhere(simulator, in, recording, state, options, out);
  out->gap_closed = out->nominal_misfit > 0 ? 1 - out->best_misfit / out->nominal_misfit : NAN;
  if (std::isnan(out->best_misfit)) {
    out->named = false;
    out->why = "the best point (" + PointName(knob, out->value) +
               ") has no model to compare at other places: the robot fell in most placements of its recording "
               "or of the nominal's";
    return;
  }
  if (out->best_misfit <= options.z * out->best_misfit_se) {
    if (!options.null_corrected_gain || !(out->z_null_corrected < options.z)) return;
    out->named = false;
    out->why = "the best point (" + PointName(knob, out->value) +
               Fmt(") fits the real samples %.3g nats per sample better than the nominal, but the nominal's own ",
                   out->real_gain) +
               Fmt("recording at other places %.3g better too (z %.2f): a broader model's gain on new places, ",
                   out->null_gain, out->z_null_corrected) +
               "not evidence of this knob";
    return;
  }
  out->named = false;
  out->why = "the real samples fit the model of the best point (" + PointName(knob, out->value) +
             Fmt(") worse than its own recording at other places does (by %.3g nats per sample, ", out->best_misfit) +
             Fmt("%.1f SE)", out->best_misfit / out->best_misfit_se) +
             (knob.leg.empty() ? ": the mismatch is not this knob alone" : ": the mismatch is not a weak leg alone");
}

// Does the best point remove enough of the nominal's misfit? Else the leg is not named.
void CheckMisfit(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateOptions& recording,
                 const SearchState& state, const LegSearchOptions& options, const Knob& knob, LegSearch* out) {
  if (options.misfit_elsewhere) return GateElsewhere(simulator, in, recording, state, options, knob, out);
  out->nominal_misfit = Misfit(state.nominal.samples, in, options, state.Ref());
  out->best_misfit = Misfit(state.scored[out->best].samples, in, options, state.Ref());
  out->gap_closed = out->nominal_misfit > 0 ? 1 - out->best_misfit / out->nominal_misfit : NAN;
  if (out->gap_closed >= options.min_gap_closed) return;
  if (options.second_look_elsewhere) return GateElsewhere(simulator, in, recording, state, options, knob, out);
  out->named = false;
  out->why = "the best point (" + PointName(knob, out->value) +
             Fmt(") removes only %.0f%% of the nominal's misfit (the real samples' deficit against the recording's own "
                 "unseen samples, %.3g nats per sample; the best's: %.3g)", 100 * out->gap_closed, out->nominal_misfit,
                 out->best_misfit) +
             (knob.leg.empty() ? ": the mismatch is not this knob alone" : ": the mismatch is not a weak leg alone");
}

// The spacing of knob k's values in `grid` (the refinement's step), else a tenth of its nominal.
double GridStep(const std::vector<std::pair<int, double>>& grid, int k, double nominal) {
  double step = INFINITY;
  for (const auto& [ka, va] : grid) {
    for (const auto& [kb, vb] : grid) {
      if (ka == k && kb == k && va != vb) step = std::min(step, std::fabs(va - vb));
    }
  }
  return std::isfinite(step) ? step : 0.1 * std::fabs(nominal);
}

}  // namespace

double PairedZ(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const std::vector<int>& placement, double extra) {
  const PairedSum d = PairedDifference(a, b, NumberUnits(placement));
  const double se = std::hypot(d.se, extra);
  return se > 0 && std::isfinite(d.sum) ? d.sum / se : 0;
}

bool LegSearchOptions::IsValid(std::string* error) const {
  if (factors.empty() || std::any_of(factors.begin(), factors.end(), [](double f) { return !(f > 0); })) {
    *error = "leg search: factors must be positive";
    return false;
  }
  if (!(outlier_share > 0 && outlier_share < 1) || !(outlier_scale > 1)) {
    *error = "leg search: outlier_share in (0, 1) and outlier_scale > 1 expected";
    return false;
  }
  if (refine_steps < 0 || executions_per_placement < 0 || !(z > 0) || !(min_gap_closed >= 0 && min_gap_closed <= 1) ||
      !(challenge_gap_closed >= 0 && challenge_gap_closed <= 1) || !(challenge_inclusion >= 0 && challenge_inclusion <= 1)) {
    *error = "leg search: refine_steps >= 0, executions_per_placement >= 0, z > 0, min_gap_closed, "
             "challenge_gap_closed and challenge_inclusion in [0, 1] expected";
    return false;
  }
  if (!(sag.broad_share > 0 && sag.broad_share < 0.5) || !(sag.broad_scale > 1) || !(sag.floor >= 0)) {
    *error = "leg search: sag broad_share in (0, 0.5), broad_scale > 1 and floor >= 0 expected";
    return false;
  }
  if (draws < 1) {
    *error = "leg search: draws >= 1 expected";
    return false;
  }
  return model.IsValid(error) && chance.IsValid(error);
}

std::vector<int> LegGainKnobs(const KnobSimulator& simulator, bool sides) {
  std::vector<int> out;
  const auto& knobs = simulator.knobs();
  for (const bool side : {false, true}) {
    if (side && !sides) break;
    for (int k = 0; k < static_cast<int>(knobs.size()); ++k) {
      const Knob& knob = knobs[k];
      const bool part = side ? IsSideGain(knob) : IsPart(knob) && !knob.leg.empty();
      if (part && knob.role == Knob::Role::kShift) out.push_back(k);
    }
  }
  return out;
}

LegSearch SearchOwnModels(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateSet& set,
                          const CandidateOptions& recording, const LegSearchOptions& options,
                          const std::vector<std::pair<int, double>>& grid, const AlsoAt& also) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "leg search options", error);
  const auto start = Clock::now();
  LegSearch out;
  if (grid.empty()) {
    out.why = "no knob to search";
    return out;
  }
  out.ran = true;
  out.score = options.sag_mode ? "sag" : "robust";
  const auto& knobs = simulator.knobs();
  SearchState state;
  state.also = also;
  if (options.sag_mode) state.ref = MakeSagReference(in.sim, options.model);
  RecordPoints(simulator, in, set, recording, options, grid, &state, &out);
  out.nominal_model = state.nominal.model();
  out.nominal_score = state.nominal.rows.mean();
  Decide(in, knobs, options, &state, &out);
  const double step = out.best >= 0 ? GridStep(grid, out.knob_index, out.nominal) : 0;
  for (int round = 0; out.named && round < options.refine_steps; ++round) {
    const auto more = HalfSteps(state, out.best, knobs[out.knob_index], step / (1 << round));
    if (more.empty()) break;
    RecordPoints(simulator, in, set, recording, options, more, &state, &out);
    Decide(in, knobs, options, &state, &out);
  }
  if (out.named) CheckMisfit(simulator, in, recording, state, options, knobs[out.knob_index], &out);
  out.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

LegSearch SearchLegGains(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateSet& set,
                         const CandidateOptions& recording, const LegSearchOptions& options, bool sides) {
  const std::vector<int> legs = LegGainKnobs(simulator, sides);
  if (legs.empty()) {
    LegSearch out;
    out.why = "the simulator has no per-leg gain knobs";
    return out;
  }
  std::vector<std::pair<int, double>> grid;
  for (int k : legs) {
    for (double v : GridValues(simulator.knobs()[k], options.factors)) grid.push_back({k, v});
  }
  LegSearch out = SearchOwnModels(simulator, in, set, recording, options, grid);
  out.sides_searched = sides && legs.size() > LegGainKnobs(simulator).size();
  return out;
}

void LegSearchChallenge(const AnalysisInputs& in, const std::vector<std::string>& named, const Eigen::VectorXd& corrected,
                        const LegSearchOptions& options, LegSearch* s, const std::string& best_point) {
  s->challenged = named;
  if (!s->ran || s->best < 0 || corrected.size() != in.real.size() || s->best_rows.size() != in.real.size()) return;
  // The correction with the floor the search's score gives every sample: its broad component.
  const double e = options.sag.broad_share;
  const Eigen::VectorXd broad = BroadLogDensity(MakeSagReference(in.sim, options.model), in.real, options.sag);
  Eigen::VectorXd floored(corrected.size());
  for (int i = 0; i < corrected.size(); ++i) floored(i) = LogAddExp(std::log1p(-e) + corrected(i), std::log(e) + broad(i));
  s->z_vs_named = PairedZ(s->best_rows, floored, in.real.episode);
  if (!s->named || s->z_vs_named >= options.z) return;
  s->named = false;
  s->rivals_named = s->z_vs_named > 0;
  s->bar_z = options.z;
  const std::string than = s->rivals_named ? Fmt(" better than the named knobs' correction, but by under %.3g SE", options.z)
                                           : " no better than the named knobs' correction";
  const std::string point = best_point.empty() ? s->leg + Fmt(" at gain %.3g", s->value) : best_point;
  s->why = "its best point (" + point + ") fits the real samples" + than +
           Fmt(" (%.3g against %.3g nats per sample, z %.2f)", s->best_rows.mean(), floored.mean(), s->z_vs_named);
}

Correction LegSearchCorrection(const LegSearch& search) {
  Correction out;
  if (!search.named) return out;
  auto best = std::make_shared<LinearGaussianModel>(search.best_model);
  auto nominal = std::make_shared<LinearGaussianModel>(search.nominal_model);
  out.shift = [best, nominal](int c, const Eigen::VectorXd& z, double f) {
    return Eigen::VectorXd(best->Predict(c, z, f).mean - nominal->Predict(c, z, f).mean);
  };
  out.log_var = search.log_var;
  out.terms.push_back({search.knob + "@" + search.by, Eigen::VectorXd::Constant(1, search.value)});
  return out;
}

}  // namespace dgmm::sim2real
