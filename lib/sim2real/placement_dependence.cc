#include "sim2real/placement_dependence.h"

#include <algorithm>
#include <map>
#include <numeric>
#include <random>
#include <vector>

#include "sim2real/units.h"

namespace dgmm::sim2real {
namespace {

// One set's rows grouped by placement and by command.
struct Grouped {
  const Eigen::MatrixXd* r = nullptr;
  std::vector<int> placement;                  // per row: 0 .. placements - 1
  int placements = 0;
  std::vector<std::vector<int>> by_command;    // rows of each command
};

Grouped Group(const Samples& s, const Eigen::MatrixXd& r) {
  Grouped g;
  g.r = &r;
  const UnitIds placements = NumberUnits(s.episode);
  g.placement = placements.unit;
  g.placements = placements.count;
  std::map<int, std::vector<int>> commands;
  for (int i = 0; i < s.size(); ++i) commands[s.command[i]].push_back(i);
  for (auto& [c, rows] : commands) g.by_command.push_back(std::move(rows));
  return g;
}

// T = sum_p n_p |mean of r over p|^2 = sum_p |sum of r over p|^2 / n_p, with row i of r read at
// source[i].
double Spread(const Grouped& g, const std::vector<int>& source) {
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(g.placements, g.r->cols());
  Eigen::VectorXd n = Eigen::VectorXd::Zero(g.placements);
  for (size_t i = 0; i < source.size(); ++i) {
    sum.row(g.placement[i]) += g.r->row(source[i]);
    n(g.placement[i]) += 1;
  }
  return (sum.rowwise().squaredNorm().array() / n.array().max(1.0)).sum();
}

std::vector<int> Identity(int n) {
  std::vector<int> v(n);
  std::iota(v.begin(), v.end(), 0);
  return v;
}

// The rows shuffled among the placements of each command.
std::vector<int> ShuffledWithinCommand(const Grouped& g, std::mt19937_64& rng) {
  std::vector<int> source = Identity(static_cast<int>(g.placement.size()));
  for (const auto& rows : g.by_command) {
    std::vector<int> moved = rows;
    std::shuffle(moved.begin(), moved.end(), rng);
    for (size_t k = 0; k < rows.size(); ++k) source[rows[k]] = moved[k];
  }
  return source;
}

}  // namespace

bool PlacementDependenceOptions::IsValid(std::string* error) const {
  if (permutations < 1 || !(alpha > 0 && alpha < 1)) {
    if (error) *error = "placement dependence: permutations >= 1 and 0 < alpha < 1";
    return false;
  }
  return true;
}

PlacementDependence TestPlacementDependence(const Samples& sim, const Eigen::MatrixXd& sim_residuals,
                                            const Samples& real, const Eigen::MatrixXd& real_residuals,
                                            const PlacementDependenceOptions& options, std::uint64_t seed) {
  const Grouped sets[2] = {Group(sim, sim_residuals), Group(real, real_residuals)};
  PlacementDependence d;
  for (const Grouped& g : sets) d.statistic += Spread(g, Identity(static_cast<int>(g.placement.size())));
  std::mt19937_64 rng(seed);
  int exceed = 0;
  for (int p = 0; p < options.permutations; ++p) {
    double t = 0;
    for (const Grouped& g : sets) t += Spread(g, ShuffledWithinCommand(g, rng));
    if (t >= d.statistic * (1 - 1e-12)) ++exceed;
  }
  d.p_value = (1.0 + exceed) / (1.0 + options.permutations);
  d.dependent = d.p_value < options.alpha;
  return d;
}

Eigen::VectorXd WithinPlacementCorrelation(const Eigen::MatrixXd& residuals, const std::vector<int>& episode) {
  const int dx = static_cast<int>(residuals.cols());
  const double n = static_cast<double>(residuals.rows());
  const std::vector<std::vector<int>> rows_of = RowsOfUnits(NumberUnitsAscending(episode));
  const double p = static_cast<double>(rows_of.size());
  Eigen::VectorXd rho = Eigen::VectorXd::Zero(dx);
  if (p < 2 || n <= p) return rho;
  const Eigen::RowVectorXd grand = residuals.colwise().mean();
  Eigen::VectorXd between = Eigen::VectorXd::Zero(dx), within = Eigen::VectorXd::Zero(dx);
  double sum_n2 = 0;
  for (const std::vector<int>& rows : rows_of) {
    Eigen::RowVectorXd m = Eigen::RowVectorXd::Zero(dx);
    for (int i : rows) m += residuals.row(i);
    m /= static_cast<double>(rows.size());
    between += rows.size() * (m - grand).array().square().matrix().transpose();
    for (int i : rows) within += (residuals.row(i) - m).array().square().matrix().transpose();
    sum_n2 += static_cast<double>(rows.size()) * rows.size();
  }
  const double n0 = (n - sum_n2 / n) / (p - 1);
  for (int d = 0; d < dx; ++d) {
    const double msb = between(d) / (p - 1), msw = within(d) / (n - p);
    const double denominator = msb + (n0 - 1) * msw;
    rho(d) = denominator > 0 ? std::clamp((msb - msw) / denominator, 0.0, 0.95) : 0.0;
  }
  return rho;
}

}  // namespace dgmm::sim2real
