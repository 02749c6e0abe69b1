// The knobs' part of stage 4 (refine.h): a likelihood search over a selected one-parameter knob's
// value. A knob's effect can be far from linear in its value (friction only slips below the
// coefficient the gait needs; a weak servo only sags past a load), so its probe's linear
// reading only starts the search. The knob is recorded at deviations from the nominal
//   v(u) = nominal + d0 f^u,  d0 = the probe's linear reading's deviation, f = 1.6,
// first at u = -1, 0, 1 (one parallel batch; the probe's own recording scored with them), each
// scored by the real log-likelihood with its shift at face value (refine_search.h). Then at most
// refine_iterations single recordings: while the best point has no point on one side, a step
// beyond it (not past the knob's range); once bracketed, Brent-like steps inside the bracket
// (parabola vertex, else bisection) until it is narrower than kResolution. The best recording
// becomes the signature of every candidate of that knob (its probes at other values included) and
// the selection reruns.
#include <algorithm>
#include <cmath>

#include "sim2real/refine.h"
#include "sim2real/refine_search.h"
#include "sim2real/sentence_format.h"

namespace dgmm::sim2real {
namespace {

constexpr double kStepFactor = 1.6;  // grid spacing: the deviation from nominal, in ratios
constexpr double kResolution = 0.25;  // a bracket this narrow in u (a 12% change of deviation) is done
constexpr double kFullShare = 0.9;  // a point pairing this share of the fullest recording's samples is judged

struct KnobPoint {
  double value = 0, u = 0;
  int shift = -1;  // index into CandidateSet::shifts
  double score = -INFINITY;
  Eigen::VectorXd rows;  // the score per real sample
};

bool ByScore(const KnobPoint& a, const KnobPoint& b) { return a.score < b.score; }

// Deviations from the nominal d0 f^u, clamped to the knob's range.
struct KnobFrame {
  const KnobCandidate* c = nullptr;
  double d0 = 0;
  double ValueAt(double u) const { return std::clamp(c->nominal + d0 * std::pow(kStepFactor, u), c->lo, c->hi); }
  // NaN for a value not on the reading's side of the nominal.
  double UOf(double v) const {
    const double ratio = (v - c->nominal) / d0;
    return ratio > 1e-9 ? std::log(ratio) / std::log(kStepFactor) : NAN;
  }
  bool Known(const std::vector<KnobPoint>& pts, double v) const {
    const double tol = 1e-6 * (c->hi - c->lo);
    return std::any_of(pts.begin(), pts.end(), [&](const KnobPoint& p) { return std::abs(p.value - v) <= tol; });
  }
};

std::vector<int> SameKnob(const CandidateSet& set, int k) {
  std::vector<int> out;
  for (size_t j = 0; j < set.candidates.size(); ++j) {
    if (set.candidates[j].knob_index == set.candidates[k].knob_index) out.push_back(static_cast<int>(j));
  }
  return out;
}

struct KnobSearch : SearchContext {
  int k;
  KnobFrame f;
  std::vector<int> same;  // candidates of the same knob (k among them): not refit while scoring

