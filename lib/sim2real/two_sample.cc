#include "sim2real/two_sample.h"

#include <algorithm>
#include <cmath>
#include <numeric>

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

MmdResult MmdTest(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, const MmdOptions& options,
                  std::mt19937_64& rng) {
  MmdResult r;
  r.n_a = static_cast<int>(a.rows());
  r.n_b = static_cast<int>(b.rows());
  if (r.n_a < 2 || r.n_b < 2) return r;
  const int n = r.n_a + r.n_b;
  Eigen::MatrixXd pooled(n, a.cols());
  pooled << a, b;
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
  double h2 = off[off.size() / 2] * options.bandwidth_factor * options.bandwidth_factor;
  if (!(h2 > 0)) h2 = 1.0;
  Eigen::MatrixXd k = (-d2.array() / (2 * h2)).exp().matrix();
  std::vector<int> index(n);
  std::iota(index.begin(), index.end(), 0);
  r.mmd2 = Mmd2(k, index, r.n_a);
  int exceed = 0;
  for (int p = 0; p < options.permutations; ++p) {
    std::shuffle(index.begin(), index.end(), rng);
    if (Mmd2(k, index, r.n_a) >= r.mmd2) ++exceed;
  }
  r.p_value = (1.0 + exceed) / (1.0 + options.permutations);
  return r;
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
