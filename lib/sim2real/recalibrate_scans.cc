#ifdef DGMM_SIM2REAL_HAVE_SIM
#include "sim2real/recalibrate_scans.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dgmm::sim2real {
namespace {

using json = nlohmann::json;
constexpr double kNegInf = -std::numeric_limits<double>::infinity();

// A payload added as a further point mass on the torso joins the config's payload at their
// common centre of mass.
sim::SimConfig WithPayload(const sim::SimConfig& base, double mass_kg, const Eigen::Vector3d& pos) {
  sim::SimConfig c = base;
  const double m = base.payload.mass_kg + mass_kg;
  c.payload.mass_kg = m;
  if (m > 0) {
    c.payload.position_body_m =
        (base.payload.mass_kg * base.payload.position_body_m + mass_kg * pos) / m;
  }
  return c;
}

double RobotMassKg(const sim::SimConfig& c) {
  return c.masses.torso_kg + sim::kNumLegs * (c.masses.coxa_kg + c.masses.femur_kg + c.masses.tibia_kg);
}

// Scores of configs, -inf for a failed simulation (its error in *errors).
std::vector<double> Scores(ResimScorer& scorer, const std::vector<sim::SimConfig>& configs,
                           std::vector<std::string>* errors = nullptr) {
  std::vector<double> out;
  for (const ResimScore& s : scorer.Evaluate(configs)) {
    out.push_back(s.ok ? s.mean_log_likelihood : kNegInf);
    if (errors) errors->push_back(s.error);
  }
  return out;
}

// One more point for a 1-D scan of (xs ascending, lls): the vertex of the parabola through the
// three points around the best one (allowed half a grid step beyond them), else half a step
// beyond the best end point; clamped to [lo, hi]; NaN when it would repeat a point (within tol)
// or nothing is finite.
double RefinePoint(const std::vector<double>& xs, const std::vector<double>& lls, double lo,
                   double hi, double tol) {
  const int n = static_cast<int>(xs.size());
  if (n < 3) return NAN;
  const int b = static_cast<int>(std::max_element(lls.begin(), lls.end()) - lls.begin());
  if (!std::isfinite(lls[b])) return NAN;
  const int i0 = std::clamp(b - 1, 0, n - 3);
  const double x0 = xs[i0], x1 = xs[i0 + 1], x2 = xs[i0 + 2];
  const double y0 = lls[i0], y1 = lls[i0 + 1], y2 = lls[i0 + 2];
  double x = NAN;
  if (std::isfinite(y0) && std::isfinite(y1) && std::isfinite(y2)) {
    const double d = (x0 - x1) * (x0 - x2) * (x1 - x2);
    const double a = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / d;
    const double bb = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / d;
    if (a < 0) x = std::clamp(-bb / (2 * a), x0 - (x1 - x0) / 2, x2 + (x2 - x1) / 2);
  }
  if (!std::isfinite(x) && (b == 0 || b == n - 1)) {
    const int nb = b == 0 ? 1 : n - 2;
    x = xs[b] + (xs[b] - xs[nb]) / 2;
  }
  if (!std::isfinite(x)) return NAN;
  x = std::clamp(x, lo, hi);
  for (double v : xs) {
    if (std::abs(v - x) < tol) return NAN;
  }
  return x;
}

json Vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

// Index of the best score; `nominal_ll` wins ties (no change without evidence).
int Best(const std::vector<double>& lls, double nominal_ll) {
  int best = -1;
  double best_ll = nominal_ll;
  for (int i = 0; i < static_cast<int>(lls.size()); ++i) {
    if (lls[i] > best_ll) {
      best_ll = lls[i];
      best = i;
    }
  }
  return best;
}

}  // namespace

