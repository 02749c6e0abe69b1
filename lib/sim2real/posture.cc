#include "sim2real/posture.h"

#include <cmath>
#include <map>
#include <random>

#include "sim2real/candidates.h"
#include "sim2real/sentence_format.h"
#include "sim2real/verdict.h"
#include "util/error.h"
#include "util/median.h"

namespace dgmm::sim2real {

namespace {

// Mean z (pitch, roll) per command label over `rows`.
std::map<std::string, Eigen::Vector2d> MeanPerCommand(const SampleSet& s, const std::vector<int>& rows, int pitch_col,
                                                      int roll_col) {
  std::map<std::string, Eigen::Vector2d> sum;
  std::map<std::string, int> n;
  for (int i : rows) {
    const std::string& label = s.command_labels[s.command(i)];
    auto [it, fresh] = sum.emplace(label, Eigen::Vector2d::Zero());
    it->second += Eigen::Vector2d(s.z(i, pitch_col), s.z(i, roll_col));
    ++n[label];
  }
  for (auto& [label, v] : sum) v /= n[label];
  return sum;
}

constexpr double kMadToSd = 1.4826;  // a normal's SD over its median absolute deviation

// h(theta) of SlopeGeometry::radius.
Eigen::Matrix<double, 5, 1> Harmonics(double theta) {
  Eigen::Matrix<double, 5, 1> h;
  h << 1, std::cos(theta), std::sin(theta), std::cos(2 * theta), std::sin(2 * theta);
  return h;
}

// A row's z relative to the slope's centre: its direction theta and radial part rho~ = |z - c| - R(theta).
struct Radial {
  double theta = 0, rho = 0;
};
Radial RadialPart(const SampleSet& s, int i, int pitch_col, int roll_col, const SlopeGeometry& g) {
  const Eigen::Vector2d z(s.z(i, pitch_col), s.z(i, roll_col));
  const Eigen::Vector2d d = z - g.centre;
  return {std::atan2(d(1), d(0)), RadialResidual(g, z)};
}

// Mean rho~ and mean unit direction per (command label, direction bin) over `rows`.
struct RadialCell {
  double rho = 0;
  Eigen::Vector2d u = Eigen::Vector2d::Zero();
  int n = 0;
};
std::map<std::pair<std::string, int>, RadialCell> RadialCells(const SampleSet& s, const std::vector<int>& rows,
                                                             int pitch_col, int roll_col, const SlopeGeometry& g) {
  std::map<std::pair<std::string, int>, RadialCell> cells;
  const double width = 2 * M_PI / g.directions;
  for (int i : rows) {
    const Radial r = RadialPart(s, i, pitch_col, roll_col, g);
    if (!(std::abs(r.rho) <= g.outlier_rad)) continue;
    const int bin = ((static_cast<int>(std::lround(r.theta / width)) % g.directions) + g.directions) % g.directions;
    RadialCell& c = cells[{s.command_labels[s.command(i)], bin}];
    c.rho += r.rho, c.u += Eigen::Vector2d(std::cos(r.theta), std::sin(r.theta)), ++c.n;
  }
  for (auto& [key, c] : cells) c.rho /= c.n, c.u /= c.n;
  return cells;
}

// d minimising sum over the cells both have of (rho~_a - rho~_b - u . d)^2, u the cells' mean direction.
Eigen::Vector2d RadialDifference(const SampleSet& a, const std::vector<int>& rows_a, const SampleSet& b,
                                 const std::vector<int>& rows_b, int pitch_col, int roll_col, const SlopeGeometry& g) {
  const auto ca = RadialCells(a, rows_a, pitch_col, roll_col, g), cb = RadialCells(b, rows_b, pitch_col, roll_col, g);
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  int n = 0;
  for (const auto& [key, cell] : ca) {
    const auto it = cb.find(key);
    if (it == cb.end()) continue;
    const Eigen::Vector2d u = (cell.u + it->second.u) / 2;
    normal += u * u.transpose(), rhs += u * (cell.rho - it->second.rho), ++n;
  }
  // Both directions spanned: the weaker of the two at least a tenth of an average cell's.
  if (n < 3 || !(Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(normal).eigenvalues()(0) >= 0.1 * n / 2)) {
    return Eigen::Vector2d::Constant(NAN);
  }
  return normal.ldlt().solve(rhs);
}

// The rows of each placement by its episode id (each row its own without sequence data, and then
// every row a first execution); `first_only` keeps the first execution of each.
std::map<int, std::vector<int>> RowsByPlacement(const SampleSet& s, bool first_only) {
  std::map<int, std::vector<int>> rows;
  for (int i = 0; i < s.size(); ++i) {
    if (!s.has_sequence()) rows[i].push_back(i);
    else if (!first_only || s.step(i) == 0) rows[s.episode(i)].push_back(i);
  }
  return rows;
}

// The same as units in ascending order of episode id.
std::vector<std::vector<int>> Placements(const SampleSet& s, bool first_only) {
  std::vector<std::vector<int>> units;
  for (auto& [episode, rows] : RowsByPlacement(s, first_only)) units.push_back(std::move(rows));
  return units;
}

std::vector<int> Concatenate(const std::vector<std::vector<int>>& units, const std::vector<int>& pick) {
  std::vector<int> rows;
  for (int u : pick) rows.insert(rows.end(), units[u].begin(), units[u].end());
  return rows;
}

std::vector<int> All(int n) {
  std::vector<int> pick(n);
  for (int u = 0; u < n; ++u) pick[u] = u;
  return pick;
}

std::vector<int> Resample(int n, std::mt19937_64* rng) {
  std::uniform_int_distribution<int> draw(0, n - 1);
  std::vector<int> pick(n);
  for (int& u : pick) u = draw(*rng);
  return pick;
}

// The standard deviation of `draw(&rng)` over `resamples` draws (NaN draws skipped; NaN from fewer
// than two).
template <typename Draw>
Eigen::Vector2d SpreadOfDraws(int resamples, std::uint64_t seed, const Draw& draw) {
  std::mt19937_64 rng(seed);
  Eigen::Vector2d sum = Eigen::Vector2d::Zero(), sq = Eigen::Vector2d::Zero();
  int n = 0;
  for (int r = 0; r < resamples; ++r) {
    const Eigen::Vector2d d = draw(&rng);
    if (!d.allFinite()) continue;
    sum += d, sq += d.cwiseAbs2(), ++n;
  }
  if (n < 2) return Eigen::Vector2d::Constant(NAN);
  return ((sq - sum.cwiseAbs2() / n) / (n - 1)).cwiseMax(0).cwiseSqrt();
}

std::string Mrad(const Eigen::Vector2d& v) { return Fmt("%+.1f mrad in pitch, %+.1f in roll", 1e3 * v(0), 1e3 * v(1)); }

double MaxZ(const Eigen::Vector2d& v, const Eigen::Vector2d& se) {
  return std::max(std::abs(v(0)) / se(0), std::abs(v(1)) / se(1));
}

// Where the check cannot run (empty: it can).
std::string WhyNot(const PostureGround& ground, const AnalysisInputs& in, const PostureOptions& options) {
  if (!options.enabled) return "turned off (--no-posture)";
  if (in.pitch_col < 0 || in.roll_col < 0) return "the sets' z has no pitch and roll";
  if (!ground.known) return "the ground is not known without a simulator config";
  if (!ground.plane) return "the simulator's ground is not a plane (a height field)";
  if (!in.sim_set.has_sequence() || !in.real_set.has_sequence()) return "a set has no placements (episodes)";
  return "";
}

}  // namespace

bool PostureOptions::IsValid(std::string* error) const {
  if (!(z > 0) || resamples < 10) {
    *error = "posture z must be positive and resamples at least 10";
    return false;
  }
  return true;
}

double RadialResidual(const SlopeGeometry& g, const Eigen::Vector2d& z) {
  const Eigen::Vector2d d = z - g.centre;
  return d.norm() - Harmonics(std::atan2(d(1), d(0))).dot(g.radius);
}

SlopeGeometry FitSlopeGeometry(const SampleSet& reference, int pitch_col, int roll_col) {
  SlopeGeometry g;
  const int n = reference.size();
  if (n < 3) {
    g.why = "fewer than three samples";
    return g;
  }
  // Circle: |z|^2 = 2 c . z + k, k = r^2 - |c|^2 (algebraic least squares).
  Eigen::MatrixXd a(n, 3);
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) {
    const double p = reference.z(i, pitch_col), r = reference.z(i, roll_col);
    a.row(i) << 2 * p, 2 * r, 1;
    b(i) = p * p + r * r;
  }
  const Eigen::Vector3d circle = a.colPivHouseholderQr().solve(b);
  g.centre = circle.head<2>();
  Eigen::MatrixXd h(n, 5);
  Eigen::VectorXd rho(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d d = Eigen::Vector2d(reference.z(i, pitch_col), reference.z(i, roll_col)) - g.centre;
    h.row(i) = Harmonics(std::atan2(d(1), d(0))).transpose();
    rho(i) = d.norm();
  }
  g.radius = h.completeOrthogonalDecomposition().solve(rho);
  const Eigen::VectorXd residual = rho - h * g.radius;
  const Eigen::VectorXd deviation = residual.cwiseAbs();
  const double sd = kMadToSd * Median(std::vector<double>(deviation.data(), deviation.data() + n)), radius = g.radius(0);
  g.outlier_rad = 6 * sd;
  if (!g.centre.allFinite() || !g.radius.allFinite() || !(radius >= 4 * sd)) {
    g.why = Fmt("z does not trace the slope's circle clearly (radius %.3g rad,", radius) +
            Fmt(" radial residuals %.3g rad robust SD)", sd);
    return g;
  }
  g.valid = true;
  return g;
}

