#include "sim2real/residual_structure.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <set>

#include "sim2real/units.h"

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

double ExcessKurtosisSe(const Eigen::MatrixXd& r, const std::vector<int>& episode, int resamples, std::uint64_t seed) {
  const std::vector<std::vector<int>> rows_of = RowsOfUnits(NumberUnitsAscending(episode));  // ascending episode id
  std::vector<const std::vector<int>*> units;
  for (const auto& rows : rows_of) units.push_back(&rows);
  if (units.size() < 2 || resamples < 2) return NAN;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<size_t> pick(0, units.size() - 1);
  std::vector<double> k;
  for (int b = 0; b < resamples; ++b) {
    std::vector<int> rows;
    for (size_t u = 0; u < units.size(); ++u) {
      const auto* unit = units[pick(rng)];
      rows.insert(rows.end(), unit->begin(), unit->end());
    }
    Eigen::MatrixXd rb(rows.size(), r.cols());
    for (size_t i = 0; i < rows.size(); ++i) rb.row(i) = r.row(rows[i]);
    k.push_back(ExcessKurtosis(rb));
  }
  const double mean = std::accumulate(k.begin(), k.end(), 0.0) / k.size();
  double ss = 0;
  for (double v : k) ss += (v - mean) * (v - mean);
  return std::sqrt(ss / (k.size() - 1));
}

