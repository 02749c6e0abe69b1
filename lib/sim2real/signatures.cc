#include "sim2real/signatures.h"

#include <algorithm>
#include <map>

#include "util/error.h"

namespace dgmm::sim2real {
namespace {

// phi = (1, z_1 .. z_q, first) with q = max(2, the set's conditioning dims) (missing dims 0). P
// is its size at compile time: 4 for pitch and roll (the fixed-size path every paper set takes),
// Eigen::Dynamic when z also carries sensed terrain or continuous commands.
template <int P>
using Vec = Eigen::Matrix<double, P, 1>;
template <int P>
using Mat = Eigen::Matrix<double, P, P>;

template <int P>
Vec<P> Phi(const Eigen::Ref<const Eigen::VectorXd>& z, double first, int size) {
  Vec<P> phi = Vec<P>::Zero(size);
  phi(0) = 1.0;
  for (int j = 0; j < size - 2 && j < z.size(); ++j) phi(1 + j) = z(j);
  phi(size - 1) = first;
  return phi;
}

// The paired executions of two recordings: phi, both x and the sim table's command row of each pair.
template <int P>
struct Pairs {
  std::vector<Vec<P>> phi;
  std::vector<Eigen::VectorXd> xn, xp;
  std::vector<int> command;
};

template <int P>
Pairs<P> PairUp(const SampleSet& nominal, const SampleSet& perturbed, const SampleSet& table, int size) {
  std::map<std::string, int> row_of;  // command rows of the sim table by label
  for (int c = 0; c < table.num_commands(); ++c) {
    row_of[c < static_cast<int>(table.command_labels.size()) ? table.command_labels[c] : std::to_string(c)] = c;
  }
  auto sim_row = [&](const SampleSet& s, int i) {
    const int c = s.command(i);
    auto it = row_of.find(c < static_cast<int>(s.command_labels.size()) ? s.command_labels[c] : std::to_string(c));
    return it == row_of.end() ? -1 : it->second;
  };
  std::map<std::pair<int, int>, int> index;
  for (int i = 0; i < perturbed.size(); ++i) index[{perturbed.episode(i), perturbed.step(i)}] = i;
  Pairs<P> p;
  for (int i = 0; i < nominal.size(); ++i) {
    auto it = index.find({nominal.episode(i), nominal.step(i)});
    if (it == index.end() || perturbed.command(it->second) != nominal.command(i)) continue;
    const int c = sim_row(nominal, i);
    if (c < 0) continue;
    const Eigen::VectorXd z = nominal.terrain_dim() > 0 ? Eigen::VectorXd(nominal.z.row(i).transpose()) : Eigen::VectorXd();
    p.phi.push_back(Phi<P>(z, nominal.step(i) == 0 ? 1.0 : 0.0, size));
    p.xn.push_back(nominal.x.row(i).transpose());
    p.xp.push_back(perturbed.x.row(it->second).transpose());
    p.command.push_back(c);
  }
  return p;
}

// The fit of PairedShift::Fit in phi of size `size` (P: at compile time, or Eigen::Dynamic).
struct ShiftFit {
  Eigen::MatrixXd pooled;
  std::vector<Eigen::MatrixXd> b;
  Eigen::VectorXd log_var, paired_rms, nominal_sd;
  int pairs = 0;
};

template <int P>
ShiftFit FitShift(const SampleSet& nominal, const SampleSet& perturbed, const SampleSet& table, double slope_ridge,
                  int size) {
  const Pairs<P> pairs = PairUp<P>(nominal, perturbed, table, size);
  const int n = static_cast<int>(pairs.phi.size()), dx = nominal.pose_dim();
  if (n < 10) throw MakeInputError("signature", "", "fewer than 10 paired simulated samples");
  ShiftFit out;
  out.pairs = n;
  Eigen::MatrixXd* pooled = &out.pooled;
  std::vector<Eigen::MatrixXd>* b = &out.b;
  // Pooled fit (intercept, slopes, first flag) over all commands; the scale of z for the ridge.
  const Mat<P> zero = Mat<P>::Zero(size, size), eye = Mat<P>::Identity(size, size);
  Mat<P> gram = zero;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(size, dx);
  Vec<P> mean_phi = Vec<P>::Zero(size), sq_phi = Vec<P>::Zero(size);
  const int commands = table.num_commands();
  std::vector<Mat<P>> g(commands, zero);
  std::vector<Eigen::MatrixXd> r(commands, Eigen::MatrixXd::Zero(size, dx)), rn = r, rp = r;
  std::vector<int> count(commands, 0);
  for (int i = 0; i < n; ++i) {
    const Vec<P>& phi = pairs.phi[i];
    const Eigen::VectorXd diff = pairs.xp[i] - pairs.xn[i];
    gram += phi * phi.transpose();
    rhs += phi * diff.transpose();
    mean_phi += phi / n;
    sq_phi += phi.cwiseProduct(phi) / n;
    const int c = pairs.command[i];
    g[c] += phi * phi.transpose();
    r[c] += phi * diff.transpose();
    rn[c] += phi * pairs.xn[i].transpose();
    rp[c] += phi * pairs.xp[i].transpose();
    ++count[c];
  }
  const Vec<P> var_phi = (sq_phi - mean_phi.cwiseProduct(mean_phi)).cwiseMax(1e-12);
  *pooled = (gram + 1e-9 * eye).ldlt().solve(rhs);
  // Per command: ridge on the slopes and the flag towards the pooled coefficients.
  Mat<P> lambda = zero;
  for (int j = 1; j < size; ++j) lambda(j, j) = slope_ridge * var_phi(j);
  lambda(0, 0) = 1e-9;
  b->assign(commands, Eigen::MatrixXd());
  // Spread change: residual variance of x about each command's own linear fit in phi (the
  // spread the sim model's covariance describes), nominal vs perturbed, pooled over commands.
  std::vector<Eigen::MatrixXd> bn(commands), bp(commands);
  for (int c = 0; c < commands; ++c) {
    if (count[c] == 0) continue;
    Mat<P> lam = lambda;
    lam(0, 0) = 0;
    (*b)[c] = (g[c] + lam + 1e-9 * eye).ldlt().solve(r[c] + lam * *pooled);
    const auto solver = (g[c] + lambda + 1e-9 * eye).ldlt();
    bn[c] = solver.solve(rn[c]);
    bp[c] = solver.solve(rp[c]);
  }
  Eigen::VectorXd ss_n = Eigen::VectorXd::Zero(dx), ss_p = Eigen::VectorXd::Zero(dx), ss_d = ss_n;
  for (int i = 0; i < n; ++i) {
    const int c = pairs.command[i];
    ss_n += (pairs.xn[i] - bn[c].transpose() * pairs.phi[i]).cwiseAbs2();
    ss_p += (pairs.xp[i] - bp[c].transpose() * pairs.phi[i]).cwiseAbs2();
    ss_d += (pairs.xp[i] - pairs.xn[i]).cwiseAbs2();
  }
  out.log_var = (ss_p.array() + 1e-30).log() - (ss_n.array() + 1e-30).log();
  out.paired_rms = (ss_d / n).cwiseSqrt();
  out.nominal_sd = (ss_n / n).cwiseSqrt();
  return out;
}

}  // namespace

PairedShift PairedShift::Fit(const SampleSet& nominal, const SampleSet& perturbed, const SampleSet& table,
                             double slope_ridge) {
  PairedShift out;
  out.phi_size_ = 2 + std::max(2, nominal.terrain_dim());
  ShiftFit f = out.phi_size_ == 4 ? FitShift<4>(nominal, perturbed, table, slope_ridge, 4)
                                   : FitShift<Eigen::Dynamic>(nominal, perturbed, table, slope_ridge, out.phi_size_);
  out.pooled_ = std::move(f.pooled), out.b_ = std::move(f.b), out.log_var_ = std::move(f.log_var);
  out.paired_rms_ = std::move(f.paired_rms), out.nominal_sd_ = std::move(f.nominal_sd), out.pairs_ = f.pairs;
  return out;
}

Eigen::VectorXd PairedShift::Shift(int command, const Eigen::Ref<const Eigen::VectorXd>& z, double first) const {
  const bool own = command >= 0 && command < static_cast<int>(b_.size()) && b_[command].size() > 0;
  const Eigen::MatrixXd& b = own ? b_[command] : pooled_;
  if (phi_size_ == 4) return b.transpose() * Phi<4>(z, first, 4);
  return b.transpose() * Phi<Eigen::Dynamic>(z, first, phi_size_);
}

}  // namespace dgmm::sim2real
