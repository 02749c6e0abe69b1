#include "sim2real/two_sample.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "sim2real/units.h"

namespace dgmm::sim2real {
namespace {

// Unbiased MMD^2 from the kernel matrix k of the pooled sample with labels (true = first sample).
double Mmd2(const Eigen::MatrixXd& k, const std::vector<int>& index, int n_a) {
  const int n = static_cast<int>(index.size()), n_b = n - n_a;
  double saa = 0, sbb = 0, sab = 0;
  for (int i = 0; i < n; ++i) {
    const double* col = k.col(index[i]).data();
    for (int j = i + 1; j < n; ++j) {
      const double v = col[index[j]];
      if (i < n_a && j < n_a) saa += v;
      else if (i >= n_a && j >= n_a) sbb += v;
      else sab += v;
    }
  }
  return 2 * saa / (double(n_a) * (n_a - 1)) + 2 * sbb / (double(n_b) * (n_b - 1)) -
         2 * sab / (double(n_a) * n_b);
}

}  // namespace

bool MmdOptions::IsValid(std::string* error) const {
  if (permutations < 1 || !(bandwidth_factor > 0)) {
    if (error) *error = "permutations must be >= 1 and the bandwidth factor > 0";
    return false;
  }
  return true;
}

namespace {

// The Gaussian kernel matrix of the pooled rows, bandwidth by the median heuristic.
Eigen::MatrixXd PooledKernel(const Eigen::MatrixXd& pooled, double bandwidth_factor) {
  const int n = static_cast<int>(pooled.rows());
  Eigen::MatrixXd d2(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = i; j < n; ++j) d2(i, j) = d2(j, i) = (pooled.row(i) - pooled.row(j)).squaredNorm();
  }
  std::vector<double> off;
  off.reserve(n * (n - 1) / 2);
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) off.push_back(d2(i, j));
  }
  std::nth_element(off.begin(), off.begin() + off.size() / 2, off.end());
  double h2 = off[off.size() / 2] * bandwidth_factor * bandwidth_factor;
  if (!(h2 > 0)) h2 = 1.0;
  return (-d2.array() / (2 * h2)).exp().matrix();
}

// Pooled row indices per cluster: a's clusters first (in order of first appearance), then b's.
std::vector<std::vector<int>> PooledClusters(const std::vector<int>& cluster_a, const std::vector<int>& cluster_b,
                                             int* clusters_a) {
  std::vector<std::vector<int>> out;
  auto add = [&](const std::vector<int>& labels, int offset) {
    const UnitIds ids = NumberUnits(labels);
    const size_t first = out.size();
    out.resize(first + ids.count);
    for (size_t i = 0; i < labels.size(); ++i) out[first + ids.unit[i]].push_back(offset + static_cast<int>(i));
  };
  add(cluster_a, 0);
  *clusters_a = static_cast<int>(out.size());
  add(cluster_b, static_cast<int>(cluster_a.size()));
  return out;
}

}  // namespace

MmdResult MmdTest(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const std::vector<int>& cluster_a,
                  const std::vector<int>& cluster_b, const MmdOptions& options, std::mt19937_64& rng) {
  MmdResult r;
  r.n_a = static_cast<int>(a.rows());
  r.n_b = static_cast<int>(b.rows());
  if (r.n_a < 2 || r.n_b < 2) return r;
  Eigen::MatrixXd pooled(r.n_a + r.n_b, a.cols());
  pooled << a, b;
  const Eigen::MatrixXd k = PooledKernel(pooled, options.bandwidth_factor);
  int clusters_a = 0;
  std::vector<std::vector<int>> clusters = PooledClusters(cluster_a, cluster_b, &clusters_a);
  std::vector<int> index;
  auto assemble = [&]() {  // the rows of the first clusters_a clusters, then the rest
    index.clear();
    int n_a = 0;
    for (size_t c = 0; c < clusters.size(); ++c) {
      index.insert(index.end(), clusters[c].begin(), clusters[c].end());
      if (static_cast<int>(c) < clusters_a) n_a += static_cast<int>(clusters[c].size());
    }
    return n_a;
  };
  assemble();
  r.mmd2 = Mmd2(k, index, r.n_a);
  int exceed = 0;
  for (int p = 0; p < options.permutations; ++p) {
    std::shuffle(clusters.begin(), clusters.end(), rng);
    const int n_a = assemble();
    // A draw that leaves a side under 2 rows has no statistic: it counts against the observed one.
    if (n_a < 2 || static_cast<int>(index.size()) - n_a < 2 || Mmd2(k, index, n_a) >= r.mmd2) ++exceed;
  }
  r.p_value = (1.0 + exceed) / (1.0 + options.permutations);
  return r;
}

MmdResult MmdTest(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const MmdOptions& options,
                  std::mt19937_64& rng) {
  std::vector<int> ca(a.rows()), cb(b.rows());
  std::iota(ca.begin(), ca.end(), 0);
  std::iota(cb.begin(), cb.end(), 0);
  return MmdTest(a, b, ca, cb, options, rng);
}

std::vector<double> BenjaminiHochberg(const std::vector<double>& p) {
  const size_t m = p.size();
  std::vector<size_t> order(m);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t i, size_t j) { return p[i] < p[j]; });
  std::vector<double> q(m, 1.0);
  double running = 1.0;
  for (size_t r = m; r-- > 0;) {
    running = std::min(running, p[order[r]] * m / (r + 1.0));
    q[order[r]] = std::min(1.0, running);
  }
  return q;
}

}  // namespace dgmm::sim2real
