#include "sim2real/experiment_check.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <random>

#include "sim2real/simulation_cache.h"
#include "util/error.h"
#include "util/parallel_for.h"

namespace dgmm::sim2real {

bool ExperimentCheckOptions::IsValid(std::string* error) const {
  if (min_executions < 1 || max_executions < min_executions || executions_per_placement < 1 ||
      !(z_required > 0) || !(alpha > 0 && alpha < 1) || permutations < 1 || threads < 1) {
    if (error) {
      *error = "1 <= min_executions <= max_executions, executions_per_placement >= 1, z_required > 0, "
               "0 < alpha < 1, permutations >= 1, threads >= 1";
    }
    return false;
  }
  return true;
}

int ExecutionsToSeparate(double d2) { return static_cast<int>(std::ceil(11.7 / d2)); }

PairedSeparation SeparationOfPairs(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, int proposed_executions,
                                   int permutations, std::uint64_t seed, double spread_scale) {
  const int n = static_cast<int>(a.rows()), dx = static_cast<int>(a.cols());
  if (!(spread_scale > 0) || !std::isfinite(spread_scale)) {
    throw MakeInputError("experiment check", "spread_scale", "a positive finite number");
  }
  if (b.rows() != n || b.cols() != dx || dx < 1 || n < dx + 2 || !a.allFinite() || !b.allFinite()) {
    throw MakeInputError("experiment check", "outcomes", "two finite paired sets of at least dx + 2 rows");
  }
  PairedSeparation out;
  out.pairs = n;
  const Eigen::MatrixXd d = a - b;
  const Eigen::VectorXd delta = d.colwise().mean().transpose();
  const Eigen::MatrixXd dc = d.rowwise() - delta.transpose();
  const Eigen::MatrixXd s_d = dc.transpose() * dc / (n - 1);
  const Eigen::MatrixXd ac = a.rowwise() - a.colwise().mean();
  const Eigen::MatrixXd bc = b.rowwise() - b.colwise().mean();
  Eigen::MatrixXd sigma = (ac.transpose() * ac + bc.transpose() * bc) / (2.0 * n - 2) * (spread_scale * spread_scale);
  // Floor: 1e-9 of each dimension's own variance (relative, so the units of x do not matter).
  const double floor = 1e-9 * std::max(sigma.diagonal().maxCoeff(), 1e-300);
  sigma.diagonal().array() += floor;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(sigma);
  const double t_obs = delta.dot(ldlt.solve(delta));
  // The estimation error of delta (no spread scale: it comes from the simulation itself).
  const double bias = (ldlt.solve(s_d)).trace() / n;
  out.d2 = std::max(0.0, t_obs - bias);
  out.z = std::sqrt(std::max(proposed_executions, 0) * out.d2);
  out.executions_needed = out.d2 > 0 ? ExecutionsToSeparate(out.d2) : -1;
  // Paired sign-flip permutation test of "no difference in the cell".
  std::mt19937_64 rng(seed);
  std::bernoulli_distribution flip(0.5);
  int at_least = 0;
  for (int p = 0; p < permutations; ++p) {
    Eigen::VectorXd m = Eigen::VectorXd::Zero(dx);
    for (int i = 0; i < n; ++i) m += (flip(rng) ? -1.0 : 1.0) * d.row(i).transpose();
    m /= n;
    if (m.dot(ldlt.solve(m)) >= t_obs * (1 - 1e-12)) ++at_least;
  }
  out.p_value = (1.0 + at_least) / (1.0 + permutations);
  return out;
}

ExperimentCheck CheckExperiment(const KnobSimulator& simulator, const KnobValue& a, const KnobValue& b,
                                const Eigen::VectorXd& command, const Eigen::VectorXd& terrain,
                                int proposed_executions, const ExperimentCheckOptions& options,
                                double spread_scale) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "experiment check options", error);
  const auto start = std::chrono::steady_clock::now();
  ExperimentCheck out;
  out.executions_proposed = proposed_executions;
  out.seed = options.seed;
  out.spread_scale = spread_scale;
  out.knobs = {simulator.knobs().at(a.knob).name, simulator.knobs().at(b.knob).name};
  out.values = {a.value, b.value};
  const int want = std::clamp(proposed_executions, options.min_executions, options.max_executions);
  out.placements = (want + options.executions_per_placement - 1) / options.executions_per_placement;
  Cell cell;
  cell.command = command;
  cell.terrain = terrain;
  cell.placements = out.placements;
  cell.executions_per_placement = options.executions_per_placement;
  cell.seed = options.seed;
  // The two runs (in parallel when allowed); same cell and seed: common random numbers.
  CellRecording runs[2];
  try {
    ParallelFor(2, options.threads, [&](int r) { runs[r] = simulator.RecordCell(cell, {r == 0 ? a : b}); });
  } catch (const std::exception& e) {
    throw MakeInputError("simulator", "", std::string("experiment check simulation failed: ") + e.what());
  }
  out.heading_deg = runs[0].heading_deg;
  out.placement = runs[0].placement;
  const SampleSet sets[2] = {runs[0].set, runs[1].set};
  // Pair executions by (placement, execution index); a placement re-placed after a fall in one
  // run only is no longer paired and is left out.
  std::map<std::pair<int, int>, int> row_b;
  for (int i = 0; i < sets[1].size(); ++i) row_b[{sets[1].episode(i), sets[1].step(i)}] = i;
  std::vector<int> ia, ib;
  for (int i = 0; i < sets[0].size(); ++i) {
    auto it = row_b.find({sets[0].episode(i), sets[0].step(i)});
    if (it != row_b.end()) ia.push_back(i), ib.push_back(it->second);
  }
  const int dx = sets[0].pose_dim();
  out.executions_simulated = static_cast<int>(ia.size());
  if (static_cast<int>(ia.size()) < dx + 2) {
    out.why_not = "too few paired executions survived the simulation (falls)";
  } else {
    Eigen::MatrixXd xa(ia.size(), dx), xb(ib.size(), dx);
    for (size_t i = 0; i < ia.size(); ++i) {
      xa.row(i) = sets[0].x.row(ia[i]);
      xb.row(i) = sets[1].x.row(ib[i]);
    }
    out.separation =
        SeparationOfPairs(xa, xb, proposed_executions, options.permutations, options.seed, spread_scale);
    out.checked = true;
    out.confirmed = out.separation.z >= options.z_required && out.separation.p_value < options.alpha;
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

void RecordCheck(const ExperimentCheck& check, double z_required, VerdictExperiment* ex) {
  ex->checked_by_simulation = check.checked;
  ex->not_checked_because = check.why_not;
  ex->confirmed = check.confirmed;
  ex->simulated_knobs = check.knobs;
  ex->simulated_values = check.values;
  ex->executions_simulated = check.executions_simulated;
  ex->placements = check.placements;
  ex->seed = check.seed;
  ex->heading_deg = check.heading_deg;
  ex->placement = check.placement;
  ex->spread_scale = check.spread_scale;
  ex->simulated_separation = check.separation.d2;
  ex->z = check.separation.z;
  ex->z_required = z_required;
  ex->p_value = check.separation.p_value;
  ex->executions_needed = check.separation.executions_needed;
  ex->seconds = check.seconds;
}

}  // namespace dgmm::sim2real
