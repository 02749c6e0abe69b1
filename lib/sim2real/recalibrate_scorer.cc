#ifdef DGMM_SIM2REAL_HAVE_SIM
#include "sim2real/recalibrate_scorer.h"

#include <atomic>
#include <cmath>
#include <exception>
#include <thread>

#include "sim/protocol.h"
#include "sim2real/effect_fit.h"
#include "sim2real/linear_gaussian.h"
#include "sim2real/samples.h"
#include "util/error.h"

namespace dgmm::sim2real {

bool ResimOptions::IsValid(std::string* error) const {
  if (placements < 5 || threads < 1) {
    if (error) *error = ">= 5 placements per re-simulation and >= 1 thread are needed";
    return false;
  }
  return true;
}

ResimScorer::ResimScorer(const Sim2RealResult& result, const SampleSet& real,
                         const sim::SimConfig& nominal, const std::vector<EffectSpec>& effects,
                         const ResimOptions& options)
    : result_(result), real_(real), nominal_(nominal), options_(options) {
  for (const auto& e : effects) {
    if (e.is_noise || e.num_params() == 0) continue;
    effects_.push_back(e);
    num_params_ += e.num_params();
  }
  // The nominal re-simulation anchors every shift (and the command map).
  std::vector<ResimScore> nominal_score = Evaluate({nominal_});
  if (!nominal_score[0].ok) throw MakeInputError("--sim-config", "simulation", nominal_score[0].error);
  const Samples r = MakeSamples(real_, CommandMap(real_));
  if (r.size() == 0) {
    throw MakeInputError("--sim-config", "commands",
                         "the simulator's commands match none of the real set's");
  }
  real_projection_ = Project(r);
}

std::vector<int> ResimScorer::CommandMap(const SampleSet& set) const {
  // The nominal re-simulation is mapped onto the sim model's commands by label; any other set
  // through the nominal re-simulation's command table (labels, then values).
  const SampleSet* anchor = nominal_set_.size() > 0 ? &nominal_set_ : nullptr;
  std::vector<int> to_sim(set.num_commands(), -1);
  auto by_label = [&](const SampleSet& s, int row) {
    if (row >= static_cast<int>(s.command_labels.size())) return -1;
    for (int c = 0; c < static_cast<int>(result_.command_labels.size()); ++c) {
      if (result_.command_labels[c] == s.command_labels[row]) return c;
    }
    return -1;
  };
  if (anchor == nullptr) {
    for (int row = 0; row < set.num_commands(); ++row) to_sim[row] = by_label(set, row);
    return to_sim;
  }
  const std::vector<int> to_anchor = AlignCommands(*anchor, set);
  for (int row = 0; row < set.num_commands(); ++row) {
    to_sim[row] = by_label(set, row);
    if (to_sim[row] < 0 && to_anchor[row] >= 0) to_sim[row] = by_label(*anchor, to_anchor[row]);
  }
  return to_sim;
}

ResimScorer::Projection ResimScorer::Project(const Samples& samples) const {
  const FitProblem fp = MakeFitProblem(samples, result_.sim_model, effects_, result_.layout);
  // Stacked whitened designs ((n dx) x P, rows sample-major as in FitProblem) and residuals.
  Eigen::MatrixXd g(fp.n * fp.dx, num_params_);
  int col = 0;
  for (const Eigen::MatrixXd& ge : fp.g) {
    g.middleCols(col, ge.cols()) = ge;
    col += static_cast<int>(ge.cols());
  }
  const Eigen::MatrixXd r0t = fp.r0.transpose();
  const Eigen::Map<const Eigen::VectorXd> y(r0t.data(), r0t.size());
  return {g.transpose() * g, g.transpose() * y, y.squaredNorm(), fp.log_norm.sum(), fp.n};
}

Eigen::VectorXd ResimScorer::Solve(const Projection& p) const {
  Eigen::MatrixXd a = p.a;
  a.diagonal().array() += 1e-9 + 1e-6 * a.diagonal().mean();
  return a.ldlt().solve(p.b);
}

double ResimScorer::LogLikelihood(const Eigen::VectorXd& theta) const {
  // sum_r -||y_r - W_r theta||^2 / 2 expanded in the precomputed sums.
  const Projection& p = real_projection_;
  const double ss = p.yy - 2 * theta.dot(p.b) + theta.dot(p.a * theta);
  return (p.log_norm - 0.5 * ss) / p.n;
}

Eigen::VectorXd ResimScorer::FitCoefficients(const Eigen::MatrixXd& basis, double ridge) const {
  Eigen::MatrixXd a = basis.transpose() * real_projection_.a * basis;
  a.diagonal().array() += 1e-12 + ridge * std::abs(a.diagonal().mean());
  return a.ldlt().solve(basis.transpose() * real_projection_.b);
}

std::vector<SampleSet> ResimScorer::Simulate(const std::vector<sim::SimConfig>& configs,
                                             int placements, std::uint64_t seed,
                                             std::vector<std::string>* errors) {
  std::vector<SampleSet> sets(configs.size());
  errors->assign(configs.size(), "");
  std::atomic<int> next{0};
  auto work = [&] {
    for (int i; (i = next++) < static_cast<int>(configs.size());) {
      try {
        sim::ProtocolOptions protocol;
        protocol.protocol = sim::Protocol::kPaper830;
        protocol.seed = seed;
        protocol.placements = placements;
        sets[i] = sim::SimulateProtocol(configs[i], protocol);
      } catch (const std::exception& e) {
        (*errors)[i] = e.what();
      }
    }
  };
  const int workers = std::min<int>(options_.threads, static_cast<int>(configs.size()));
  std::vector<std::thread> pool;
  for (int t = 1; t < workers; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  simulations_ += static_cast<int>(configs.size());
  return sets;
}

std::vector<ResimScore> ResimScorer::Evaluate(const std::vector<sim::SimConfig>& configs) {
  std::vector<std::string> keys;
  std::vector<sim::SimConfig> todo;
  std::vector<std::string> todo_keys;
  for (const auto& c : configs) {
    keys.push_back(sim::SimConfigToJson(c));
    bool seen = cache_.count(keys.back()) > 0;
    for (const auto& k : todo_keys) seen |= k == keys.back();
    if (!seen) {
      todo.push_back(c);
      todo_keys.push_back(keys.back());
    }
  }
  if (!todo.empty()) {
    std::vector<std::string> errors;
    std::vector<SampleSet> sets = Simulate(todo, options_.placements, options_.seed, &errors);
    for (size_t i = 0; i < todo.size(); ++i) {
      ResimScore s;
      s.ok = errors[i].empty() && sets[i].size() > 0;
      s.error = errors[i].empty() ? "no samples" : errors[i];
      if (s.ok) {
        if (nominal_set_.size() == 0 && todo_keys[i] == sim::SimConfigToJson(nominal_)) {
          nominal_set_ = sets[i];
        }
        s.error.clear();
        s.samples = sets[i].size();
        s.shift = Solve(Project(MakeSamples(sets[i], CommandMap(sets[i]))));  // theta(set); shifted below
      }
      cache_[todo_keys[i]] = s;
    }
    if (nominal_theta_.size() == 0 && cache_.count(sim::SimConfigToJson(nominal_))) {
      nominal_theta_ = cache_[sim::SimConfigToJson(nominal_)].shift;
    }
    for (size_t i = 0; i < todo.size(); ++i) {
      ResimScore& s = cache_[todo_keys[i]];
      if (s.ok && nominal_theta_.size() == s.shift.size()) s.shift -= nominal_theta_;
    }
  }
  std::vector<ResimScore> out;
  for (const auto& k : keys) {
    ResimScore s = cache_[k];
    if (s.ok && real_projection_.n > 0) s.mean_log_likelihood = LogLikelihood(s.shift);
    out.push_back(s);
  }
  return out;
}

std::vector<double> ResimScorer::DirectLogLikelihoods(const std::vector<sim::SimConfig>& configs,
                                                      int placements) {
  std::vector<std::string> errors;
  std::vector<SampleSet> sets = Simulate(configs, placements, options_.seed + 1, &errors);
  const Samples r = MakeSamples(real_, CommandMap(real_));
  std::vector<double> out;
  for (size_t i = 0; i < configs.size(); ++i) {
    if (!errors[i].empty() || sets[i].size() == 0) {
      out.push_back(NAN);
      continue;
    }
    const Samples s = MakeSamples(sets[i], CommandMap(sets[i]));
    const LinearGaussianModel model = LinearGaussianModel::Fit(s, LinearGaussianOptions{});
    out.push_back(model.LogLikelihood(r).mean());
  }
  return out;
}

}  // namespace dgmm::sim2real
#endif  // DGMM_SIM2REAL_HAVE_SIM