Eigen::Vector2d PostureDifference(const SampleSet& a, const std::vector<int>& rows_a, const SampleSet& b,
                                  const std::vector<int>& rows_b, int pitch_col, int roll_col,
                                  const SlopeGeometry* slope) {
  if (slope) return RadialDifference(a, rows_a, b, rows_b, pitch_col, roll_col, *slope);
  const auto ma = MeanPerCommand(a, rows_a, pitch_col, roll_col), mb = MeanPerCommand(b, rows_b, pitch_col, roll_col);
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  int n = 0;
  for (const auto& [label, v] : ma) {
    const auto it = mb.find(label);
    if (it == mb.end()) continue;
    sum += v - it->second;
    ++n;
  }
  return n > 0 ? Eigen::Vector2d(sum / n) : Eigen::Vector2d::Constant(NAN);
}

namespace {

// The shift over placement units `ua` of a and `ub` of b, with its bootstrap SE: each side
// resampled by itself, or, paired (ua[i] and ub[i] one placement), both with one pick.
PostureShift ShiftOverUnits(const SampleSet& a, const std::vector<std::vector<int>>& ua, const SampleSet& b,
                            const std::vector<std::vector<int>>& ub, bool paired, int pitch_col, int roll_col,
                            int resamples, std::uint64_t seed, const SlopeGeometry* slope) {
  PostureShift out;
  if (ua.empty() || ub.empty()) return out;
  const int na = static_cast<int>(ua.size()), nb = static_cast<int>(ub.size());
  out.shift = PostureDifference(a, Concatenate(ua, All(na)), b, Concatenate(ub, All(nb)), pitch_col, roll_col, slope);
  out.se = SpreadOfDraws(resamples, seed, [&](std::mt19937_64* rng) {
    const std::vector<int> pick_a = Resample(na, rng), pick_b = paired ? pick_a : Resample(nb, rng);
    return PostureDifference(a, Concatenate(ua, pick_a), b, Concatenate(ub, pick_b), pitch_col, roll_col, slope);
  });
  return out;
}

}  // namespace

