#include "sim2real/walk_chance.h"

#include <cmath>
#include <limits>

#include "util/error.h"

namespace dgmm::sim2real {

namespace {

// The nominal's spread per axis, floored at a billionth of its largest axis (a pose entry that never
// moves divides by that, not by 0).
Eigen::VectorXd Spread(const PairedShift& shift) {
  const Eigen::VectorXd& sd = shift.nominal_sd();
  return sd.cwiseMax(1e-9 * sd.maxCoeff()).cwiseMax(std::numeric_limits<double>::min());
}

}  // namespace

bool WalkChanceOptions::IsValid(std::string* error) const {
  if (!(share >= 0 && share < 0.1)) {
    if (error) *error = "walk chance: 0 <= share < 0.1 of the robot's mass";
    return false;
  }
  return true;
}

std::vector<KnobValue> ChanceRequest(const KnobSimulator& simulator, const WalkChanceOptions& options) {
  if (options.share <= 0) return {};
  const auto& knobs = simulator.knobs();
  for (int k = 0; k < static_cast<int>(knobs.size()); ++k) {
    if (knobs[k].role == Knob::Role::kPayloadMass) {
      return {KnobValue{k, knobs[k].nominal + options.share * simulator.total_mass_kg()}};
    }
  }
  return {};
}

WalkChance MeasureWalkChance(const SampleSet& nominal, const SampleSet& replica, const SampleSet& table,
                             const Samples& real, double added_kg, double slope_ridge) {
  WalkChance out;
  out.added_kg = added_kg;
  try {
    out.shift = PairedShift::Fit(nominal, replica, table, slope_ridge);
  } catch (const InputError&) {
    out.why_not = "the robot fell in most placements of the nominal's replica";
    return out;
  }
  out.spread = Spread(*out.shift);
  out.size = SignatureSize({*out.shift}, {0}, real, out.spread);
  out.paired_ratio = out.shift->paired_rms().cwiseQuotient(out.spread);
  out.largest_ratio = out.paired_ratio.maxCoeff(&out.largest_axis);
  out.measured = true;
  return out;
}

double SignatureSize(const std::vector<PairedShift>& shifts, const std::vector<int>& of, const Samples& real,
                     const Eigen::VectorXd& sd) {
  double largest = 0;
  for (int s : of) {
    double sum = 0;
    for (int i = 0; i < real.size(); ++i) {
      const Eigen::VectorXd v = shifts[s].Shift(real.command[i], real.z.row(i).transpose(), real.first_execution[i]);
      sum += v.cwiseQuotient(sd).squaredNorm();
    }
    largest = std::max(largest, std::sqrt(sum / std::max(1, real.size())));
  }
  return largest;
}

double ChanceShare(const WalkChance& chance, const std::vector<PairedShift>& shifts, const std::vector<int>& of,
                   const Samples& real) {
  if (!chance.measured || of.empty()) return NAN;
  const double own = SignatureSize(shifts, of, real, chance.spread);
  return own > 0 ? chance.size / own : INFINITY;
}

double FittedChanceShare(const WalkChance& chance, const Eigen::MatrixXd& design, const Eigen::VectorXd& theta,
                         const Samples& real) {
  if (!chance.measured || real.size() == 0 || design.cols() != theta.size()) return NAN;
  const Eigen::VectorXd& sd = chance.spread;
  const int dx = static_cast<int>(sd.size());
  const Eigen::VectorXd effect = design * theta;
  double sum = 0;
  for (int i = 0; i < real.size(); ++i) sum += effect.segment(i * dx, dx).cwiseQuotient(sd).squaredNorm();
  const double own = std::sqrt(sum / real.size());
  return own > 0 ? chance.size * theta.norm() / own : INFINITY;
}

}  // namespace dgmm::sim2real