  // Scores the recording `shift` of the knob at `value`, traces it and adds it to `pts`.
  void Add(double value, int shift, std::vector<KnobPoint>* pts) const {
    KnobPoint p{value, f.UOf(value), shift};
    p.score = FaceValueScore(in, base, set, *r, k, {shift}, same, options, &p.rows);
    r->trace.push_back({set->candidates[k].knob, p.value, NAN, p.score / in.real.size()});
    pts->push_back(p);
  }
  // Values at which the robot fell (too few paired samples): not points, and the search's limit.
  mutable std::vector<double> fell = {};
  bool Fell(double v) const {
    const double tol = 1e-6 * (f.c->hi - f.c->lo);
    return std::any_of(fell.begin(), fell.end(), [&](double x) { return std::abs(x - v) <= tol; });
  }
  // Records the values not yet known (one batch) and scores them into `pts`; a value at which the
  // robot fell is listed in `fell` and the candidate set's unwalkable probes instead.
  void RecordAndScore(const std::vector<double>& values, std::vector<KnobPoint>* pts) const {
    std::vector<double> fresh;
    for (double v : values) {
      if (std::isfinite(f.UOf(v)) && !f.Known(*pts, v) && !Fell(v)) fresh.push_back(v);
    }
    std::sort(fresh.begin(), fresh.end());
    fresh.erase(std::unique(fresh.begin(), fresh.end()), fresh.end());
    std::vector<std::vector<KnobValue>> requests;
    for (double v : fresh) requests.push_back({KnobValue{set->candidates[k].knob_index, v}});
    auto shifts = RecordWalkableShifts(simulator, in, *set, requests, recording, &r->recorded, &r->from_cache);
    for (size_t i = 0; i < fresh.size(); ++i) {
      if (!shifts[i]) {
        fell.push_back(fresh[i]);
        AddUnique(&set->unwalkable_probes, set->candidates[k].knob + Fmt("@%.4g", fresh[i]));
        continue;
      }
      set->shifts.push_back(std::move(*shifts[i]));
      Add(fresh[i], static_cast<int>(set->shifts.size()) - 1, pts);
    }
  }
};

// The best point's nearest neighbours below and above it in u (nullptr: none).
void Neighbours(const std::vector<KnobPoint>& pts, const KnobPoint& best, const KnobPoint** below,
                const KnobPoint** above) {
  *below = *above = nullptr;
  for (const auto& p : pts) {
    if (p.u < best.u && (!*below || p.u > (*below)->u)) *below = &p;
    if (p.u > best.u && (!*above || p.u < (*above)->u)) *above = &p;
  }
}

// The next u inside the bracket a < b < c (b the best), as in Brent's method: the vertex of the
// parabola through the three scores, or the middle of the wider side when the vertex is not
// concave, outside the bracket or within a tenth of the bracket of a point already scored; NaN
// once the bracket is narrower than kResolution.
double NextInside(const KnobPoint& a, const KnobPoint& b, const KnobPoint& c) {
  const double width = c.u - a.u;
  if (width < kResolution) return NAN;
  const double d1 = (b.score - a.score) / (b.u - a.u), d2 = (c.score - b.score) / (c.u - b.u);
  const double curvature = (d2 - d1) / width;  // p(u) = a + d1 (u - a.u) + curvature (u - a.u)(u - b.u)
  const double u = curvature < 0 ? 0.5 * (a.u + b.u) - d1 / (2 * curvature) : NAN;
  const double gap = std::min({std::abs(u - a.u), std::abs(u - b.u), std::abs(u - c.u)});
  if (std::isfinite(u) && u > a.u && u < c.u && gap >= 0.1 * width) return u;
  return b.u - a.u > c.u - b.u ? 0.5 * (a.u + b.u) : 0.5 * (b.u + c.u);
}

// The range of the searched values that fit as well as the best (refine_search.h).
SearchSpan AsWell(const KnobSearch& s, const std::vector<KnobPoint>& pts, const KnobPoint& best) {
  std::vector<Eigen::VectorXd> rows;
  std::vector<double> values;
  for (const auto& p : pts) rows.push_back(p.rows), values.push_back(p.value);
  return FitAsWellSpan(rows, static_cast<int>(&best - pts.data()), values, {}, s.in.real.episode, s.options.as_well_z);
}

// Empty, or why the search's scores do not rise to one peak (DeepestDip), in words. Only points
// recorded as fully as the fullest are judged (a probe kept from the first look pairs 2 executions
// of 5: its score is noisier, not chaotic).
std::string Rugged(const KnobSearch& s, const std::vector<KnobPoint>& pts) {
  int most = 0;
  for (const auto& p : pts) most = std::max(most, s.set->shifts[p.shift].pairs());
  std::vector<Eigen::VectorXd> rows;
  std::vector<double> values;
  for (const auto& p : pts) {
    if (s.set->shifts[p.shift].pairs() >= kFullShare * most) rows.push_back(p.rows), values.push_back(p.value);
  }
  const ScoreDip dip = DeepestDip(rows, values, s.in.real.episode, s.options.as_well_z);
  if (!dip.Found()) return "";
  return Fmt("its likelihood search does not rise to one peak: the recording at %.4g fits worse than those at ",
             values[dip.at]) +
         Fmt("%.4g and %.4g on either side of it ", values[dip.left], values[dip.right]) +
         DipDeficits(dip, static_cast<int>(s.in.real.size())) +
         ", so recordings at nearby values differ by more than their values explain (a chaotic walk, or two values "
         "that fit), and the value may lie outside its interval";
}

// Every candidate of the knob takes the best recording as its signature; the selection reruns.
void Adopt(const KnobSearch& s, const std::vector<KnobPoint>& pts, const KnobPoint& best, bool bracketed) {
  for (int j : s.same) {
    s.set->externals[j].shifts = {best.shift};
    s.r->signature_at[j] = best.value;
    s.r->searched[j] = true;
    FillCandidateDesign(s.in, s.base, *s.set, j, &s.r->problem);
  }
  s.r->selection = ForwardSelect(s.r->problem, s.r->rows, s.base.fold, s.r->selection_options);
  KnobRefinement kr{s.k, s.set->candidates[s.k].knob, best.value, NAN, bracketed, true};
  const auto& sel = s.r->selection.selected;
  for (size_t pos = 0; pos < sel.size(); ++pos) {
    if (std::find(s.same.begin(), s.same.end(), sel[pos]) != s.same.end()) {
      kr.candidate = sel[pos], kr.coefficient = s.r->selection.fit.theta[pos](0);
    }
  }
  if (!bracketed) kr.why = "the likelihood search's best value lies at the edge of the values searched";
  kr.as_well = AsWell(s, pts, best);
  kr.rugged = Rugged(s, pts);
  s.r->refined.push_back(kr);
}

}  // namespace

void SearchKnob(const KnobSimulator& simulator, const AnalysisInputs& in, const Baseline& base,
                const CandidateOptions& recording, const RefineOptions& options, CandidateSet* set, Refinement* r,
                int k, double a0) {
  const KnobCandidate& c = set->candidates[k];
  const double probe_dev = c.probe - c.nominal;
  double d0 = a0 * probe_dev;
  if (std::abs(d0) < 0.1 * std::abs(probe_dev)) d0 = (a0 < 0 ? -0.1 : 0.1) * probe_dev;
  KnobSearch s{{simulator, in, base, recording, options, set, r}, k, KnobFrame{&c, d0}, SameKnob(*set, k)};
  std::vector<KnobPoint> pts;
  for (int j : s.same) {  // the probes' own recordings, on the reading's side of the nominal
    const double v = set->candidates[j].probe;
    if (std::isfinite(s.f.UOf(v)) && !s.f.Known(pts, v)) s.Add(v, set->externals[j].shifts[0], &pts);
  }
  const size_t probes = pts.size();
  s.RecordAndScore({s.f.ValueAt(-1), s.f.ValueAt(0), s.f.ValueAt(1)}, &pts);
  if (pts.size() == probes) return;  // nothing could be recorded on the reading's side
  const KnobPoint *below = nullptr, *above = nullptr;
  for (int it = 0; it < options.refine_iterations; ++it) {
    const KnobPoint best = *std::max_element(pts.begin(), pts.end(), ByScore);
    Neighbours(pts, best, &below, &above);
    const double u = below && above ? NextInside(*below, best, *above) : best.u + (above ? -1 : 1);
    if (!std::isfinite(u)) break;  // bracketed within kResolution
    const double next = s.f.ValueAt(u);
    if (s.f.Known(pts, next) || s.Fell(next) || !std::isfinite(s.f.UOf(next))) break;  // at a limit
    s.RecordAndScore({next}, &pts);
  }
  const KnobPoint& best = *std::max_element(pts.begin(), pts.end(), ByScore);
  Neighbours(pts, best, &below, &above);
  const bool bracketed = below && above;
  Adopt(s, pts, best, bracketed);
}

}  // namespace dgmm::sim2real
