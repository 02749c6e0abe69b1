#include "sim2real/corrected_model.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "sim2real/locate.h"
#include "sim2real/samples.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

// The analysis' prediction of x for command c at terrain z with a known first-execution flag:
// the sim model, moved by the correction when there is one.
class Predictor {
 public:
  Predictor(const LinearGaussianModel& model, const Correction* correction)
      : model_(model), correction_(correction) {
    tau2_ = correction ? std::exp(2 * correction->log_tau) : 1.0;
  }

  // E[x | c, z, f] = u + shift(c, z, f).
  Eigen::VectorXd Mean(int c, const Eigen::VectorXd& z, bool first) const {
    const Prediction p = model_.Predict(c, z, first ? 1.0 : 0.0);
    if (!correction_) return p.mean;
    return p.mean + correction_->Shift(c, z, first ? 1.0 : 0.0, static_cast<int>(p.mean.size()));
  }

  // tau^2 S Sigma_c(z, f) S: the predictive covariance (with its inflation at z).
  Eigen::MatrixXd Covariance(int c, const Eigen::VectorXd& z, bool first) const {
    const Prediction p = model_.Predict(c, z, first ? 1.0 : 0.0);
    if (correction_ && correction_->log_var.size() > 0) return correction_->Covariance(p.chol * p.chol.transpose());
    return tau2_ * p.chol * p.chol.transpose();
  }

  // Whether the prediction may depend on the first-execution flag (the signatures do).
  bool UsesSequence() const { return model_.uses_sequence() || (correction_ && correction_->shift); }

 private:
  const LinearGaussianModel& model_;
  const Correction* correction_;
  double tau2_ = 1.0;
};

// One piece of the sim terrain: its samples (rows of z), mean and covariance.
struct Piece {
  std::vector<int> members;
  Eigen::VectorXd mean;
  Eigen::MatrixXd cov;
};

// k-means pieces of the rows of z (n x dz), clustered on z scaled to unit variance per column.
// Each piece's covariance gets one pseudo-observation of the pooled covariance / k, so that a
// piece whose samples are (nearly) collinear keeps a proper density.
std::vector<Piece> TerrainPieces(const Eigen::MatrixXd& z, const CorrectedModelOptions& options) {
  const int n = static_cast<int>(z.rows()), dz = static_cast<int>(z.cols());
  if (dz == 0 || n == 0) return {Piece{{}, Eigen::VectorXd::Zero(dz), Eigen::MatrixXd::Zero(dz, dz)}};
  const Eigen::RowVectorXd mean = z.colwise().mean();
  const Eigen::MatrixXd centred = z.rowwise() - mean;
  const Eigen::MatrixXd pooled = centred.transpose() * centred / std::max(1, n - 1);
  const Eigen::VectorXd sd = pooled.diagonal().cwiseMax(1e-12).cwiseSqrt();
  const Eigen::MatrixXd scaled = centred * sd.cwiseInverse().asDiagonal();
  const int k = std::clamp(n / std::max(1, options.samples_per_piece), 1, std::max(1, options.max_pieces));
  std::mt19937_64 rng(options.seed);
  const Eigen::MatrixXd centres = TerrainClusters(scaled, k, rng);
  const std::vector<int> label = NearestCentre(scaled, centres);
  std::vector<Piece> pieces(centres.rows());
  for (int i = 0; i < n; ++i) pieces[label[i]].members.push_back(i);
  const Eigen::MatrixXd prior = pooled / centres.rows() +
                                1e-12 * Eigen::MatrixXd::Identity(dz, dz);
  std::vector<Piece> out;
  for (Piece& p : pieces) {
    if (p.members.empty()) continue;
    Eigen::MatrixXd zp(p.members.size(), dz);
    for (size_t j = 0; j < p.members.size(); ++j) zp.row(j) = z.row(p.members[j]);
    p.mean = zp.colwise().mean().transpose();
    const Eigen::MatrixXd zc = zp.rowwise() - p.mean.transpose();
    p.cov = (zc.transpose() * zc + prior) / static_cast<double>(p.members.size());
    out.push_back(std::move(p));
  }
  return out;
}

