// The payload part of stage 4 (refine.h): a likelihood search over the payload's mass and forward
// offset. A payload's effect on a walking robot is far from linear in its position (on an
// open-loop trot a few centimetres forward decide between a straight and a curving walk), so
// the probes' linear reading only starts the search. The payload is recorded on a 3 x 3 grid of
// added masses m0 {1/f, 1, f} and forward offsets x0 + {-h, 0, h} (sideways offset at its linear
// reading), each scored by
//   l(m, x) = max_theta log p(real | sim model + s(m, x) + D_others theta),
// the recording's own shift taken at face value (coefficient 1), the other selected effects refit.
// A quadratic in (log m, x) through the nine scores gives the maximum, recorded once more (within
// twice the grid); the best-scoring recording becomes the payload's signature.
#include <algorithm>
#include <cmath>

#include "sim2real/refine.h"
#include "sim2real/sentence_format.h"

namespace dgmm::sim2real {
namespace {

constexpr double kMassFactor = 1.6;  // grid spacing in added mass (ratio)
constexpr double kOffsetShare = 0.25;  // grid spacing in x: this share of the x probe's offset

struct PayloadPoint {
  double mass = 0, x = 0;
  int shift = -1;        // index into CandidateSet::shifts
  double score = -INFINITY;
};

// l(m, x) of the recording `shift` as the payload's signature: the real residuals less its shift,
// the other selected effects refit on them.
double FixedShiftScore(const AnalysisInputs& in, const Baseline& base, CandidateSet* set, const Refinement& r, int pay,
                       int shift, const RefineOptions& options) {
  FitProblem trial = r.problem;
  const std::vector<int> keep = set->externals[pay].shifts;
  set->externals[pay].shifts = {shift, keep[keep.size() - 3], keep[keep.size() - 2], keep[keep.size() - 1]};
  FillCandidateDesign(in, base, *set, pay, &trial);
  set->externals[pay].shifts = keep;
  for (int i = 0; i < trial.n; ++i) {
    trial.r0.row(i) -= trial.g[pay].col(0).segment(i * trial.dx, trial.dx).transpose();
    trial.raw.row(i) -= trial.d[pay].col(0).segment(i * trial.dx, trial.dx).transpose();
  }
  std::vector<int> others;
  for (int e : r.selection.selected) {
    if (e != pay) others.push_back(e);
  }
  if (others.empty()) return CorrectedLogLikelihood(trial, EffectFit{}).sum();
  return FitEffects(trial, others, {}, options.selection.fit).train_log_likelihood;
}

// The maximum of ll = a + b u + c v + d u^2 + e v^2 + g u v fitted to the points (u, v, ll), within
// |u| <= u_max, |v| <= v_max; false when the fit is not concave.
bool QuadraticMaximum(const std::vector<Eigen::Vector3d>& pts, double u_max, double v_max, double* u, double* v) {
  Eigen::MatrixXd a(pts.size(), 6);
  Eigen::VectorXd y(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    const double pu = pts[i](0), pv = pts[i](1);
    a.row(i) << 1, pu, pv, pu * pu, pv * pv, pu * pv;
    y(i) = pts[i](2);
  }
  const Eigen::VectorXd q = a.colPivHouseholderQr().solve(y);
  Eigen::Matrix2d h;
  h << 2 * q(3), q(5), q(5), 2 * q(4);
  if (!(h(0, 0) < 0 && h.determinant() > 0)) return false;
  const Eigen::Vector2d s = -h.inverse() * Eigen::Vector2d(q(1), q(2));
  *u = std::clamp(s(0), -u_max, u_max);
  *v = std::clamp(s(1), -v_max, v_max);
  return true;
}

}  // namespace

void RefinePayload(const KnobSimulator& simulator, const AnalysisInputs& in, const Baseline& base,
                   const CandidateOptions& recording, const RefineOptions& options, CandidateSet* set,
                   Refinement* r) {
  const auto found = std::find_if(set->candidates.begin(), set->candidates.end(),
                                  [](const KnobCandidate& c) { return c.key == "payload"; });
  const int pay = static_cast<int>(found - set->candidates.begin());
  const auto& sel = r->selection.selected;
  const auto at = std::find(sel.begin(), sel.end(), pay);
  if (found == set->candidates.end() || at == sel.end() || options.refine_iterations == 0 ||
      options.refine_knobs == 0) {
    return;
  }
  const Eigen::VectorXd t = r->selection.fit.theta[at - sel.begin()];
  if (t(0) <= 0.05) return;  // a payload heavier than nominal (a lighter one has no position to fit)
  const auto& knobs = simulator.knobs();
  const Knob &km = knobs[set->payload_knob[0]], &kx = knobs[set->payload_knob[1]], &ky = knobs[set->payload_knob[2]];
  const KnobCandidate& c = *found;
  // The probes' linear reading: added mass t0 (probe - nominal), offsets t1 / t0, t2 / t0 of the probes'.
  const double added = std::max(t(0) * (c.probe - c.nominal), 1e-3 * (c.probe - c.nominal));
  const double x0 = std::clamp(kx.nominal + t(1) / t(0) * (kx.probes[0] - kx.nominal), kx.lo, kx.hi);
  const double py = std::clamp(ky.nominal + t(2) / t(0) * (ky.probes[0] - ky.nominal), ky.lo, ky.hi);
  const double h = kOffsetShare * std::abs(kx.probes[0] - kx.nominal);
  const double lf = std::log(kMassFactor);
  auto point = [&](double u, double v) {
    return PayloadPoint{std::clamp(c.nominal + added * std::exp(u * lf), km.lo, km.hi),
                        std::clamp(x0 + v * h, kx.lo, kx.hi)};
  };
  auto record = [&](std::vector<PayloadPoint>* pts) {
    std::vector<std::vector<KnobValue>> requests;
    for (const auto& p : *pts) {
      requests.push_back({{set->payload_knob[0], p.mass}, {set->payload_knob[1], p.x}, {set->payload_knob[2], py}});
    }
    auto shifts = RecordShifts(simulator, in, *set, requests, recording, &r->recorded, &r->from_cache);
    for (size_t i = 0; i < pts->size(); ++i) {
      set->shifts.push_back(std::move(shifts[i]));
      (*pts)[i].shift = static_cast<int>(set->shifts.size()) - 1;
      (*pts)[i].score = FixedShiftScore(in, base, set, *r, pay, (*pts)[i].shift, options);
    }
  };
  std::vector<PayloadPoint> grid;
  std::vector<Eigen::Vector3d> scored;
  for (int iu = -1; iu <= 1; ++iu) {
    for (int iv = -1; iv <= 1; ++iv) grid.push_back(point(iu, iv));
  }
  record(&grid);
  for (int i = 0; i < 9; ++i) scored.emplace_back(i / 3 - 1, i % 3 - 1, grid[i].score);
  double u = 0, v = 0;
  const bool concave = QuadraticMaximum(scored, 2, 2, &u, &v);
  if (concave) {
    std::vector<PayloadPoint> extra = {point(u, v)};
    record(&extra);
    grid.push_back(extra[0]);
  }
  const auto best = std::max_element(grid.begin(), grid.end(),
                                     [](const PayloadPoint& a, const PayloadPoint& b) { return a.score < b.score; });
  const std::string label = c.knob + Fmt(" at (x %.3g, ", best->x) + Fmt("y %.3g) m", py);
  for (const auto& p : grid) {
    r->trace.push_back({c.knob + Fmt(" at (x %.3g, ", p.x) + Fmt("y %.3g) m", py), p.mass, NAN, p.score / in.real.size()});
  }
  const std::vector<int> probes = set->externals[pay].shifts;
  set->externals[pay].shifts = {best->shift, probes[probes.size() - 3], probes[probes.size() - 2],
                                probes[probes.size() - 1]};
  FillCandidateDesign(in, base, *set, pay, &r->problem);
  SelectionOptions so = options.selection;
  so.backward = true;
  r->selection = ForwardSelect(r->problem, r->rows, base.fold, so);
  KnobRefinement kr{pay, label, best->mass, NAN, false, true};
  const auto pos = std::find(r->selection.selected.begin(), r->selection.selected.end(), pay);
  if (pos != r->selection.selected.end()) kr.coefficient = r->selection.fit.theta[pos - r->selection.selected.begin()](0);
  // Converged: the search brackets the maximum (the grid's centre scored best, or the quadratic's
  // maximum lies inside the searched box).
  kr.converged = best == grid.begin() + 4 || (concave && std::abs(u) < 2 && std::abs(v) < 2);
  if (!kr.converged) kr.why = "the likelihood search's best payload lies at the edge of the masses and offsets searched";
  r->refined.push_back(kr);
  r->payload_mass = best->mass, r->payload_x = best->x, r->payload_y = py;
}

}  // namespace dgmm::sim2real