namespace {

// The residuals per episode (the exchangeable unit): sums, counts and labels (the first sample's
// command, the majority terrain).
struct EpisodeUnits {
  std::vector<int> unit;        // per sample
  Eigen::MatrixXd sum, scaled;  // units x dx; scaled = sum / sqrt(count): unit variance under H0
  std::vector<int> count, command, terrain;
};

EpisodeUnits Units(const Eigen::MatrixXd& r, const std::vector<int>& command, const std::vector<int>& terrain,
                   const std::vector<int>& episode) {
  const int n = static_cast<int>(r.rows()), dx = static_cast<int>(r.cols());
  const UnitIds ids = NumberUnits(episode);
  const int units = ids.count;
  EpisodeUnits e;
  e.sum = Eigen::MatrixXd::Zero(units, dx);
  e.count.assign(units, 0), e.command.assign(units, -1), e.terrain.assign(units, -1);
  std::vector<std::map<int, int>> terrain_votes(units);
  e.unit = ids.unit;
  for (int i = 0; i < n; ++i) {
    const int u = e.unit[i];
    e.sum.row(u) += r.row(i);
    ++e.count[u];
    if (e.command[u] < 0) e.command[u] = command[i];
    if (terrain[i] >= 0) ++terrain_votes[u][terrain[i]];
  }
  for (int u = 0; u < units; ++u) {
    int best = 0;
    for (const auto& [t, v] : terrain_votes[u]) {
      if (v > best) best = v, e.terrain[u] = t;
    }
  }
  e.scaled.resize(units, dx);
  for (int u = 0; u < units; ++u) e.scaled.row(u) = e.sum.row(u) / std::sqrt(std::max(1, e.count[u]));
  return e;
}

// Between-group test of the episode means over `labels` (labels permuted over episodes).
void GroupTest(const EpisodeUnits& e, const std::string& where, const std::vector<int>& labels, int permutations,
               std::mt19937_64& rng, ResidualStructure* out) {
  std::set<int> distinct(labels.begin(), labels.end());
  distinct.erase(-1);
  if (distinct.size() < 2) return;
  ResidualTest t;
  t.where = where;
  t.statistic = BetweenSS(e.scaled, labels);
  std::vector<int> perm = labels;
  std::vector<double> null;
  for (int p = 0; p < permutations; ++p) {
    std::shuffle(perm.begin(), perm.end(), rng);
    null.push_back(BetweenSS(e.scaled, perm));
  }
  t.p_value = PermutationP(t.statistic, null);
  out->tests.push_back(t);
}

// The two sets' command means compared: sum_c w_c |m_real,c - m_sim,c|^2, w_c = N_r N_s / (N_r +
// N_s), over the pooled episode units `u` whose `real` flag says which set they are of.
double CommandContrast(const EpisodeUnits& u, const std::vector<char>& real) {
  struct Side {
    Eigen::VectorXd sum;
    int n = 0;
  };
  std::map<int, std::array<Side, 2>> by_command;
  for (size_t k = 0; k < u.count.size(); ++k) {
    if (u.command[k] < 0) continue;
    Side& side = by_command[u.command[k]][real[k] ? 0 : 1];
    if (side.n == 0) side.sum = Eigen::VectorXd::Zero(u.sum.cols());
    side.sum += u.sum.row(k).transpose();
    side.n += u.count[k];
  }
  double t = 0;
  for (const auto& [c, s] : by_command) {
    if (s[0].n == 0 || s[1].n == 0) continue;
    const double w = static_cast<double>(s[0].n) * s[1].n / (s[0].n + s[1].n);
    t += w * (s[0].sum / s[0].n - s[1].sum / s[1].n).squaredNorm();
  }
  return t;
}

// Command against the sim set's own residuals: are the real command means the sim set's? The
// set labels are permuted over each command's episodes of both sets.
void CommandTestAgainstSim(const EpisodeUnits& real, const EpisodeUnits& sim, int permutations, std::mt19937_64& rng,
                           ResidualStructure* out) {
  EpisodeUnits pooled;
  pooled.sum.resize(real.sum.rows() + sim.sum.rows(), real.sum.cols());
  pooled.sum << real.sum, sim.sum;
  pooled.count = real.count, pooled.command = real.command;
  pooled.count.insert(pooled.count.end(), sim.count.begin(), sim.count.end());
  pooled.command.insert(pooled.command.end(), sim.command.begin(), sim.command.end());
  std::vector<char> is_real(pooled.count.size(), 0);
  std::fill(is_real.begin(), is_real.begin() + real.count.size(), 1);
  std::map<int, std::vector<int>> units_of;
  for (size_t k = 0; k < pooled.command.size(); ++k) units_of[pooled.command[k]].push_back(static_cast<int>(k));
  ResidualTest t;
  t.where = "command";
  t.statistic = CommandContrast(pooled, is_real);
  std::vector<double> null;
  std::vector<char> perm = is_real, labels;
  for (int p = 0; p < permutations; ++p) {
    for (const auto& [c, units] : units_of) {
      labels.clear();
      for (int k : units) labels.push_back(is_real[k]);
      std::shuffle(labels.begin(), labels.end(), rng);
      for (size_t j = 0; j < units.size(); ++j) perm[units[j]] = labels[j];
    }
    null.push_back(CommandContrast(pooled, perm));
  }
  t.p_value = PermutationP(t.statistic, null);
  out->tests.push_back(t);
}

// Residuals minus their episode's mean, their step labels and each episode's rows.
struct StepRows {
  Eigen::MatrixXd centred;
  std::vector<int> step;
  std::vector<std::vector<int>> rows_of;  // per episode, in ascending episode id
};

StepRows CentreByEpisode(const Eigen::MatrixXd& r, const std::vector<int>& episode, const std::vector<int>& step) {
  StepRows out;
  out.step = step;
  out.rows_of = RowsOfUnits(NumberUnitsAscending(episode));
  out.centred.resize(r.rows(), r.cols());
  for (const std::vector<int>& rows : out.rows_of) {
    Eigen::VectorXd m = Eigen::VectorXd::Zero(r.cols());
    for (int i : rows) m += r.row(i).transpose();
    m /= static_cast<double>(rows.size());
    for (int i : rows) out.centred.row(i) = r.row(i) - m.transpose();
  }
  return out;
}

// Step labels shuffled within each episode.
std::vector<int> ShuffledWithinEpisodes(const StepRows& s, std::mt19937_64& rng) {
  std::vector<int> perm = s.step;
  for (const std::vector<int>& rows : s.rows_of) {
    std::vector<int> labels;
    for (int i : rows) labels.push_back(s.step[i]);
    std::shuffle(labels.begin(), labels.end(), rng);
    for (size_t k = 0; k < rows.size(); ++k) perm[rows[k]] = labels[k];
  }
  return perm;
}

// Mean of `centred` per step label (rows of *means) and the count of each (steps < 0 skipped).
void StepMeans(const Eigen::MatrixXd& centred, const std::vector<int>& s, int max_step, Eigen::MatrixXd* means,
               Eigen::VectorXd* counts) {
  *means = Eigen::MatrixXd::Zero(max_step + 1, centred.cols());
  *counts = Eigen::VectorXd::Zero(max_step + 1);
  for (int i = 0; i < centred.rows(); ++i) {
    if (s[i] < 0 || s[i] > max_step) continue;
    means->row(s[i]) += centred.row(i);
    (*counts)(s[i]) += 1;
  }
  for (int k = 0; k <= max_step; ++k) {
    if ((*counts)(k) > 0) means->row(k) /= (*counts)(k);
  }
}

// The step statistic: sum over steps of c_k |m_k|^2 (one set), or against the sim set's profile
//   T = sum_k w_k |m_real,k - m_sim,k|^2,  w_k = c_real,k c_sim,k / (c_real,k + c_sim,k);
// *profile gets the step means (their difference with a sim set).
double StepStatistic(const StepRows& real, const std::vector<int>& real_step, const StepRows* sim,
                     const std::vector<int>* sim_step, int max_step, Eigen::MatrixXd* profile) {
  Eigen::MatrixXd m;
  Eigen::VectorXd c;
  StepMeans(real.centred, real_step, max_step, &m, &c);
  Eigen::VectorXd w = c;
  if (sim) {
    Eigen::MatrixXd ms;
    Eigen::VectorXd cs;
    StepMeans(sim->centred, *sim_step, max_step, &ms, &cs);
    m -= ms;
    for (int k = 0; k <= max_step; ++k) w(k) = c(k) + cs(k) > 0 ? c(k) * cs(k) / (c(k) + cs(k)) : 0;
  }
  double t = 0;
  for (int k = 0; k <= max_step; ++k) t += w(k) * m.row(k).squaredNorm();
  if (profile) *profile = m;
  return t;
}

// Step: the residual minus its episode mean, step labels permuted within each episode (in both sets
// when the sim set's own residuals are given: then the question is whether the real step profile
// differs from the sim set's, which the model's own shortcomings shape as much); then the
// periodicity of the step-mean profile (its main direction's lag-1 autocorrelation).
void StepTest(const Eigen::MatrixXd& r, const std::vector<int>& episode, const std::vector<int>& step,
              const SimReference& sim_ref, int permutations, std::mt19937_64& rng, ResidualStructure* out) {
  const StepRows real = CentreByEpisode(r, episode, step);
  // A sim set without execution indices (no sequence data) has no profile to compare with.
  const bool two = sim_ref.has_residuals() && sim_ref.step &&
                   std::any_of(sim_ref.step->begin(), sim_ref.step->end(), [](int s) { return s > 0; });
  StepRows sim;
  if (two) sim = CentreByEpisode(*sim_ref.residuals, *sim_ref.episode, *sim_ref.step);
  const int max_step = *std::max_element(step.begin(), step.end());
  Eigen::MatrixXd means;
  ResidualTest t;
  t.where = "step";
  t.statistic = StepStatistic(real, real.step, two ? &sim : nullptr, two ? &sim.step : nullptr, max_step, &means);
  std::vector<double> null;
  for (int p = 0; p < permutations; ++p) {
    const std::vector<int> perm = ShuffledWithinEpisodes(real, rng);
    const std::vector<int> sim_perm = two ? ShuffledWithinEpisodes(sim, rng) : std::vector<int>();
    null.push_back(StepStatistic(real, perm, two ? &sim : nullptr, two ? &sim_perm : nullptr, max_step, nullptr));
  }
  t.p_value = PermutationP(t.statistic, null);
  out->tests.push_back(t);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(means, Eigen::ComputeThinV);
  const Eigen::VectorXd profile = means * svd.matrixV().col(0);
  out->step_profile = profile;
  const Eigen::VectorXd c = profile.array() - profile.mean();
  double num = 0;
  for (int k = 0; k + 1 < c.size(); ++k) num += c(k) * c(k + 1);
  const double lag1 = c.squaredNorm() > 0 ? num / c.squaredNorm() : 0;
  ResidualTest per;
  per.where = "periodic";
  per.statistic = lag1;
  per.p_value = t.p_value;  // the same evidence; named periodic when the profile alternates
  if (lag1 < -0.3) out->tests.push_back(per);
}

}  // namespace

