#include "sim2real/ground_search.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <random>

#include "sim2real/candidates.h"
#include "sim2real/sentence_format.h"
#include "sim2real/simulation_cache.h"
#include "sim2real/verdict_stage.h"
#include "util/error.h"
#include "util/median.h"

namespace dgmm::sim2real {
namespace {

using Clock = std::chrono::steady_clock;
constexpr int kMinPlacements = 10;

// t of each placement's first execution (every row its own without sequence data), by episode id.
std::map<int, double> StandingTilts(const SampleSet& s, int pitch_col, int roll_col, const SlopeGeometry* slope) {
  std::map<int, Eigen::Vector2d> z;
  for (int i = 0; i < s.size(); ++i) {
    if (s.has_sequence() && s.step(i) != 0) continue;
    z.emplace(s.has_sequence() ? s.episode(i) : i, Eigen::Vector2d(s.z(i, pitch_col), s.z(i, roll_col)));
  }
  std::map<int, double> t;
  if (slope) {
    for (const auto& [e, v] : z) t[e] = RadialResidual(*slope, v);
    return t;
  }
  std::vector<double> pitch, roll;
  for (const auto& [e, v] : z) pitch.push_back(v(0)), roll.push_back(v(1));
  const Eigen::Vector2d median(Median(pitch), Median(roll));
  for (const auto& [e, v] : z) t[e] = (v - median).norm();
  return t;
}

std::vector<double> Values(const std::map<int, double>& t) {
  std::vector<double> v;
  for (const auto& [e, x] : t) v.push_back(x);
  return v;
}

// s over the units `pick` of `t`: about its median on a slope (`centred`), else t's mean (a distance already).
double Spread(const std::vector<double>& t, const std::vector<int>& pick, bool centred) {
  std::vector<double> v;
  for (int u : pick) v.push_back(t[u]);
  const double m = centred ? Median(v) : 0;
  double sum = 0;
  for (double x : v) sum += std::abs(x - m);
  return v.empty() ? NAN : sum / v.size();
}

std::vector<int> All(int n) {
  std::vector<int> pick(n);
  for (int u = 0; u < n; ++u) pick[u] = u;
  return pick;
}

// The SD of draw(pick) over `resamples` draws of n units with replacement.
template <typename Draw>
double ResampledSd(int n, int resamples, std::uint64_t seed, const Draw& draw) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> unit(0, n - 1);
  double sum = 0, sq = 0;
  int m = 0;
  for (int r = 0; r < resamples; ++r) {
    std::vector<int> pick(n);
    for (int& u : pick) u = unit(rng);
    const double d = draw(pick);
    if (std::isfinite(d)) sum += d, sq += d * d, ++m;
  }
  return m < 2 ? NAN : std::sqrt(std::max(0.0, (sq - sum * sum / m) / (m - 1)));
}

// s(a) / s(b) of two recordings at the same places (the episodes both have), with its SE from
// resampling those places jointly.
std::pair<double, double> PairedRatio(const std::map<int, double>& a, const std::map<int, double>& b, bool centred,
                                      int resamples, std::uint64_t seed) {
  std::vector<double> ta, tb;
  for (const auto& [e, x] : a) {
    if (const auto it = b.find(e); it != b.end()) ta.push_back(x), tb.push_back(it->second);
  }
  const int n = static_cast<int>(ta.size());
  if (n < kMinPlacements) return {NAN, NAN};
  const auto ratio = [&](const std::vector<int>& pick) {
    return Spread(ta, pick, centred) / Spread(tb, pick, centred);
  };
  return {ratio(All(n)), ResampledSd(n, resamples, seed, ratio)};
}

// Where the curve's ratios meet q, walking out from the nominal on q's side (linear between recordings).
double Crossing(const GroundCurve& c, double nominal, double q) {
  std::vector<int> order;
  for (size_t j = 0; j < c.values.size(); ++j) {
    if (q > 1 ? c.values[j] >= nominal : c.values[j] <= nominal) order.push_back(static_cast<int>(j));
  }
  if (q < 1) std::reverse(order.begin(), order.end());
  for (size_t j = 1; j < order.size(); ++j) {
    const double va = c.values[order[j - 1]], vb = c.values[order[j]];
    const double ra = c.ratios[order[j - 1]], rb = c.ratios[order[j]];
    if ((ra - q) * (rb - q) <= 0 && ra != rb) return va + (q - ra) * (vb - va) / (rb - ra);
  }
  return NAN;
}

double Quantile(std::vector<double> v, double q) {
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

std::vector<double> Centred(std::vector<double> v) {
  const double m = Median(v);
  for (double& x : v) x -= m;
  return v;
}

// Which meeting curves' recordings have the real standing tilts' shape as well as the best's.
void CompareShapes(const std::vector<double>& real, const GroundSearchOptions& options,
                   std::vector<GroundCurve>* curves) {
  std::vector<Eigen::VectorXd> ll(curves->size());
  int best = -1;
  for (size_t j = 0; j < curves->size(); ++j) {
    GroundCurve& c = (*curves)[j];
    if (!c.meets) continue;
    ll[j] = TiltLogDensity(real, c.matched_tilts);
    c.tilt_score = ll[j].mean();
    if (best < 0 || c.tilt_score > (*curves)[best].tilt_score) best = static_cast<int>(j);
  }
  for (size_t j = 0; j < curves->size(); ++j) {
    GroundCurve& c = (*curves)[j];
    if (!c.meets) continue;
    const Eigen::VectorXd d = ll[best] - ll[j];
    const double sd = d.size() > 1 ? std::sqrt((d.array() - d.mean()).square().sum() / (d.size() - 1)) : 0;
    c.tilt_z = static_cast<int>(j) == best ? 0.0 : sd > 0 ? d.mean() / (sd / std::sqrt(d.size())) : 0.0;
    c.tilt_as_well = c.tilt_z < options.shape_z;
  }
}

// Why the comparison cannot run (empty: it can).
std::string WhyNot(const KnobSimulator& simulator, const AnalysisInputs& in) {
  if (GroundKnobs(simulator).empty()) return "the simulator has no ground knobs";
  if (simulator.plane_ground()) return "the ground is a plane";
  if (in.pitch_col < 0 || in.roll_col < 0) return "the sets' z has no pitch and roll";
  return "";
}

// Compare by z's radial part on the slope's circle? Where it is clear (SlopeGeometry::valid), or on
// a simulator's sloped ground wherever a circle was fitted: on terraces 4 cm high the octopod's
// standing tilt spreads 0.06 rad (mean absolute deviation) about a circle of radius 0.2, which the
// fit's test (a radius of 4 robust SDs) refuses, and the distance from the median z would measure
// the heading's circle instead.
bool OnSlope(const KnobSimulator& simulator, const SlopeGeometry& g) {
  return g.valid || (simulator.sloped_ground() && g.centre.allFinite() && g.radius.allFinite() && g.radius(0) > 0);
}

// The curve of every ground knob: its recordings at the factors on q's side, their ratios.
// `nominal` receives the nominal re-recording's tilts.
std::vector<GroundCurve> RecordCurves(const KnobSimulator& simulator, const Recording& rec, const RecordingOptions& ro,
                                      const SlopeGeometry* slope, const GroundSearchOptions& options, int p, int r,
                                      double q, GroundSearch* out, std::map<int, double>* nominal) {
  const auto& knobs = simulator.knobs();
  std::vector<std::vector<KnobValue>> requests = {{}};
  std::vector<GroundCurve> curves;
  for (int k : GroundKnobs(simulator)) {
    GroundCurve c;
    c.knob = knobs[k].name, c.knob_index = k;
    for (double f : q > 1 ? options.up : options.down) {
      const double v = WithinKnob(knobs[k], f * knobs[k].nominal);
      if (v == knobs[k].nominal || std::find(c.values.begin(), c.values.end(), v) != c.values.end()) continue;
      c.values.push_back(v);
      requests.push_back({{k, v}});
    }
    curves.push_back(c);
  }
  const RecordingBatch batch = RecordBatch(simulator, rec, requests, ro);
  out->recorded += batch.recorded, out->from_cache += batch.from_cache;
  *nominal = StandingTilts(batch.sets[0], p, r, slope);
  size_t j = 1;
  for (GroundCurve& c : curves) {
    std::vector<std::pair<double, double>> points = {{knobs[c.knob_index].nominal, 1.0}};
    for (double v : c.values) {
      const auto tilts = StandingTilts(batch.sets[j++], p, r, slope);
      points.push_back({v, PairedRatio(tilts, *nominal, slope != nullptr, 0, 0).first});  // no resamples: no SE
    }
    std::sort(points.begin(), points.end());
    c.values.clear(), c.ratios.clear();
    for (const auto& [v, ratio] : points) c.values.push_back(v), c.ratios.push_back(ratio);
    c.matched = Crossing(c, knobs[c.knob_index].nominal, q);
  }
  return curves;
}

// Records each curve's matched value and checks that its ratio meets q (against `nominal`, the
// nominal re-recording's tilts).
void CheckMatches(const KnobSimulator& simulator, const Recording& rec, const RecordingOptions& ro,
                  const SlopeGeometry* slope, const GroundSearchOptions& options, int p, int r,
                  const std::map<int, double>& nominal, GroundSearch* out) {
  std::vector<std::vector<KnobValue>> requests;
  for (const GroundCurve& c : out->curves) {
    if (std::isfinite(c.matched)) requests.push_back({{c.knob_index, c.matched}});
  }
  if (requests.empty()) return;
  const RecordingBatch batch = RecordBatch(simulator, rec, requests, ro);
  out->recorded += batch.recorded, out->from_cache += batch.from_cache;
  size_t j = 0;
  for (GroundCurve& c : out->curves) {
    if (!std::isfinite(c.matched)) continue;
    const auto tilts = StandingTilts(batch.sets[j++], p, r, slope);
    const auto [ratio, se] = PairedRatio(tilts, nominal, slope != nullptr, options.resamples, options.seed + 2);
    c.matched_ratio = ratio, c.matched_se = se;
    c.matched_tilts = Values(tilts);
    c.match_z = std::abs(ratio - out->ratio) / std::hypot(se, out->ratio_se);
    c.meets = c.match_z <= options.match_z;
  }
}

// "terrain.stones.height_scale up to 3 spreads it x1.05 at most; terrain.rough.rms_scale at 1.8 x1.21 (z 2.5)".
std::string WhyNoneMeets(const std::vector<GroundCurve>& curves, double q) {
  std::vector<std::string> words;
  for (const GroundCurve& c : curves) {
    if (!std::isfinite(c.matched)) {
      const auto [lo, hi] = std::minmax_element(c.ratios.begin(), c.ratios.end());
      words.push_back(c.knob + Fmt(" from %.3g to %.3g", c.values.front(), c.values.back()) +
                      Fmt(" spreads it x%.2f to x%.2f", *lo, *hi));
    } else {
      words.push_back(c.knob + Fmt(" at %.3g spreads it x%.2f", c.matched, c.matched_ratio) +
                      Fmt(" (%.1f SE from the real x%.2f)", c.match_z, q));
    }
  }
  return "no ground knob gives that spread within its range (" + JoinWords(words) + ")";
}

// ", its standing tilts shaped like the real ones, which terrain.stones.height_scale at 2.55's are
// not (z 4.1)" for the meeting knobs the shape left out; "" when none.
std::string ShapeWords(const GroundSearch& g, int named) {
  std::vector<std::string> out;
  for (const GroundCurve& c : g.curves) {
    if (c.meets && !c.tilt_as_well && c.knob_index != named) {
      out.push_back(c.knob + Fmt(" at %.3g (z %.1f)", c.matched, c.tilt_z));
    }
  }
  return out.empty() ? "" : ", its standing tilts shaped like the real ones, unlike those of " + JoinWords(out);
}

}  // namespace

bool GroundSearchOptions::IsValid(std::string* error) const {
  const auto positive = [](const std::vector<double>& f) {
    return !f.empty() && std::all_of(f.begin(), f.end(), [](double v) { return v > 0 && std::isfinite(v); });
  };
  if (!(z > 0) || !(match_z > 0) || !(shape_z > 0) || resamples < 2 || !positive(up) || !positive(down)) {
    *error = "ground search: z, match_z, shape_z > 0, resamples >= 2 and positive factors expected";
    return false;
  }
  return search.IsValid(error);
}

StandingSpread MeasureStandingSpread(const SampleSet& set, int pitch_col, int roll_col, const SlopeGeometry* slope,
                                     int resamples, std::uint64_t seed) {
  StandingSpread out;
  const std::vector<double> t = Values(StandingTilts(set, pitch_col, roll_col, slope));
  out.placements = static_cast<int>(t.size());
  if (out.placements < 2) return out;
  const bool centred = slope != nullptr;
  out.value = Spread(t, All(out.placements), centred);
  out.se = ResampledSd(out.placements, resamples, seed,
                       [&](const std::vector<int>& pick) { return Spread(t, pick, centred); });
  return out;
}

Eigen::VectorXd TiltLogDensity(const std::vector<double>& real, const std::vector<double>& reference) {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(real.size());
  if (reference.size() < 2 || real.empty()) return out;
  const std::vector<double> x = Centred(real), ref = Centred(reference);
  const Eigen::Map<const Eigen::VectorXd> r(ref.data(), ref.size());
  const double sd = std::sqrt((r.array() - r.mean()).square().sum() / (r.size() - 1));
  const double iqr = Quantile(ref, 0.75) - Quantile(ref, 0.25);
  const double h = 0.9 * std::min(sd, iqr > 0 ? iqr / 1.34 : sd) * std::pow(static_cast<double>(ref.size()), -0.2);
  if (!(h > 0)) return out;  // every reference tilt alike: no shape to compare
  for (size_t i = 0; i < x.size(); ++i) {
    // log mean_j N(x_i; ref_j, h^2), by log-sum-exp
    const Eigen::ArrayXd e = -0.5 * ((x[i] - r.array()) / h).square();
    const double m = e.maxCoeff();
    out(i) = m + std::log((e - m).exp().mean()) - std::log(h * std::sqrt(2 * M_PI));
  }
  return out;
}

std::vector<int> GroundKnobs(const KnobSimulator& simulator) {
  std::vector<int> out;
  const auto& knobs = simulator.knobs();
  for (size_t k = 0; k < knobs.size(); ++k) {
    if (knobs[k].family == "ground" && knobs[k].role == Knob::Role::kShift) out.push_back(static_cast<int>(k));
  }
  return out;
}

GroundSearch SearchGround(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateSet& set,
                          const CandidateOptions& recording, const GroundSearchOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "ground search options", error);
  const auto start = Clock::now();
  GroundSearch out;
  out.why = WhyNot(simulator, in);
  if (!out.why.empty()) return out;
  const int p = in.pitch_col, r = in.roll_col;
  const SlopeGeometry geometry = FitSlopeGeometry(in.sim_set, p, r);
  out.on_slope = OnSlope(simulator, geometry);
  const SlopeGeometry* slope = out.on_slope ? &geometry : nullptr;
  out.real = MeasureStandingSpread(in.real_set, p, r, slope, options.resamples, options.seed);
  out.sim = MeasureStandingSpread(in.sim_set, p, r, slope, options.resamples, options.seed + 1);
  if (std::min(out.real.placements, out.sim.placements) < kMinPlacements || !(out.sim.value > 0) ||
      !(out.real.se > 0) || !(out.sim.se > 0)) {
    out.why = Fmt("the sets have under %.0f placements with a measurable standing tilt", kMinPlacements);
    return out;
  }
  out.ran = true;
  out.ratio = out.real.value / out.sim.value;
  out.ratio_se = out.ratio * std::hypot(out.real.se / out.real.value, out.sim.se / out.sim.value);
  out.z_moved = (out.ratio - 1) / out.ratio_se;
  out.moved = std::abs(out.z_moved) >= options.z;
  if (!out.moved) {
    out.why = Fmt("the standing tilt spreads alike (ratio %.2f, z %.1f)", out.ratio, out.z_moved);
    return out;
  }
  // The tilts are recorded at the sim set's own places, its first execution alone (all a standing tilt needs).
  Recording rec = in.recording;
  rec.placements = out.sim.placements;
  rec.executions_per_placement = 1;
  std::map<int, double> nominal;
  out.curves = RecordCurves(simulator, rec, recording.recording, slope, options, p, r, out.ratio, &out, &nominal);
  CheckMatches(simulator, rec, recording.recording, slope, options, p, r, nominal, &out);
  CompareShapes(Values(StandingTilts(in.real_set, p, r, slope)), options, &out.curves);
  std::vector<std::pair<int, double>> grid;
  for (const GroundCurve& c : out.curves) {
    if (c.meets && c.tilt_as_well) grid.push_back({c.knob_index, c.matched});
  }
  if (grid.empty()) {
    out.why = WhyNoneMeets(out.curves, out.ratio);
  } else {
    out.search = SearchOwnModels(simulator, in, set, recording, options.search, grid);
    out.search.by = "ground_search";
    out.recorded += out.search.recorded, out.from_cache += out.search.from_cache;
    out.why = out.search.named ? "" : out.search.why;
  }
  out.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

void AddGroundSearch(const KnobSimulator& simulator, const GroundSearch& g, Verdict* v) {
  if (!g.ran || !g.moved) return;
  const std::string tilt =
      "standing where it was placed, the real robot tilts " + std::string(g.ratio > 1 ? "more" : "less") +
      Fmt(" variously than the simulated one (spread %.1f against %.1f mrad,", 1e3 * g.real.value, 1e3 * g.sim.value) +
      Fmt(" ratio %.2f, z %.1f)", g.ratio, g.z_moved);
  if (!g.search.named) {
    const std::string doubt = tilt + ": " + g.why;
    AddVerdictDoubt(doubt, v);
    if (!v->named.empty()) v->named.front().doubts.push_back(doubt);
    v->unexplained_present = true;
    AddUnique(&v->structured_in, "ground");
    v->sentence += " The ground: " + doubt + ".";
    return;
  }
  const LegSearch& s = g.search;
  const Knob& k = simulator.knobs()[s.knob_index];
  const std::string before = v->named.empty() ? "" : v->named.front().knob;
  VerdictNamed n = SearchNamed(s, k.family, k.unit);
  n.doubts.push_back("found by the standing tilt's spread, its recording scored by a model of its own: no bootstrap, "
                     "its range is the values that fit as well" +
                     (before.empty() || before == k.name ? "" : "; the mean shifts had named " + before));
  AddRemainingMismatchDoubt(s, "it", &n);
  v->ties.clear();
  ReplaceNamed(s, n, v);
  AddUnique(&v->structured_in, "ground");
  const GroundCurve* c = nullptr;
  for (const GroundCurve& curve : g.curves) c = curve.knob_index == s.knob_index ? &curve : c;
  v->sentence += " The ground: " + tilt + "; " + k.name +
                 Fmt(" at %.3g spreads it x%.2f", s.value, c ? c->matched_ratio : NAN) + ShapeWords(g, s.knob_index) +
                 Fmt(" and fits the real samples %.3g nats per sample better than the nominal (z %.1f).",
                     s.points[s.best].score - s.nominal_score, s.z_vs_nominal);
}

}  // namespace dgmm::sim2real
