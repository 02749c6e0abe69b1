#include "sim2real/residual_structure.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <set>

namespace dgmm::sim2real {
namespace {

// Between-group sum of squares of unit means (rows of m) for group labels g (-1 skipped).
double BetweenSS(const Eigen::MatrixXd& m, const std::vector<int>& g) {
  std::map<int, std::pair<Eigen::VectorXd, int>> acc;
  for (int u = 0; u < m.rows(); ++u) {
    if (g[u] < 0) continue;
    auto& a = acc[g[u]];
    if (a.second == 0) a.first = Eigen::VectorXd::Zero(m.cols());
    a.first += m.row(u).transpose();
    ++a.second;
  }
  double ss = 0;
  for (const auto& [k, a] : acc) ss += a.first.squaredNorm() / a.second;
  return ss;
}

// p-value of a permutation test (add-one).
double PermutationP(double observed, const std::vector<double>& null) {
  int ge = 0;
  for (double v : null) ge += v >= observed - 1e-12 * std::abs(observed);
  return (ge + 1.0) / (null.size() + 1.0);
}

}  // namespace

bool ResidualStructureOptions::IsValid(std::string* error) const {
  if (permutations < 20 || !(alpha > 0 && alpha < 1)) {
    if (error) *error = "permutations >= 20 and 0 < alpha < 1";
    return false;
  }
  return true;
}

double ExcessKurtosis(const Eigen::MatrixXd& r) {
  if (r.rows() < 4 || r.cols() == 0) return NAN;
  double total = 0;
  for (int j = 0; j < r.cols(); ++j) {
    const Eigen::VectorXd c = r.col(j).array() - r.col(j).mean();
    const double m2 = c.squaredNorm() / c.size();
    const double m4 = c.array().pow(4).sum() / c.size();
    total += m2 > 0 ? m4 / (m2 * m2) - 3 : 0;
  }
  return total / r.cols();
}

ResidualStructure TestResidualStructure(const Eigen::MatrixXd& r, const std::vector<int>& command,
                                        const std::vector<int>& terrain, const std::vector<int>& episode,
                                        const std::vector<int>& step, double sim_kurtosis,
                                        const ResidualStructureOptions& options, std::uint64_t seed) {
  ResidualStructure out;
  const int n = static_cast<int>(r.rows()), dx = static_cast<int>(r.cols());
  std::mt19937_64 rng(seed);
  // Episode means and per-episode labels (the first sample's command; the majority terrain).
  std::map<int, int> unit_of;
  for (int i = 0; i < n; ++i) unit_of.emplace(episode[i], static_cast<int>(unit_of.size()));
  const int units = static_cast<int>(unit_of.size());
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(units, dx);
  std::vector<int> count(units, 0), unit_cmd(units, -1);
  std::vector<std::map<int, int>> terrain_votes(units);
  std::vector<int> unit(n);
  for (int i = 0; i < n; ++i) {
    unit[i] = unit_of[episode[i]];
    sum.row(unit[i]) += r.row(i);
    ++count[unit[i]];
    if (unit_cmd[unit[i]] < 0) unit_cmd[unit[i]] = command[i];
    if (terrain[i] >= 0) ++terrain_votes[unit[i]][terrain[i]];
  }
  std::vector<int> unit_terrain(units, -1);
  for (int u = 0; u < units; ++u) {
    int best = 0;
    for (const auto& [t, v] : terrain_votes[u]) {
      if (v > best) best = v, unit_terrain[u] = t;
    }
  }
  // Episode sums scaled so that each unit mean has unit variance per dim under H0: sum/sqrt(count).
  Eigen::MatrixXd scaled(units, dx);
  for (int u = 0; u < units; ++u) scaled.row(u) = sum.row(u) / std::sqrt(std::max(1, count[u]));
  auto group_test = [&](const std::string& where, const std::vector<int>& labels) {
    std::set<int> distinct(labels.begin(), labels.end());
    distinct.erase(-1);
    if (distinct.size() < 2) return;
    ResidualTest t;
    t.where = where;
    t.statistic = BetweenSS(scaled, labels);
    std::vector<int> perm = labels;
    std::vector<double> null;
    for (int p = 0; p < options.permutations; ++p) {
      std::shuffle(perm.begin(), perm.end(), rng);
      null.push_back(BetweenSS(scaled, perm));
    }
    t.p_value = PermutationP(t.statistic, null);
    out.tests.push_back(t);
  };
  group_test("command", unit_cmd);
  group_test("terrain", unit_terrain);
  // Step: residual minus its episode mean; permute step labels within each episode.
  const bool has_steps = std::any_of(step.begin(), step.end(), [](int s) { return s > 0; });
  if (has_steps && units < n) {
    Eigen::MatrixXd centred(n, dx);
    for (int i = 0; i < n; ++i) centred.row(i) = r.row(i) - sum.row(unit[i]) / count[unit[i]];
    const int max_step = *std::max_element(step.begin(), step.end());
    auto step_ss = [&](const std::vector<int>& s, Eigen::MatrixXd* means) {
      Eigen::MatrixXd m = Eigen::MatrixXd::Zero(max_step + 1, dx);
      Eigen::VectorXd c = Eigen::VectorXd::Zero(max_step + 1);
      for (int i = 0; i < n; ++i) {
        if (s[i] < 0) continue;
        m.row(s[i]) += centred.row(i);
        c(s[i]) += 1;
      }
      double ss = 0;
      for (int k = 0; k <= max_step; ++k) {
        if (c(k) > 0) {
          ss += m.row(k).squaredNorm() / c(k);
          m.row(k) /= c(k);
        }
      }
      if (means) *means = m;
      return ss;
    };
    Eigen::MatrixXd means;
    ResidualTest t;
    t.where = "step";
    t.statistic = step_ss(step, &means);
    std::map<int, std::vector<int>> rows_of;
    for (int i = 0; i < n; ++i) rows_of[unit[i]].push_back(i);
    std::vector<double> null;
    std::vector<int> perm = step;
    for (int p = 0; p < options.permutations; ++p) {
      for (const auto& [u, rows] : rows_of) {
        std::vector<int> s;
        for (int i : rows) s.push_back(step[i]);
        std::shuffle(s.begin(), s.end(), rng);
        for (size_t k = 0; k < rows.size(); ++k) perm[rows[k]] = s[k];
      }
      null.push_back(step_ss(perm, nullptr));
    }
    t.p_value = PermutationP(t.statistic, null);
    out.tests.push_back(t);
    // Periodicity of the step-mean profile: project on its main direction, lag-1 autocorrelation.
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(means, Eigen::ComputeThinV);
    Eigen::VectorXd profile = means * svd.matrixV().col(0);
    out.step_profile = profile;
    const Eigen::VectorXd c = profile.array() - profile.mean();
    double num = 0;
    for (int k = 0; k + 1 < c.size(); ++k) num += c(k) * c(k + 1);
    const double lag1 = c.squaredNorm() > 0 ? num / c.squaredNorm() : 0;
    ResidualTest per;
    per.where = "periodic";
    per.statistic = lag1;
    per.p_value = t.p_value;  // the same evidence; named periodic when the profile alternates
    if (lag1 < -0.3) out.tests.push_back(per);
  }
  if (std::isfinite(sim_kurtosis)) {
    ResidualTest t;
    t.where = "tails";
    const double k = ExcessKurtosis(r);
    const double se = std::sqrt(24.0 / std::max(1, n * dx));
    t.statistic = k - sim_kurtosis;
    t.p_value = t.statistic > std::max(1.0, 4 * se) ? 0.0 : 1.0;
    out.tests.push_back(t);
  }
  const double level = options.alpha / 4;
  for (auto& t : out.tests) {
    t.significant = t.p_value < level;
    if (t.significant) out.structured_in.push_back(t.where);
  }
  return out;
}

}  // namespace dgmm::sim2real
