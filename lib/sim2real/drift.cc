#include "sim2real/drift.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "sim2real/units.h"

namespace dgmm::sim2real {
namespace {

// p (add-one) and z of `observed` against the permutation values' running sums: `ge` of them at
// least as extreme, `sum` and `sum2` their sum and sum of squares over `n`. Returns the null mean.
double SummariseNull(double observed, int ge, double sum, double sum2, int n, EffectDrift* out) {
  const double m = sum / n;
  const double sd = std::sqrt(std::max(0.0, sum2 / n - m * m));
  out->p_value = (ge + 1.0) / (n + 1.0);
  out->z = sd > 0 ? (observed - m) / sd : 0.0;
  return m;
}

}  // namespace

bool DriftOptions::IsValid(std::string* error) const {
  if (permutations < 20 || !(alpha > 0 && alpha < 1) || !(min_relative_change >= 0)) {
    if (error) *error = "permutations >= 20, 0 < alpha < 1 and min_relative_change >= 0";
    return false;
  }
  return true;
}

EffectDrift TestEffectDrift(const Eigen::MatrixXd& r, const Eigen::MatrixXd& s, const std::vector<int>& command,
                            const std::vector<int>& episode, const DriftOptions& options, std::uint64_t seed) {
  EffectDrift out;
  const int n = static_cast<int>(r.rows());
  // Episodes in recording order (ascending id), with their per-episode sums.
  const UnitIds ids = NumberUnitsAscending(episode);
  const int units = ids.count;
  out.episodes = units;
  if (units < 2) return out;
  std::vector<double> a(units, 0), b(units, 0), count(units, 0);
  std::vector<int> unit_cmd(units, -1);
  for (int i = 0; i < n; ++i) {
    const int e = ids.unit[i];
    a[e] += r.row(i).dot(s.row(i));
    b[e] += s.row(i).squaredNorm();
    count[e] += 1;
    if (unit_cmd[e] < 0) unit_cmd[e] = command[i];
  }
  // Recording positions in [0, 1], split into the command's mean position (a protocol may record
  // each command in one block) and the episode's offset from it (a protocol that interleaves).
  std::vector<double> t(units);
  for (int e = 0; e < units; ++e) t[e] = static_cast<double>(e) / (units - 1);
  std::map<int, std::vector<int>> units_of_command;
  for (int e = 0; e < units; ++e) units_of_command[unit_cmd[e]].push_back(e);
  std::vector<double> centre, offset(units);
  for (const auto& [c, es] : units_of_command) {
    double m = 0;
    for (int e : es) m += t[e];
    m /= es.size();
    centre.push_back(m);
    for (int e : es) offset[e] = t[e] - m;
  }
  auto evaluate = [&](const std::vector<double>& pos, double* denominator) {
    double w = 0, tw = 0;
    for (int e = 0; e < units; ++e) w += count[e], tw += count[e] * pos[e];
    const double mean = tw / w;  // sample-weighted, so a constant effect error is not a drift
    double num = 0, den = 0;
    for (int e = 0; e < units; ++e) {
      num += (pos[e] - mean) * a[e];
      den += (pos[e] - mean) * (pos[e] - mean) * b[e];
    }
    if (denominator) *denominator = den;
    return num;
  };
  double den = 0;
  const double observed = evaluate(t, &den);
  if (!(den > 0)) return out;
  out.gamma = observed / den;
  // Null: commands take each other's positions (whole blocks), episodes shuffle their offsets
  // within the command. Exchangeable when the protocol's command order is random.
  std::mt19937_64 rng(seed);
  std::vector<double> perm(units), slots = centre;
  int ge = 0;
  double sum = 0, sum2 = 0;
  for (int p = 0; p < options.permutations; ++p) {
    std::shuffle(slots.begin(), slots.end(), rng);
    size_t q = 0;
    for (const auto& [c, es] : units_of_command) {
      std::vector<double> off;
      for (int e : es) off.push_back(offset[e]);
      std::shuffle(off.begin(), off.end(), rng);
      for (size_t k = 0; k < es.size(); ++k) perm[es[k]] = slots[q] + off[k];
      ++q;
    }
    const double v = evaluate(perm, nullptr);
    sum += v, sum2 += v * v;
    ge += std::abs(v) >= std::abs(observed) * (1 - 1e-12);
  }
  SummariseNull(observed, ge, sum, sum2, options.permutations, &out);
  return out;
}

EffectDrift TestEffectStepVariation(const Eigen::MatrixXd& r, const Eigen::MatrixXd& s,
                                    const std::vector<int>& episode, const std::vector<int>& step,
                                    const DriftOptions& options, std::uint64_t seed) {
  EffectDrift out;
  const int n = static_cast<int>(r.rows());
  int max_step = -1;
  for (int i = 0; i < n; ++i) max_step = std::max(max_step, step[i]);
  if (max_step < 1) return out;
  std::vector<double> dot(n), norm2(n);
  for (int i = 0; i < n; ++i) dot[i] = r.row(i).dot(s.row(i)), norm2[i] = s.row(i).squaredNorm();
  std::vector<double> b(max_step + 1, 0);
  for (int i = 0; i < n; ++i) {
    if (step[i] >= 0) b[step[i]] += norm2[i];
  }
  double total_b = 0;
  for (double v : b) total_b += v;
  if (!(total_b > 0)) return out;
  auto q_of = [&](const std::vector<int>& labels, std::vector<double>* a_out) {
    std::vector<double> a(max_step + 1, 0);
    for (int i = 0; i < n; ++i) {
      if (labels[i] >= 0) a[labels[i]] += dot[i];
    }
    double q = 0;
    for (int k = 0; k <= max_step; ++k) {
      if (b[k] > 0) q += a[k] * a[k] / b[k];
    }
    if (a_out) *a_out = a;
    return q;
  };
  // B_k depends on the labels too; permuting within episodes keeps each episode's steps, and the
  // shift varies little within an episode, so B_k is held at its observed value.
  std::vector<double> a;
  const double observed = q_of(step, &a);
  std::map<int, std::vector<int>> rows_of;
  for (int i = 0; i < n; ++i) rows_of[episode[i]].push_back(i);
  out.episodes = static_cast<int>(rows_of.size());
  std::mt19937_64 rng(seed);
  std::vector<int> perm = step;
  int ge = 0;
  double sum = 0, sum2 = 0;
  for (int p = 0; p < options.permutations; ++p) {
    for (const auto& [e, rows] : rows_of) {
      std::vector<int> v;
      for (int i : rows) v.push_back(step[i]);
      std::shuffle(v.begin(), v.end(), rng);
      for (size_t k = 0; k < rows.size(); ++k) perm[rows[k]] = v[k];
    }
    const double q = q_of(perm, nullptr);
    sum += q, sum2 += q * q;
    ge += q >= observed * (1 - 1e-12);
  }
  const double m = SummariseNull(observed, ge, sum, sum2, options.permutations, &out);
  out.gamma = std::sqrt(std::max(0.0, observed - m) / total_b);
  for (int k = 0; k <= max_step; ++k) {
    if (!(b[k] > 0)) continue;
    const double size = 1 + a[k] / b[k];
    if (out.low_step < 0 || size < out.low) out.low = size, out.low_step = k;
    if (out.high_step < 0 || size > out.high) out.high = size, out.high_step = k;
  }
  return out;
}

void MarkDrifting(EffectDrift* total, std::vector<EffectDrift>* drifts, const DriftOptions& options) {
  total->drifting = total->p_value < options.alpha && std::abs(total->gamma) >= options.min_relative_change;
  const double level = options.alpha / std::max<size_t>(1, drifts->size());
  for (auto& d : *drifts) {
    d.drifting = total->drifting && d.p_value < level && std::abs(d.gamma) >= options.min_relative_change;
  }
}

}  // namespace dgmm::sim2real
