#pragma once
// Continuous command values (joystick speeds, steering angles) -> a few discrete commands, as
// `import-log --bins` / `--bin-edges` do. A value of exactly zero (a stop) is its own command and
// never shares a bin with slow motion; the other values are binned by quantiles (equal counts,
// the default), equal widths, or explicit edges. Each bin is represented by the median of its
// values (its label), so a bin's label is a command value that occurred.
#include <string>
#include <vector>

namespace dgmm {

struct CommandBinOptions {
  enum class Rule { kQuantile, kWidth };
  int bins = 0;  // > 0: this many bins of the non-zero values (rule)
  Rule rule = Rule::kQuantile;
  std::vector<double> edges;  // non-empty: explicit increasing inner edges (bins = edges + 1)
  bool zero_is_own_bin = true;
  // False with one line naming the flag when inconsistent (bins and edges both, edges unsorted).
  bool IsValid(std::string* error) const;
};

// The binned value of each of `values` (same order): 0 for zeros (zero_is_own_bin), else the
// median of the values in its bin. Bins follow the rule over the non-zero values; a quantile edge
// falling inside a run of equal values moves so that equal values share a bin (fewer bins then).
// Options must be valid and ask for binning (bins > 0 or edges).
std::vector<double> BinCommandValues(const std::vector<double>& values,
                                     const CommandBinOptions& options);

}  // namespace dgmm
