#pragma once
// Signatures of the simulator's knobs (lib/sim/knobs.h), learnt from the simulator itself: the
// sim set's own protocol and seed are re-simulated at the nominal config and at each knob probe
// with common random numbers (same placements, commands and sensor noise), and per command the
// paired difference x_probe - x_nominal is regressed on phi = (1, pitch, roll, f):
//   shift_k(c, z, f) = B_kc^T phi   (dx),  B_kc = (Phi^T Phi + Lambda)^-1 (Phi^T D + Lambda B_k,pool)
// with the slopes shrunk towards the slopes pooled over commands. Simulated sets are cached on
// disk, keyed by a hash of (MJCF text, config JSON, protocol, seed, placements, knob, value).
#include <Eigen/Dense>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim/knobs.h"
#include "sim/protocol.h"

namespace dgmm::sim2real {

struct SignatureOptions {
  int placements = 78;      // per simulation (paper protocol: 3 per command covers all 26)
  int threads = 2;          // simulations in parallel
  std::string cache_dir;    // empty: $XDG_CACHE_HOME/dgmm, else ~/.cache/dgmm; "-": no cache
  double slope_ridge = 5.0; // pseudo-samples pulling each command's slopes to the pooled ones
  bool IsValid(std::string* error) const;
};

// The default cache folder ($XDG_CACHE_HOME/dgmm or $HOME/.cache/dgmm; empty when neither is set).
std::string DefaultCacheDir();

// Simulates (or reads from the cache) the protocol at the knob values. Same seed: paired.
struct SimulationRequest {
  std::vector<sim::KnobValue> values;  // empty: nominal
};
struct SimulationBatch {
  std::vector<SampleSet> sets;  // one per request
  int from_cache = 0, simulated = 0;
  double wall_seconds = 0;
};
SimulationBatch SimulateBatch(const sim::SimConfig& config, sim::Protocol protocol, std::uint64_t seed,
                              const std::vector<sim::Knob>& knobs,
                              const std::vector<SimulationRequest>& requests, const SignatureOptions& options);

// Hex cache key of one simulation.
std::string SimulationKey(const sim::SimConfig& config, sim::Protocol protocol, std::uint64_t seed,
                          int placements, const std::vector<sim::Knob>& knobs,
                          const std::vector<sim::KnobValue>& values);

// How x moves from a nominal simulated set to a paired perturbed one (per command, linear in
// phi = (1, pitch, roll, f)); commands are the rows of `command_table_of` (the sim set's table,
// matched by label).
class PairedShift {
 public:
  // Throws InputError when fewer than 10 samples pair up.
  static PairedShift Fit(const SampleSet& nominal, const SampleSet& perturbed, const SampleSet& command_table_of,
                         double slope_ridge);
  // Mean shift (dx) at command c (row of the sim table), terrain z (pitch, roll), first flag.
  Eigen::VectorXd Shift(int command, const Eigen::Ref<const Eigen::VectorXd>& z, double first) const;
  // log(var_perturbed / var_nominal) per dimension of x: residuals about each command's linear
  // fit in phi (the spread the sim model's covariance describes), pooled over commands.
  const Eigen::VectorXd& log_variance_ratio() const { return log_var_; }
  int pairs() const { return pairs_; }

 private:
  std::vector<Eigen::MatrixXd> b_;  // per sim command: 4 x dx (empty: not simulated, use pooled)
  Eigen::MatrixXd pooled_;          // 4 x dx
  Eigen::VectorXd log_var_;
  int pairs_ = 0;
};

}  // namespace dgmm::sim2real