PostureShift MeasurePostureShift(const SampleSet& a, const SampleSet& b, int pitch_col, int roll_col, bool first_only,
                                 int resamples, std::uint64_t seed, const SlopeGeometry* slope) {
  return ShiftOverUnits(a, Placements(a, first_only), b, Placements(b, first_only), false, pitch_col, roll_col,
                        resamples, seed, slope);
}

PostureShift MeasurePairedPostureShift(const SampleSet& a, const SampleSet& b, int pitch_col, int roll_col,
                                       bool first_only, int resamples, std::uint64_t seed,
                                       const SlopeGeometry* slope) {
  if (!a.has_sequence() || !b.has_sequence()) return {};
  // The placements both recordings kept (a probe that topples the robot keeps fewer), by episode id.
  const auto in_a = RowsByPlacement(a, first_only), in_b = RowsByPlacement(b, first_only);
  std::vector<std::vector<int>> ua, ub;
  for (const auto& [episode, rows] : in_a) {
    const auto it = in_b.find(episode);
    if (it == in_b.end()) continue;
    ua.push_back(rows), ub.push_back(it->second);
  }
  return ShiftOverUnits(a, ua, b, ub, true, pitch_col, roll_col, resamples, seed, slope);
}

PostureGround GroundOf(const KnobSimulator& simulator) {
  return {true, simulator.plane_ground(), simulator.level_ground()};
}