// The joint Gaussian over y = x || z with z ~ N(m, S) and x | z ~ N(a + B (z - m), Sigma).
std::optional<Gaussian> JointGaussian(const Eigen::VectorXd& a, const Eigen::MatrixXd& b,
                                      const Eigen::MatrixXd& sigma, const Eigen::VectorXd& m,
                                      const Eigen::MatrixXd& s) {
  const int dx = static_cast<int>(a.size()), dz = static_cast<int>(m.size());
  Eigen::VectorXd mean(dx + dz);
  mean << a, m;
  Eigen::MatrixXd cov(dx + dz, dx + dz);
  cov.topLeftCorner(dx, dx) = sigma + b * s * b.transpose();
  if (dz > 0) {
    cov.topRightCorner(dx, dz) = b * s;
    cov.bottomLeftCorner(dz, dx) = s * b.transpose();
    cov.bottomRightCorner(dz, dz) = s;
  }
  cov = 0.5 * (cov + cov.transpose());
  auto g = Gaussian::Create(mean, cov);
  for (int attempt = 0; !g && attempt < 6; ++attempt) {
    cov.diagonal().array() += std::pow(10.0, attempt - 9) * (1.0 + cov.diagonal().array().abs());
    g = Gaussian::Create(mean, cov);
  }
  return g;
}

// Local fit of the prediction over one piece for command c and flag `first`: intercept a (at the
// piece mean), slope B (dx x dz) by ridge-stabilised least squares over the piece's samples, and
// Sigma = mean predictive covariance + residual scatter of the linear fit.
struct LocalFit {
  Eigen::VectorXd a;
  Eigen::MatrixXd b, sigma;
};
LocalFit FitPiece(const Predictor& predictor, int c, const Piece& piece, const Eigen::MatrixXd& z,
                  bool first, int max_points) {
  const int dz = static_cast<int>(piece.mean.size());
  std::vector<Eigen::VectorXd> points;
  // Large sets: an evenly strided subset of the piece's samples is enough for a linear fit.
  const size_t stride = std::max<size_t>(1, (piece.members.size() + max_points - 1) / max_points);
  for (size_t j = 0; j < piece.members.size(); j += stride) points.push_back(z.row(piece.members[j]).transpose());
  if (points.empty()) points.push_back(piece.mean);
  const int n = static_cast<int>(points.size());
  std::vector<Eigen::VectorXd> ys;
  Eigen::MatrixXd sigma;
  for (const auto& p : points) {
    ys.push_back(predictor.Mean(c, p, first));
    const Eigen::MatrixXd s = predictor.Covariance(c, p, first);
    sigma = sigma.size() ? Eigen::MatrixXd(sigma + s) : s;
  }
  sigma /= n;
  const int dx = static_cast<int>(ys[0].size());
  Eigen::MatrixXd y(n, dx), zc(n, dz);
  for (int i = 0; i < n; ++i) {
    y.row(i) = ys[i].transpose();
    zc.row(i) = (points[i] - piece.mean).transpose();
  }
  LocalFit fit;
  fit.a = y.colwise().mean().transpose();
  const Eigen::MatrixXd yc = y.rowwise() - fit.a.transpose();
  fit.b = Eigen::MatrixXd::Zero(dx, dz);
  if (dz > 0 && n > 1) {
    Eigen::MatrixXd gram = zc.transpose() * zc;
    gram.diagonal().array() += 1e-8 * gram.trace() / dz + 1e-15;
    fit.b = gram.ldlt().solve(zc.transpose() * yc).transpose();
  }
  const Eigen::MatrixXd resid = yc - zc * fit.b.transpose();
  fit.sigma = sigma + resid.transpose() * resid / n;
  return fit;
}

