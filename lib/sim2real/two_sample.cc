#include "sim2real/two_sample.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "sim2real/units.h"

namespace dgmm::sim2real {
namespace {

// The sums of a kernel matrix K that the unbiased MMD^2 of any split of its rows needs. With the
// indicator a of the first sample, every sum is linear in a except a'Ka:
// MMD^2 = (a'Ka - a'd)/(n_a(n_a-1)) + (b'Kb - b'd)/(n_b(n_b-1)) - 2 a'Kb/(n_a n_b), b = 1 - a, d = diag K.
struct KernelSums {
  Eigen::VectorXd row_sum;  // K 1
  Eigen::VectorXd diag;     // d
  double total = 0;         // 1'K1
  double trace = 0;         // 1'd
  explicit KernelSums(const Eigen::MatrixXd& k)
      : row_sum(k.rowwise().sum()), diag(k.diagonal()), total(row_sum.sum()), trace(diag.sum()) {}
};

// Unbiased MMD^2 (Gretton et al. 2012) of the split with indicator a, given quadratic = a'Ka.
double Mmd2(const KernelSums& s, const Eigen::Ref<const Eigen::VectorXd>& a, double quadratic) {
  const double n_a = a.sum(), n_b = static_cast<double>(a.size()) - n_a;
  const double a_row = a.dot(s.row_sum), a_diag = a.dot(s.diag);
  const double within_a = quadratic - a_diag;                                      // i != j, both in a
  const double within_b = s.total - 2 * a_row + quadratic - (s.trace - a_diag);  // i != j, both in b
  const double across = a_row - quadratic;                                         // i in a, j in b
  return within_a / (n_a * (n_a - 1)) + within_b / (n_b * (n_b - 1)) - 2 * across / (n_a * n_b);
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
  const KernelSums sums(k);
  // Indicator of the first clusters_a clusters (a's side) after the clusters' current order.
  auto indicator = [&](Eigen::Ref<Eigen::VectorXd> a) {
    a.setZero();
    for (int c = 0; c < clusters_a; ++c) {
      for (int i : clusters[c]) a(i) = 1.0;
    }
  };
  Eigen::VectorXd observed(k.rows());
  indicator(observed);
  r.mmd2 = Mmd2(sums, observed, observed.dot(k * observed));
  // Permutations in blocks, so a'Ka of a block is one matrix product (the draws are made in order).
  constexpr int kBlock = 64;
  Eigen::MatrixXd split(k.rows(), kBlock), k_split(k.rows(), kBlock);
  // A split equal to the observed one (small regions draw it again) ties, whatever the rounding of
  // its matrix product: kernel entries are at most 1, so MMD^2 is at most 4.
  const double reached = r.mmd2 - 1e-12;
  int exceed = 0;
  for (int done = 0; done < options.permutations; done += kBlock) {
    const int m = std::min(kBlock, options.permutations - done);
    for (int j = 0; j < m; ++j) {
      std::shuffle(clusters.begin(), clusters.end(), rng);
      indicator(split.col(j));
    }
    k_split.leftCols(m).noalias() = k * split.leftCols(m);
    for (int j = 0; j < m; ++j) {
      const double n_a = split.col(j).sum(), n_b = static_cast<double>(k.rows()) - n_a;
      // A draw that leaves a side under 2 rows has no statistic: it counts against the observed one.
      if (n_a < 2 || n_b < 2 || Mmd2(sums, split.col(j), split.col(j).dot(k_split.col(j))) >= reached) ++exceed;
    }
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