PostureCheck ComparePosture(const AnalysisInputs& in, const PostureGround& ground, const PostureOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "posture options", error);
  PostureCheck c;
  c.compared_only = true;
  c.correction = "nothing (the real set against the sim set alone)";
  c.why = WhyNot(ground, in, options);
  if (!c.why.empty()) return c;
  const int p = in.pitch_col, r = in.roll_col;
  c.on_slope = !ground.level;
  SlopeGeometry sim_slope;  // on a slope: where the sim set's z lies
  if (c.on_slope) {
    sim_slope = FitSlopeGeometry(in.sim_set, p, r);
    if (!sim_slope.valid) {
      c.why = "on the slope " + sim_slope.why + " in the sim set";
      return c;
    }
  }
  const SlopeGeometry* slope = c.on_slope ? &sim_slope : nullptr;
  c.walking = MeasurePostureShift(in.real_set, in.sim_set, p, r, false, options.resamples, options.seed, slope);
  c.standing = MeasurePostureShift(in.real_set, in.sim_set, p, r, true, options.resamples, options.seed + 1, slope);
  if (!c.walking.shift.allFinite() || !(c.walking.se.minCoeff() > 0)) {
    c.why = c.on_slope ? "the sets share no command in two directions on the slope with a measurable spread of z"
                       : "the sets share no command with a measurable spread of z";
    return c;
  }
  c.ran = true;
  c.left = c.walking.shift;
  c.z_left = c.z_left_without_imu = c.z_moved = MaxZ(c.walking.shift, c.walking.se);
  c.left_out = c.z_left >= options.z;
  return c;
}

PostureCheck CheckPosture(const KnobSimulator& simulator, const AnalysisInputs& in, const SampleSet& nominal,
                          const Recording& recording, const RecordingOptions& recording_options,
                          const std::vector<KnobValue>& values, const Eigen::Vector2d& imu,
                          const std::string& correction, const PostureOptions& options) {
  return CheckCorrectionPosture(ComparePosture(in, GroundOf(simulator), options), simulator, in, nominal, recording,
                                recording_options, values, imu, correction, options);
}

PostureCheck CheckCorrectionPosture(const PostureCheck& compared, const KnobSimulator& simulator,
                                    const AnalysisInputs& in, const SampleSet& nominal, const Recording& recording,
                                    const RecordingOptions& recording_options, const std::vector<KnobValue>& values,
                                    const Eigen::Vector2d& imu, const std::string& correction,
                                    const PostureOptions& options) {
  PostureCheck c = compared;
  c.compared_only = false;
  c.correction = correction;
  if (!c.ran) return c;
  c.predicted = c.predicted_standing = imu;
  if (!values.empty()) {
    // On a slope the correction's recording compares with the nominal's on the nominal's circle.
    const SlopeGeometry nominal_slope =
        c.on_slope ? FitSlopeGeometry(nominal, in.pitch_col, in.roll_col) : SlopeGeometry();
    if (c.on_slope && !nominal_slope.valid) {
      c.ran = false, c.left_out = false;
      c.why = "on the slope " + nominal_slope.why + " in the nominal recording";
      return c;
    }
    const SampleSet corrected = RecordBatch(simulator, recording, {values}, recording_options).sets.at(0);
    c.recorded = true;
    const SlopeGeometry* at_nominal = c.on_slope ? &nominal_slope : nullptr;
    const int p = in.pitch_col, r = in.roll_col;
    const PostureShift walking = MeasurePairedPostureShift(corrected, nominal, p, r, false, options.resamples,
                                                           options.seed + 2, at_nominal);
    const PostureShift standing = MeasurePairedPostureShift(corrected, nominal, p, r, true, options.resamples,
                                                            options.seed + 3, at_nominal);
    if (walking.shift.allFinite() && walking.se.allFinite()) c.predicted += walking.shift, c.predicted_se = walking.se;
    if (standing.shift.allFinite()) c.predicted_standing += standing.shift;
  }
  c.imu = imu;
  c.left = c.walking.shift - c.predicted;
  const Eigen::Vector2d se = (c.walking.se.cwiseAbs2() + c.predicted_se.cwiseAbs2()).cwiseSqrt();
  c.z_left = MaxZ(c.left, se);
  c.z_left_without_imu = MaxZ(c.left + imu, se);
  c.left_out = c.z_left >= options.z;
  return c;
}

