#include "io/command_bins.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace dgmm {
namespace {

// Inner edges (ascending) splitting the sorted values into `bins` groups by rule.
std::vector<double> RuleEdges(const std::vector<double>& sorted, int bins,
                              CommandBinOptions::Rule rule) {
  std::vector<double> edges;
  if (sorted.empty() || bins < 2) return edges;
  const double lo = sorted.front(), hi = sorted.back();
  for (int b = 1; b < bins; ++b) {
    if (rule == CommandBinOptions::Rule::kWidth) {
      edges.push_back(lo + (hi - lo) * b / bins);
    } else {
      // The edge sits halfway between the values on either side of the b-th quantile, so a value
      // is never on an edge and equal values stay together.
      const size_t i = std::min(sorted.size() - 1, b * sorted.size() / bins);
      if (i == 0 || sorted[i] == sorted[i - 1]) continue;
      edges.push_back(0.5 * (sorted[i - 1] + sorted[i]));
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

bool CommandBinOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (bins < 0) return fail("--bins: expected >= 0");
  if (bins > 0 && !edges.empty()) return fail("--bins and --bin-edges: give one of them");
  for (size_t i = 0; i < edges.size(); ++i) {
    if (!std::isfinite(edges[i])) return fail("--bin-edges: expected finite numbers");
    if (i > 0 && !(edges[i] > edges[i - 1])) return fail("--bin-edges: expected increasing values");
  }
  return true;
}

std::vector<double> BinCommandValues(const std::vector<double>& values,
                                     const CommandBinOptions& options) {
  assert(options.bins > 0 || !options.edges.empty());
  auto is_stop = [&](double v) { return options.zero_is_own_bin && v == 0.0; };
  std::vector<double> moving;
  for (double v : values) {
    if (!is_stop(v)) moving.push_back(v);
  }
  std::sort(moving.begin(), moving.end());
  const std::vector<double> edges =
      options.edges.empty() ? RuleEdges(moving, options.bins, options.rule) : options.edges;
  auto bin_of = [&](double v) {
    return static_cast<int>(std::upper_bound(edges.begin(), edges.end(), v) - edges.begin());
  };
  std::vector<std::vector<double>> members(edges.size() + 1);
  for (double v : moving) members[bin_of(v)].push_back(v);
  std::vector<double> representative(members.size(), 0.0);
  for (size_t b = 0; b < members.size(); ++b) {
    if (!members[b].empty()) representative[b] = Median(members[b]);
  }
  std::vector<double> out;
  out.reserve(values.size());
  for (double v : values) out.push_back(is_stop(v) ? 0.0 : representative[bin_of(v)]);
  return out;
}

}  // namespace dgmm
