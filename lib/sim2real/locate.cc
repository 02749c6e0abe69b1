#include "sim2real/locate.h"

#include <algorithm>
#include <functional>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>

namespace dgmm::sim2real {
namespace {

Eigen::MatrixXd Rows(const Eigen::MatrixXd& m, const std::vector<int>& rows) {
  Eigen::MatrixXd out(rows.size(), m.cols());
  for (size_t k = 0; k < rows.size(); ++k) out.row(k) = m.row(rows[k]);
  return out;
}

std::vector<int> Labels(const std::vector<int>& label, const std::vector<int>& rows) {
  std::vector<int> out(rows.size());
  for (size_t k = 0; k < rows.size(); ++k) out[k] = label[rows[k]];
  return out;
}

}  // namespace

bool LocateOptions::IsValid(std::string* error) const {
  if (!(alpha > 0 && alpha < 1) || min_real_per_cell < 2) {
    if (error) *error = "0 < alpha < 1 and min_real_per_cell >= 2";
    return false;
  }
  return mmd.IsValid(error);
}

Eigen::MatrixXd TerrainClusters(const Eigen::MatrixXd& z, int k, std::mt19937_64& rng) {
  const int n = static_cast<int>(z.rows());
  k = std::max(1, std::min(k, n));
  Eigen::MatrixXd c(k, z.cols());
  if (n == 0 || z.cols() == 0) return Eigen::MatrixXd::Zero(1, z.cols());
  // k-means++ seeding.
  std::uniform_int_distribution<int> first(0, n - 1);
  c.row(0) = z.row(first(rng));
  Eigen::VectorXd d2 = (z.rowwise() - c.row(0)).rowwise().squaredNorm();
  for (int j = 1; j < k; ++j) {
    std::discrete_distribution<int> pick(d2.data(), d2.data() + n);
    c.row(j) = z.row(d2.sum() > 0 ? pick(rng) : first(rng));
    d2 = d2.cwiseMin((z.rowwise() - c.row(j)).rowwise().squaredNorm());
  }
  for (int it = 0; it < 100; ++it) {
    std::vector<int> label = NearestCentre(z, c);
    Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(k, z.cols());
    Eigen::VectorXd count = Eigen::VectorXd::Zero(k);
    for (int i = 0; i < n; ++i) {
      sum.row(label[i]) += z.row(i);
      count(label[i]) += 1;
    }
    Eigen::MatrixXd next = c;
    for (int j = 0; j < k; ++j) {
      if (count(j) > 0) next.row(j) = sum.row(j) / count(j);
    }
    const bool done = (next - c).norm() < 1e-12;
    c = next;
    if (done) break;
  }
  // Deterministic order: by first coordinate, then second.
  std::vector<int> order(k);
  for (int j = 0; j < k; ++j) order[j] = j;
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    if (c(a, 0) != c(b, 0)) return c(a, 0) < c(b, 0);
    return z.cols() > 1 && c(a, 1) < c(b, 1);
  });
  Eigen::MatrixXd sorted(k, z.cols());
  for (int j = 0; j < k; ++j) sorted.row(j) = c.row(order[j]);
  return sorted;
}

std::vector<int> NearestCentre(const Eigen::MatrixXd& z, const Eigen::MatrixXd& centres) {
  std::vector<int> label(z.rows(), 0);
  if (z.cols() == 0) return label;
  for (int i = 0; i < z.rows(); ++i) {
    Eigen::Index best;
    (centres.rowwise() - z.row(i)).rowwise().squaredNorm().minCoeff(&best);
    label[i] = static_cast<int>(best);
  }
  return label;
}

std::string DescribeTerrain(const Eigen::VectorXd& centre, int pitch_col, int roll_col) {
  const double deg = 180.0 / std::numbers::pi;
  const double p = pitch_col >= 0 ? centre(pitch_col) * deg : 0.0;
  const double r = roll_col >= 0 ? centre(roll_col) * deg : 0.0;
  std::string what;
  if (std::hypot(p, r) < 3.0) {
    what = "level";
  } else if (std::abs(p) >= std::abs(r)) {
    what = p > 0 ? "nose down (facing downhill)" : "nose up (facing uphill)";
  } else {
    what = r > 0 ? "left side up (slope across, downhill to the right)"
                 : "right side up (slope across, downhill to the left)";
  }
  char buf[200];
  std::snprintf(buf, sizeof buf, "%s: pitch %+.1f deg, roll %+.1f deg", what.c_str(), p, r);
  return buf;
}

namespace {

// Builds the regions of Locate in order (the permutation tests draw from one generator).
class RegionBuilder {
 public:
  RegionBuilder(const LocateInput& in, const LocateOptions& options, std::mt19937_64& rng)
      : in_(in), options_(options), rng_(rng) {}

