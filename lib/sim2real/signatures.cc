#include "sim2real/signatures.h"

#include <map>

#include "util/error.h"

namespace dgmm::sim2real {
namespace {

Eigen::Vector4d Phi(double pitch, double roll, double first) { return {1.0, pitch, roll, first}; }

}  // namespace

namespace {

// The paired executions of two recordings: phi = (1, pitch, roll, first), both x and the sim
// table's command row of each pair.
struct Pairs {
  std::vector<Eigen::Vector4d> phi;
  std::vector<Eigen::VectorXd> xn, xp;
  std::vector<int> command;
};

Pairs PairUp(const SampleSet& nominal, const SampleSet& perturbed, const SampleSet& table) {
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
  Pairs p;
  for (int i = 0; i < nominal.size(); ++i) {
    auto it = index.find({nominal.episode(i), nominal.step(i)});
    if (it == index.end() || perturbed.command(it->second) != nominal.command(i)) continue;
    const int c = sim_row(nominal, i);
    if (c < 0) continue;
    const double pitch = nominal.terrain_dim() > 0 ? nominal.z(i, 0) : 0.0;
    const double roll = nominal.terrain_dim() > 1 ? nominal.z(i, 1) : 0.0;
    p.phi.push_back(Phi(pitch, roll, nominal.step(i) == 0 ? 1.0 : 0.0));
    p.xn.push_back(nominal.x.row(i).transpose());
    p.xp.push_back(perturbed.x.row(it->second).transpose());
    p.command.push_back(c);
  }
  return p;
}

}  // namespace

PairedShift PairedShift::Fit(const SampleSet& nominal, const SampleSet& perturbed, const SampleSet& table,
                             double slope_ridge) {
  const Pairs pairs = PairUp(nominal, perturbed, table);
  const int n = static_cast<int>(pairs.phi.size()), dx = nominal.pose_dim();
  if (n < 10) throw MakeInputError("signature", "", "fewer than 10 paired simulated samples");
  PairedShift out;
  out.pairs_ = n;
  // Pooled fit (intercept, slopes, first flag) over all commands; the scale of z for the ridge.
  Eigen::Matrix4d gram = Eigen::Matrix4d::Zero();
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(4, dx);
  Eigen::Vector4d mean_phi = Eigen::Vector4d::Zero(), sq_phi = Eigen::Vector4d::Zero();
  const int commands = table.num_commands();
  std::vector<Eigen::Matrix4d> g(commands, Eigen::Matrix4d::Zero());
  std::vector<Eigen::MatrixXd> r(commands, Eigen::MatrixXd::Zero(4, dx)), rn = r, rp = r;
  std::vector<int> count(commands, 0);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector4d& phi = pairs.phi[i];
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
  const Eigen::Vector4d var_phi = (sq_phi - mean_phi.cwiseProduct(mean_phi)).cwiseMax(1e-12);
  out.pooled_ = (gram + 1e-9 * Eigen::Matrix4d::Identity()).ldlt().solve(rhs);
  // Per command: ridge on the slopes and the flag towards the pooled coefficients.
  Eigen::Matrix4d lambda = Eigen::Matrix4d::Zero();
  for (int j = 1; j < 4; ++j) lambda(j, j) = slope_ridge * var_phi(j);
  lambda(0, 0) = 1e-9;
  out.b_.assign(commands, Eigen::MatrixXd());
  // Spread change: residual variance of x about each command's own linear fit in phi (the
  // spread the sim model's covariance describes), nominal vs perturbed, pooled over commands.
  std::vector<Eigen::MatrixXd> bn(commands), bp(commands);
  for (int c = 0; c < commands; ++c) {
    if (count[c] == 0) continue;
    Eigen::Matrix4d lam = lambda;
    lam(0, 0) = 0;
    out.b_[c] = (g[c] + lam + 1e-9 * Eigen::Matrix4d::Identity()).ldlt().solve(r[c] + lam * out.pooled_);
    const auto solver = (g[c] + lambda + 1e-9 * Eigen::Matrix4d::Identity()).ldlt();
    bn[c] = solver.solve(rn[c]);
    bp[c] = solver.solve(rp[c]);
  }
  Eigen::VectorXd ss_n = Eigen::VectorXd::Zero(dx), ss_p = Eigen::VectorXd::Zero(dx);
  for (int i = 0; i < n; ++i) {
    const int c = pairs.command[i];
    ss_n += (pairs.xn[i] - bn[c].transpose() * pairs.phi[i]).cwiseAbs2();
    ss_p += (pairs.xp[i] - bp[c].transpose() * pairs.phi[i]).cwiseAbs2();
  }
  out.log_var_ = (ss_p.array() + 1e-30).log() - (ss_n.array() + 1e-30).log();
  return out;
}

Eigen::VectorXd PairedShift::Shift(int command, const Eigen::Ref<const Eigen::VectorXd>& z, double first) const {
  const Eigen::Vector4d phi = Phi(z.size() > 0 ? z(0) : 0.0, z.size() > 1 ? z(1) : 0.0, first);
  const bool own = command >= 0 && command < static_cast<int>(b_.size()) && b_[command].size() > 0;
  return (own ? b_[command] : pooled_).transpose() * phi;
}

}  // namespace dgmm::sim2real
