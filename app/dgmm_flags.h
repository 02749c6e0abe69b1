#pragma once
// The DGMM flags shared by fit, cv, tune and experiment: variant, covariance rule, prior
// pseudo-count, initial covariance S0 (identity, data or values) and floor (docs/dgmm.md).
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "core/dgmm_options.h"

namespace dgmm::app {

struct DgmmFlags {
  std::string variant = "faithful";
  std::string covariance = CovarianceRuleName(DgmmOptions{}.covariance_rule);
  double prior_count = DgmmOptions{}.prior_pseudo_count;
  std::vector<std::string> init_cov = {"data"};  // "identity", "data" or 1 or d values
  double init_scale = DgmmOptions{}.initial_covariance_fraction;
  double floor = 0;                     // absolute floor, when --floor was given
  CLI::Option* floor_option = nullptr;  // set by AddDgmmFlags
  double floor_relative = DgmmOptions{}.covariance_floor_relative;
};

// Adds --variant, --covariance, --prior-count, --init-cov, --init-scale, --floor,
// --floor-relative to cmd.
void AddDgmmFlags(CLI::App* cmd, DgmmFlags* flags);

// The options the flags name (k left at its default) for models of `dim` dimensions (y = x || z
// when the caller fits terrain). Throws InputError naming the flag.
DgmmOptions DgmmOptionsFromFlags(const DgmmFlags& flags, int dim);

// The flags in `flags` that differ from their defaults, as command-line words (e.g.
// {"--covariance", "blend"}), except --init-scale and --prior-count (which `tune` prints with its
// chosen values): printed recipes carry them so the recipe fits what was tuned.
std::vector<std::string> NonDefaultDgmmFlags(const DgmmFlags& flags);

}  // namespace dgmm::app