json ScanFriction(ResimScorer& scorer, sim::SimConfig* recalibrated) {
  const sim::SimConfig& base = scorer.nominal();
  const double nominal = base.friction.sliding;
  auto config = [&](double factor) {
    sim::SimConfig c = base;
    c.friction.sliding = nominal * factor;
    return c;
  };
  std::vector<double> factors = {0.55, 0.7, 0.85, 1.0};
  std::vector<sim::SimConfig> configs;
  for (double f : factors) configs.push_back(config(f));
  std::vector<double> lls = Scores(scorer, configs);
  const double extra = RefinePoint(factors, lls, 0.25, 1.5, 0.02);
  if (std::isfinite(extra)) {
    const double ll = Scores(scorer, {config(extra)})[0];
    const auto at = std::upper_bound(factors.begin(), factors.end(), extra) - factors.begin();
    factors.insert(factors.begin() + at, extra);
    lls.insert(lls.begin() + at, ll);
  }
  const double nominal_ll = scorer.NominalLogLikelihood();
  json candidates = json::array();
  for (size_t i = 0; i < factors.size(); ++i) {
    candidates.push_back({{"value", nominal * factors[i]}, {"mean_log_likelihood", lls[i]}});
  }
  const int best = Best(lls, nominal_ll);
  const double best_value = best < 0 ? nominal : nominal * factors[best];
  if (best >= 0) recalibrated->friction.sliding = best_value;
  return {{"effect", "friction"}, {"parameter", "friction.sliding"}, {"nominal", nominal},
          {"candidates", candidates}, {"best", best_value},
          {"improvement_nats_per_sample", best < 0 ? 0.0 : lls[best] - nominal_ll}};
}

json ScanPayload(ResimScorer& scorer, sim::SimConfig* recalibrated) {
  const sim::SimConfig& base = scorer.nominal();
  const double m0 = 0.15 * RobotMassKg(base), r0 = 0.1, kMaxOffset = 0.3;
  const double h = base.payload.mass_kg > 0 ? base.payload.position_body_m.z() : 0.05;
  std::vector<sim::SimConfig> configs = {WithPayload(base, m0, {0, 0, h}),
                                         WithPayload(base, m0, {r0, 0, h}),
                                         WithPayload(base, m0, {0, r0, h})};
  std::vector<std::string> roles = {"probe: centre", "probe: forward", "probe: left"};
  const std::vector<ResimScore> probes = scorer.Evaluate(configs);
  json solved = nullptr;
  if (probes[0].ok && probes[1].ok && probes[2].ok && scorer.num_params() > 0) {
    Eigen::MatrixXd basis(scorer.num_params(), 3);
    basis << probes[0].shift, probes[1].shift - probes[0].shift, probes[2].shift - probes[0].shift;
    const Eigen::Vector3d s = scorer.FitCoefficients(basis);
    if (s.allFinite()) {
      const double mass = std::clamp(s(0), 0.25, 4.0) * m0;
      const Eigen::Vector2d moment = m0 * r0 * s.tail<2>();
      Eigen::Vector2d offset = moment / mass;
      offset = offset.cwiseMax(-kMaxOffset).cwiseMin(kMaxOffset);
      solved = {{"mass_kg", mass}, {"position_body_m", Vec({offset.x(), offset.y(), h})},
                {"moment_kg_m", json::array({moment.x(), moment.y()})},
                {"predicted_mean_log_likelihood", scorer.LogLikelihood(basis * s)}};
      for (double scale : {1.0, 0.7, 1.4}) {
        configs.push_back(WithPayload(base, mass, {scale * offset.x(), scale * offset.y(), h}));
        roles.push_back(scale == 1.0 ? "solved" : "solved, offset x " + std::to_string(scale).substr(0, 3));
      }
    }
  }
  std::vector<std::string> errors;
  const std::vector<double> lls = Scores(scorer, configs, &errors);
  const double nominal_ll = scorer.NominalLogLikelihood();
  json candidates = json::array();
  for (size_t i = 0; i < configs.size(); ++i) {
    json c = {{"role", roles[i]}, {"mass_kg", configs[i].payload.mass_kg},
              {"position_body_m", Vec(configs[i].payload.position_body_m)},
              {"mean_log_likelihood", lls[i]}};
    if (!errors[i].empty()) c["error"] = errors[i];
    candidates.push_back(c);
  }
  const int best = Best(lls, nominal_ll);
  const sim::PayloadConfig& p = best < 0 ? base.payload : configs[best].payload;
  if (best >= 0) recalibrated->payload = p;
  return {{"effect", "payload_offset"}, {"parameter", "payload"},
          {"nominal", {{"mass_kg", base.payload.mass_kg}, {"position_body_m", Vec(base.payload.position_body_m)}}},
          {"candidates", candidates}, {"solved", solved},
          {"best", {{"mass_kg", p.mass_kg}, {"position_body_m", Vec(p.position_body_m)}}},
          {"improvement_nats_per_sample", best < 0 ? 0.0 : lls[best] - nominal_ll}};
}