  // One region of `family` with the real and sim rows of (command c, terrain t, sequence q), -1: all.
  void Add(const std::string& family, const std::string& label, int c, int t, int q, const Eigen::MatrixXd& a,
           const Eigen::MatrixXd& b, const std::vector<int>* real_rows = nullptr) {
    const std::vector<int> rr = real_rows ? *real_rows : Select(*in_.real, in_.real_terrain, c, t, q);
    const std::vector<int> sr = Select(*in_.sim, in_.sim_terrain, c, t, q);
    Region r;
    r.family = family, r.label = label, r.command = c, r.terrain = t, r.sequence = q;
    r.n_real = static_cast<int>(rr.size());
    r.n_sim = static_cast<int>(sr.size());
    double sum = 0;
    for (int i : rr) sum += in_.ceiling_heldout(i) - in_.model_heldout(i);
    r.deficit = rr.empty() ? 0.0 : sum / rr.size();
    const MmdResult m = options_.permute_placements
                            ? MmdTest(Rows(a, rr), Rows(b, sr), Labels(in_.real->episode, rr),
                                      Labels(in_.sim->episode, sr), options_.mmd, rng_)
                            : MmdTest(Rows(a, rr), Rows(b, sr), options_.mmd, rng_);
    r.mmd2 = m.mmd2;
    r.p_value = m.p_value;
    all_.push_back(r);
  }
  static std::vector<int> Select(const Samples& s, const std::vector<int>& terrain, int c, int t, int q) {
    std::vector<int> rows;
    for (int i = 0; i < s.size(); ++i) {
      if ((c < 0 || s.command[i] == c) && (t < 0 || terrain[i] == t) && (q < 0 || s.first_execution[i] == q)) {
        rows.push_back(i);
      }
    }
    return rows;
  }
  std::vector<Region>& regions() { return all_; }

 private:
  const LocateInput& in_;
  const LocateOptions& options_;
  std::mt19937_64& rng_;
  std::vector<Region> all_;
};

// The naive comparison: x alone, per command, pooled over terrain and sequence, each dimension
// scaled by the sim's within-command standard deviation.
void AddPooledX(const LocateInput& in, const std::vector<int>& commands,
                const std::function<std::string(int)>& command_label, RegionBuilder* b) {
  const Samples& sim = *in.sim;
  Eigen::VectorXd scale = Eigen::VectorXd::Zero(sim.pose_dim());
  std::map<int, std::vector<int>> by_c;
  for (int i = 0; i < sim.size(); ++i) by_c[sim.command[i]].push_back(i);
  double count = 0;
  for (const auto& [c, rows] : by_c) {
    Eigen::MatrixXd xs = Rows(sim.x, rows);
    scale += (xs.rowwise() - xs.colwise().mean()).colwise().squaredNorm().transpose();
    count += rows.size() - 1.0;
  }
  scale = (scale / std::max(1.0, count)).cwiseSqrt().cwiseMax(1e-12);
  const Eigen::MatrixXd xr = in.real->x * scale.cwiseInverse().asDiagonal();
  const Eigen::MatrixXd xsim = sim.x * scale.cwiseInverse().asDiagonal();
  for (int c : commands) b->Add("pooled_x", "command " + command_label(c) + " (x only, pooled)", c, -1, -1, xr, xsim);
}

// Benjamini-Hochberg: terrain, sequence and command regions form one family (so a null pair has
// at most alpha chance of any flagged region); cells and the naive test their own.
void ControlFalseDiscoveries(double alpha, std::vector<Region>* all) {
  std::map<std::string, std::vector<int>> families;
  for (size_t i = 0; i < all->size(); ++i) {
    const std::string& f = (*all)[i].family;
    const bool coarse = f == "terrain" || f == "sequence" || f == "command";
    families[coarse ? "regions" : f].push_back(static_cast<int>(i));
  }
  for (const auto& [f, idx] : families) {
    std::vector<double> p;
    for (int i : idx) p.push_back((*all)[i].p_value);
    const std::vector<double> q = BenjaminiHochberg(p);
    for (size_t k = 0; k < idx.size(); ++k) {
      (*all)[idx[k]].q_value = q[k];
      (*all)[idx[k]].significant = q[k] < alpha;
    }
  }
}

}  // namespace

std::vector<Region> Locate(const LocateInput& in, const LocateOptions& options, std::mt19937_64& rng) {
  const Samples& real = *in.real;
  RegionBuilder b(in, options, rng);
  std::vector<int> commands = real.command;
  std::sort(commands.begin(), commands.end());
  commands.erase(std::unique(commands.begin(), commands.end()), commands.end());
  const int terrains = static_cast<int>(in.terrain_labels.size());
  const std::function<std::string(int)> command_label = [&](int c) {
    return c < static_cast<int>(in.command_labels.size()) ? in.command_labels[c] : std::to_string(c);
  };
  const auto& ra = in.real_residuals;
  const auto& sb = in.sim_residuals;
  for (int t = 0; terrains > 1 && t < terrains; ++t) b.Add("terrain", in.terrain_labels[t], -1, t, -1, ra, sb);
  if (real.has_sequence && in.sim->has_sequence) {
    const char* names[2] = {"repeated command (steps 1+)", "first execution after a command change"};
    for (int q = 0; q < 2; ++q) b.Add("sequence", names[q], -1, -1, q, ra, sb);
  }
  for (int c : commands) b.Add("command", "command " + command_label(c), c, -1, -1, ra, sb);
  for (int c : commands) {
    for (int t = 0; in.with_cells && terrains > 1 && t < terrains; ++t) {
      const auto rr = RegionBuilder::Select(real, in.real_terrain, c, t, -1);
      if (static_cast<int>(rr.size()) < options.min_real_per_cell) continue;
      b.Add("cell", "command " + command_label(c) + ", " + in.terrain_labels[t], c, t, -1, ra, sb, &rr);
    }
  }
  if (in.with_pooled_x) AddPooledX(in, commands, command_label, &b);
  std::vector<Region>& all = b.regions();
  ControlFalseDiscoveries(options.alpha, &all);
  std::stable_sort(all.begin(), all.end(), [](const Region& a, const Region& b) {
    if (a.significant != b.significant) return a.significant;
    return a.deficit > b.deficit;
  });
  return all;
}

}  // namespace dgmm::sim2real