namespace {

// A posture left out in the verdict: a doubt, `explained` becomes `partly_explained` and `clean`
// becomes `unexplained`.
void AddDoubt(const std::string& doubt, Verdict* v) {
  AddVerdictDoubt(doubt, v);
  v->unexplained_present = true;
  AddUnique(&v->structured_in, "posture");
  v->sentence += " The posture: " + doubt + ".";
}

// Standing after a placement, did the posture move as it did walking (with what the correction gives
// taken off both)? An IMU mounted off level reads alike; a payload or a weak leg tilts the walk more.
bool StandingAlike(const PostureCheck& c) {
  return c.standing.shift.allFinite() && c.standing.se.allFinite() &&
         MaxZ(c.standing.shift - c.predicted_standing - c.left, c.standing.se) < 2 &&
         MaxZ(c.standing.shift - c.predicted_standing, c.standing.se) >= 2;
}

std::string WalkingSaid(const PostureCheck& c) {
  return "the torso's posture while walking differs from the simulation's by " + Mrad(c.walking.shift) +
         Fmt(" (SE %.1f, %.1f mrad)", 1e3 * c.walking.se(0), 1e3 * c.walking.se(1));
}

// ComparePosture's answer where the analysis only locates: a moved posture is a located mismatch.
void AddComparedPosture(const PostureCheck& c, Verdict* v) {
  if (v->status == "clean") v->status = "located";
  v->unexplained_present = true;
  AddUnique(&v->structured_in, "posture");
  std::string said = WalkingSaid(c) + Fmt(", %.1f SE", c.z_moved);
  said += StandingAlike(c) ? "; standing after a placement alike, as an IMU mounted off level reads"
                           : "; standing after a placement " + Mrad(c.standing.shift) +
                                 ", unlike walking: not an IMU mounted off level (it moves both alike) but something "
                                 "that tilts the robot (a payload, a weak leg?)";
  v->sentence += " The posture: " + said + ".";
}

}  // namespace

bool ContradictsNamedImu(const PostureCheck& c, double z) {
  return c.ran && c.left_out && c.imu.norm() > 0 && c.z_left_without_imu < z;
}

std::string ContradictedImuSentence(const ContradictedImu& c) {
  if (!c.refitted) return "";
  std::vector<std::string> others;
  for (const std::string& n : c.named) {
    if (n != kImuOffsetKnob) others.push_back(n);
  }
  return " A first fit named " + (others.empty() ? std::string() : JoinWords(others) + " and ") +
         Fmt("an IMU offset of (%+.1f,", 1e3 * c.check.imu(0)) + Fmt(" %+.1f) mrad, which the torso's posture", 1e3 * c.check.imu(1)) +
         Fmt(" contradicts (%.1f SE left with it,", c.check.z_left) + Fmt(" %.1f without):", c.check.z_left_without_imu) +
         " the stages from the candidates ran again without an IMU offset.";
}

void AddPostureCheck(const PostureCheck& c, double z, Verdict* v) {
  if (!c.ran || !c.left_out) return;
  if (c.compared_only) return AddComparedPosture(c, v);
  std::string doubt = WalkingSaid(c);
  const bool moves = c.recorded || c.predicted.norm() > 0;
  doubt += "; " + c.correction + (moves ? " gives " + Mrad(c.predicted) + "," : " moves no posture,") +
           Fmt(" leaving %.1f SE (a doubt from %.3g)", c.z_left, z);
  if (ContradictsNamedImu(c, z)) {
    doubt += Fmt("; without the named IMU offset (%+.1f, %+.1f mrad) it gives the real posture", 1e3 * c.imu(0),
                 1e3 * c.imu(1)) +
             Fmt(" (%.1f SE): the offset is not what the IMU reads", c.z_left_without_imu);
    AddDoubt(doubt, v);
    return;
  }
  doubt += StandingAlike(c) ? "; the standing posture moved alike, as an IMU mounted off level reads"
                          : "; standing after a placement " + Mrad(c.standing.shift) +
                                ": something that tilts the walking robot (a payload, a weak leg) is not named";
  AddDoubt(doubt, v);
}

}  // namespace dgmm::sim2real