ResidualStructure TestResidualStructure(const Eigen::MatrixXd& r, const std::vector<int>& command,
                                        const std::vector<int>& terrain, const std::vector<int>& episode,
                                        const std::vector<int>& step, double sim_kurtosis,
                                        const ResidualStructureOptions& options, std::uint64_t seed,
                                        double sim_kurtosis_se, const SimReference& sim_ref) {
  ResidualStructure out;
  const int n = static_cast<int>(r.rows()), dx = static_cast<int>(r.cols());
  std::mt19937_64 rng(seed);
  const EpisodeUnits e = Units(r, command, terrain, episode);
  if (sim_ref.has_residuals() && sim_ref.command) {
    const std::vector<int> no_terrain(sim_ref.residuals->rows(), -1);
    const EpisodeUnits sim = Units(*sim_ref.residuals, *sim_ref.command, no_terrain, *sim_ref.episode);
    CommandTestAgainstSim(e, sim, options.permutations, rng, &out);
  } else {
    GroupTest(e, "command", e.command, options.permutations, rng, &out);
  }
  GroupTest(e, "terrain", e.terrain, options.permutations, rng, &out);
  const bool has_steps = std::any_of(step.begin(), step.end(), [](int s) { return s > 0; });
  if (has_steps && static_cast<int>(e.count.size()) < n) StepTest(r, episode, step, sim_ref, options.permutations, rng, &out);
  if (std::isfinite(sim_kurtosis)) {
    ResidualTest t;
    t.where = "tails";
    const double k = ExcessKurtosis(r);
    const double se =
        options.tails_bootstrap > 0
            ? std::hypot(ExcessKurtosisSe(r, episode, options.tails_bootstrap, seed + 1), sim_kurtosis_se)
            : std::sqrt(24.0 / std::max(1, n * dx));
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