MotionModel Build(const LinearGaussianModel& model, const Correction* correction, double first_execution_share,
                  const SampleSet& sim, const CorrectedModelOptions& options) {
  const bool corrected = correction != nullptr;
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "corrected model options", error);
  MotionModel m;
  m.kind = corrected ? "corrected" : "sim2real-sim";
  m.pose_dim = sim.pose_dim();
  m.terrain_dim = sim.terrain_dim();
  m.pose_names = sim.x_names;
  m.pose_units = sim.x_units;
  m.terrain_names = sim.z_names;
  m.command_dim_names = sim.command_dim_names;
  m.transform = sim.transform;
  m.seed = options.seed;
  const Predictor predictor(model, correction);
  const bool sequence = predictor.UsesSequence();
  const double share = std::clamp(first_execution_share, 0.0, 1.0);
  // (flag, weight) of the execution kinds mixed in each piece.
  std::vector<std::pair<bool, double>> kinds;
  if (!sequence) {
    kinds = {{false, 1.0}};
  } else {
    if (share > 0) kinds.push_back({true, share});
    if (share < 1) kinds.push_back({false, 1 - share});
  }
  const Eigen::MatrixXd& z = sim.z;
  const std::vector<Piece> pieces = TerrainPieces(z, options);
  nlohmann::json effects = nlohmann::json::array();
  if (corrected) {
    for (const auto& t : correction->terms) {
      effects.push_back({{"effect", t.key}, {"theta", std::vector<double>(t.theta.data(), t.theta.data() + t.theta.size())}});
    }
  }
  m.metadata["sim2real_effects"] = effects.dump();
  m.metadata["sim2real_note"] =
      "per command " + std::to_string(pieces.size()) +
      " terrain pieces (k-means of the sim terrain), each a local linear fit of the prediction in "
      "z" + (sequence ? ", split into first executions and repeats mixed with the real "
                        "first-execution share " + std::to_string(share)
                      : std::string()) +
      "; p(x | c, z) is piecewise linear in z, weighted by the terrain density of the pieces";
  for (int c : model.Commands()) {
    if (c < sim.num_commands()) {
      m.command_values[c] = sim.commands.row(c).transpose();
      if (c < static_cast<int>(sim.command_labels.size())) m.command_labels[c] = sim.command_labels[c];
    }
    Mixture mix(m.dim());
    for (const Piece& piece : pieces) {
      double count = options.piece_pseudo_count;
      for (int i : piece.members) count += sim.command(i) == c ? 1.0 : 0.0;
      for (const auto& [first, kind_weight] : kinds) {
        const LocalFit fit = FitPiece(predictor, c, piece, z, first, options.max_fit_points);
        auto g = JointGaussian(fit.a, fit.b, fit.sigma, piece.mean, piece.cov);
        if (g && count * kind_weight > 0) mix.Add(count * kind_weight, *g);
      }
    }
    if (!mix.empty()) m.mixtures[c] = std::move(mix);
  }
  return m;
}

}  // namespace

bool CorrectedModelOptions::IsValid(std::string* error) const {
  if (max_pieces < 1 || samples_per_piece < 1 || max_fit_points < 1 || !(piece_pseudo_count > 0)) {
    if (error) *error = "max_pieces, samples_per_piece and max_fit_points must be >= 1, piece_pseudo_count > 0";
    return false;
  }
  return true;
}

MotionModel BuildSimModel(const LinearGaussianModel& model, double first_execution_share, const SampleSet& sim,
                          const CorrectedModelOptions& options) {
  return Build(model, nullptr, first_execution_share, sim, options);
}

MotionModel BuildCorrectedModel(const LinearGaussianModel& model, const Correction& correction,
                                double first_execution_share, const SampleSet& sim,
                                const CorrectedModelOptions& options) {
  return Build(model, &correction, first_execution_share, sim, options);
}

}  // namespace dgmm::sim2real