json ScanLegGain(ResimScorer& scorer, sim::SimConfig* recalibrated) {
  const sim::SimConfig& base = scorer.nominal();
  auto config = [&](int leg, double factor) {
    sim::SimConfig c = base;
    c.actuators.leg_gain[leg] = base.actuators.leg_gain[leg] * factor;
    return c;
  };
  std::vector<sim::SimConfig> configs;
  std::vector<int> legs;
  std::vector<double> factors;
  for (int leg = 0; leg < sim::kNumLegs; ++leg) {
    configs.push_back(config(leg, 0.5));
    legs.push_back(leg);
    factors.push_back(0.5);
  }
  std::vector<double> lls = Scores(scorer, configs);
  const int leg = static_cast<int>(std::max_element(lls.begin(), lls.end()) - lls.begin());
  // Refine the best leg's gain: a grid 0.25 .. 1 (1 = nominal), then the parabola's vertex.
  std::vector<double> grid = {0.25, 0.5, 0.75, 1.0};
  std::vector<double> grid_ll = {kNegInf, lls[leg], kNegInf, scorer.NominalLogLikelihood()};
  const std::vector<double> more = Scores(scorer, {config(leg, 0.25), config(leg, 0.75)});
  grid_ll[0] = more[0];
  grid_ll[2] = more[1];
  const double extra = RefinePoint(grid, grid_ll, 0.05, 1.0, 0.02);
  std::vector<double> new_factors = {0.25, 0.75};
  std::vector<double> new_lls = more;
  if (std::isfinite(extra)) {
    new_factors.push_back(extra);
    new_lls.push_back(Scores(scorer, {config(leg, extra)})[0]);
  }
  for (size_t i = 0; i < new_factors.size(); ++i) {
    configs.push_back(config(leg, new_factors[i]));
    legs.push_back(leg);
    factors.push_back(new_factors[i]);
    lls.push_back(new_lls[i]);
  }
  const double nominal_ll = scorer.NominalLogLikelihood();
  json candidates = json::array();
  for (size_t i = 0; i < configs.size(); ++i) {
    candidates.push_back({{"leg", legs[i]}, {"gain", configs[i].actuators.leg_gain[legs[i]]},
                          {"mean_log_likelihood", lls[i]}});
  }
  const int best = Best(lls, nominal_ll);
  const auto& gains = best < 0 ? base.actuators.leg_gain : configs[best].actuators.leg_gain;
  if (best >= 0) recalibrated->actuators.leg_gain = gains;
  json best_json = {{"leg_gain", gains}};
  if (best >= 0) {
    best_json["leg"] = legs[best];
    best_json["gain"] = gains[legs[best]];
    best_json["side"] = legs[best] < sim::kNumLegs / 2 ? "left" : "right";
  }
  return {{"effect", "actuator_asymmetry"}, {"parameter", "actuators.leg_gain"},
          {"nominal", base.actuators.leg_gain}, {"candidates", candidates}, {"best", best_json},
          {"improvement_nats_per_sample", best < 0 ? 0.0 : lls[best] - nominal_ll}};
}

}  // namespace dgmm::sim2real
#endif  // DGMM_SIM2REAL_HAVE_SIM
