#include "core/motion_model.h"

#include <cassert>
#include <cmath>
#include <numbers>
#include <numeric>

#include "core/data_scale.h"
#include "util/error.h"

namespace dgmm {
namespace {

std::vector<int> Range(int begin, int end) {
  std::vector<int> v(std::max(0, end - begin));
  std::iota(v.begin(), v.end(), begin);
  return v;
}

// z (raw units, terrain_dim entries: InputError otherwise) in the model's own units, where its
// mixtures live: standardised when the model was fitted on standardised data.
Eigen::VectorXd ZInModelUnits(const MotionModel& model, const Eigen::VectorXd& z) {
  const int p = model.pose_dim, t = model.terrain_dim;
  if (z.size() != t) {
    throw InputError("z: " + std::to_string(z.size()) + " values, expected " + std::to_string(t));
  }
  if (model.transform.empty()) return z;
  return (z - model.transform.offset.segment(p, t)).cwiseQuotient(model.transform.scale.segment(p, t));
}

// "0 ('fwd'), 2 ('turn')": the commands a model has a mixture for.
std::string ListCommands(const MotionModel& model) {
  std::string out;
  for (const auto& [id, mixture] : model.mixtures) {
    if (!out.empty()) out += ", ";
    out += std::to_string(id);
    if (auto it = model.command_labels.find(id); it != model.command_labels.end()) {
      out += " ('" + it->second + "')";
    }
  }
  return out.empty() ? "none" : out;
}

void CheckSize(const char* field, Eigen::Index got, int expected) {
  if (got != expected) {
    throw MakeInputError("", field,
                         "has " + std::to_string(got) + " dimensions, the model expects " +
                             std::to_string(expected));
  }
}

// Relative equality of two transforms over their first `dims` entries.
bool SameTransform(const Standardization& a, const Standardization& b, int dims) {
  if (a.offset.size() < dims || b.offset.size() < dims) return false;
  for (int j = 0; j < dims; ++j) {
    const double tol = 1e-9 * std::max({1.0, std::abs(a.scale[j]), std::abs(a.offset[j])});
    if (std::abs(a.offset[j] - b.offset[j]) > tol || std::abs(a.scale[j] - b.scale[j]) > tol) {
      return false;
    }
  }
  return true;
}

}  // namespace

const Mixture& MotionModel::MixtureFor(int command) const {
  if (auto it = mixtures.find(command); it != mixtures.end()) return it->second;
  std::string which = std::to_string(command);
  if (auto it = command_labels.find(command); it != command_labels.end()) {
    which += " ('" + it->second + "')";
  }
  if (command_values.count(command) > 0) {
    throw MakeInputError("", "command",
                         "command " + which +
                             " had no samples in the training set, so the model has no "
                             "mixture for it (model has: " +
                             ListCommands(*this) + ")");
  }
  throw MakeInputError("", "command",
                       "unknown command " + which + " (model has: " + ListCommands(*this) + ")");
}

double MotionModel::LogLikelihood(int command, const Eigen::Ref<const Eigen::VectorXd>& x) const {
  CheckSize("x", x.size(), pose_dim);
  const Mixture& mixture = MixtureFor(command);
  if (terrain_dim == 0) return mixture.LogDensity(x);
  return mixture.Marginal(Range(0, pose_dim)).LogDensity(x);
}

double MotionModel::LogLikelihood(int command, const Eigen::Ref<const Eigen::VectorXd>& x,
                                  const Eigen::Ref<const Eigen::VectorXd>& z) const {
  CheckSize("x", x.size(), pose_dim);
  return Conditional(command, z).LogDensity(x);
}

Mixture MotionModel::Conditional(int command, const Eigen::Ref<const Eigen::VectorXd>& z) const {
  if (terrain_dim == 0) {
    throw MakeInputError("", "terrain", "the model was fitted without terrain");
  }
  CheckSize("z", z.size(), terrain_dim);
  return MixtureFor(command).Conditional(Range(pose_dim, dim()), z);
}

Mixture MotionModel::RawPoseDistribution(int command, const Eigen::VectorXd& z) const {
  Mixture m;
  if (z.size() == 0) {
    m = terrain_dim > 0 ? MixtureFor(command).Marginal(Range(0, pose_dim)) : MixtureFor(command);
  } else {
    if (terrain_dim == 0) throw InputError("model: fitted without terrain; give no z");
    m = Conditional(command, ZInModelUnits(*this, z));
  }
  if (transform.empty()) return m;
  const Eigen::VectorXd scale = transform.scale.head(pose_dim), offset = transform.offset.head(pose_dim);
  return m.Affine(scale.asDiagonal(), offset);
}

double MotionModel::SamplesNear(int command, const Eigen::VectorXd& z, double* at_data) const {
  if (terrain_dim == 0) throw InputError("model: fitted without terrain; no z to be near");
  const Eigen::VectorXd q = ZInModelUnits(*this, z);
  const Mixture marginal = MixtureFor(command).Marginal(Range(pose_dim, dim()));
  // The marginal's mean and covariance: sum_k p_k (S_k + mu_k mu_k^T) - mu mu^T.
  const double total = marginal.total_weight();
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(terrain_dim);
  Eigen::MatrixXd second = Eigen::MatrixXd::Zero(terrain_dim, terrain_dim);
  for (int k = 0; k < marginal.size(); ++k) {
    const Gaussian& g = marginal.component(k);
    const double p = marginal.weight(k) / total;
    mean += p * g.mean();
    second += p * (g.covariance() + g.mean() * g.mean().transpose());
  }
  const Eigen::VectorXd sd = (second - mean * mean.transpose()).diagonal().cwiseMax(0).cwiseSqrt();
  Eigen::VectorXd h2(terrain_dim);
  double log_kernel_scale = 0.5 * terrain_dim * std::log(2 * std::numbers::pi);
  for (int j = 0; j < terrain_dim; ++j) {
    const double h = std::max(0.1 * sd[j], 1e-12 * std::max(1.0, std::abs(mean[j])));
    h2[j] = h * h;
    log_kernel_scale += std::log(h);
  }
  std::vector<Gaussian> widened;
  for (int k = 0; k < marginal.size(); ++k) {
    Eigen::MatrixXd c = marginal.component(k).covariance();
    c.diagonal() += h2;
    widened.emplace_back(marginal.component(k).mean(), c);
  }
  auto near = [&](const Eigen::VectorXd& at) {
    double sum = 0;
    for (int k = 0; k < marginal.size(); ++k) {
      sum += marginal.weight(k) * std::exp(widened[k].LogDensity(at) + log_kernel_scale);
    }
    return sum;
  };
  if (at_data) {
    *at_data = 0;
    for (int k = 0; k < marginal.size(); ++k) {
      *at_data = std::max(*at_data, near(marginal.component(k).mean()));
    }
  }
  return near(q);
}

MotionModelLearner::MotionModelLearner(MotionModel header, const MotionModelOptions& options)
    : header_(std::move(header)), options_(options), rng_(options.seed) {
  std::string error;
  if (!options_.dgmm.IsValid(header_.dim(), &error)) {
    throw MakeInputError("", "dgmm options", error);
  }
  if (header_.dim() <= 0) throw MakeInputError("", "model", "has no dimensions");
}

void MotionModelLearner::Add(int command, const Eigen::Ref<const Eigen::VectorXd>& y) {
  CheckSize("sample", y.size(), header_.dim());
  if (!y.allFinite()) {
    throw MakeInputError("", "sample",
                         "has a NaN or infinite value (command " + std::to_string(command) + ")");
  }
  if (!header_.command_values.empty() && header_.command_values.count(command) == 0) {
    throw MakeInputError(
        "", "command",
        "unknown command " + std::to_string(command) + " (not in the command table)");
  }
  auto it = learners_.find(command);
  if (it == learners_.end()) {
    it = learners_.try_emplace(command, header_.dim(), options_.dgmm).first;
  }
  it->second.AddSample(y, rng_);
}

MotionModel MotionModelLearner::Finish() const {
  MotionModel model = header_;
  model.kind = "dgmm";
  model.dgmm_options = options_.dgmm;
  model.seed = options_.seed;
  model.mixtures.clear();
  model.max_components_hit.clear();
  for (const auto& [command, learner] : learners_) {
    model.mixtures[command] = learner.mixture();
    if (learner.max_components_hit()) model.max_components_hit[command] = true;
  }
  return model;
}

MotionModel ModelHeaderFor(const SampleSet& set, bool with_terrain) {
  const bool terrain = with_terrain && set.terrain_dim() > 0;
  MotionModel header;
  header.pose_dim = set.pose_dim();
  header.terrain_dim = terrain ? set.terrain_dim() : 0;
  header.pose_names = set.x_names;
  header.pose_units = set.x_units;
  if (terrain) header.terrain_names = set.z_names;
  header.command_dim_names = set.command_dim_names;
  for (int c = 0; c < set.num_commands(); ++c) {
    header.command_values[c] = set.commands.row(c).transpose();
    if (c < static_cast<int>(set.command_labels.size())) {
      header.command_labels[c] = set.command_labels[c];
    }
  }
  header.transform = set.transform;
  if (!set.source.empty()) header.metadata["training_source"] = set.source;
  return header;
}

MotionModelOptions ResolveMotionModelOptions(const SampleSet& set,
                                             const MotionModelOptions& options,
                                             std::string* warning) {
  const bool terrain = options.with_terrain && set.terrain_dim() > 0;
  return ResolveMotionModelOptions(set, options, PooledWithinCommandVariance(set, terrain),
                                   warning);
}

MotionModelOptions ResolveMotionModelOptions(const SampleSet& set,
                                             const MotionModelOptions& options,
                                             const Eigen::VectorXd& v, std::string* warning) {
  const bool terrain = options.with_terrain && set.terrain_dim() > 0;
  const int dim = set.pose_dim() + (terrain ? set.terrain_dim() : 0);
  std::string error;
  if (!options.dgmm.IsValid(&error)) throw MakeInputError("", "dgmm options", error);
  if (options.dgmm.initial_covariance_rule == DgmmOptions::InitialCovarianceRule::kUser &&
      options.dgmm.initial_covariance_diagonal.size() != dim) {
    throw MakeInputError("", "initial covariance",
                         std::to_string(options.dgmm.initial_covariance_diagonal.size()) +
                             " values for " + std::to_string(dim) + " dimensions");
  }
  std::vector<std::string> names = set.x_names;
  if (terrain) names.insert(names.end(), set.z_names.begin(), set.z_names.end());
  MotionModelOptions resolved = options;
  assert(v.size() == dim);
  resolved.dgmm = ResolveDgmmOptions(options.dgmm, v, names, warning);
  return resolved;
}

MotionModel LearnMotionModel(const SampleSet& set, const MotionModelOptions& options_in) {
  if (std::string e = set.Validate(); !e.empty()) throw MakeInputError("", "sample set", e);
  const bool terrain = options_in.with_terrain && set.terrain_dim() > 0;
  const MotionModelOptions options = ResolveMotionModelOptions(set, options_in);
  MotionModelLearner learner(ModelHeaderFor(set, options.with_terrain), options);
  Eigen::VectorXd y(learner.Finish().dim());
  for (int i = 0; i < set.size(); ++i) {
    y.head(set.pose_dim()) = set.x.row(i).transpose();
    if (terrain) y.tail(set.terrain_dim()) = set.z.row(i).transpose();
    learner.Add(set.command[i], y);
  }
  return learner.Finish();
}

int ModelCommandId(const MotionModel& model, const SampleSet& set, int index, const std::string& source) {
  if (set.command_labels.empty() || model.command_labels.empty()) return index;
  const std::string& label = set.command_labels[index];
  for (const auto& [id, l] : model.command_labels) {
    if (l == label) return id;
  }
  throw MakeInputError(source, "command", "unknown command '" + label + "' (model has: " + ListCommands(model) + ")");
}

Eigen::VectorXd ScoreSamples(const MotionModel& model, const SampleSet& set) {
  if (std::string e = set.Validate(); !e.empty()) throw MakeInputError("", "sample set", e);
  CheckSize("x", set.pose_dim(), model.pose_dim);
  const bool terrain = model.terrain_dim > 0;
  if (terrain) CheckSize("z", set.terrain_dim(), model.terrain_dim);
  const int dy = model.dim();
  // Standardisation: score in the model's units, then subtract sum log scale over pose dims
  // (the Jacobian of x_std = (x_raw - offset) / scale) to return raw-unit log densities.
  bool standardize = false;
  double log_jacobian = 0.0;
  if (model.transform.empty()) {
    if (!set.transform.empty()) {
      throw MakeInputError("", "transform",
                           "the set is standardised but the model was fitted on raw data");
    }
  } else {
    if (model.transform.offset.size() < dy || model.transform.scale.size() < dy) {
      throw MakeInputError("", "transform",
                           "the model's transform has fewer entries than "
                           "its dimensions");
    }
    if (set.transform.empty()) {
      standardize = true;
    } else if (!SameTransform(model.transform, set.transform, model.pose_dim) ||
               (terrain && !SameTransform(model.transform, set.transform, dy))) {
      throw MakeInputError("", "transform",
                           "the set was standardised differently from the model's training set");
    }
    log_jacobian = model.transform.scale.head(model.pose_dim).array().log().sum();
  }
  // Per command: the mixture over y (or x) and, with terrain, its marginal over z, so that
  // log p(x | z) = log p(x || z) - log p(z) (eq. 15 without forming the conditional).
  struct Prepared {
    const Mixture* joint = nullptr;
    Mixture marginal;  // over x (no terrain in use) or over z (terrain)
  };
  std::map<int, Prepared> prepared;
  Eigen::VectorXd scores(set.size());
  Eigen::VectorXd y(dy);
  for (int i = 0; i < set.size(); ++i) {
    const int id = ModelCommandId(model, set, set.command[i]);
    auto it = prepared.find(id);
    if (it == prepared.end()) {
      Prepared p;
      p.joint = &model.MixtureFor(id);
      p.marginal = terrain ? p.joint->Marginal(Range(model.pose_dim, dy))
                           : p.joint->Marginal(Range(0, model.pose_dim));
      it = prepared.emplace(id, std::move(p)).first;
    }
    y.head(model.pose_dim) = set.x.row(i).transpose();
    if (terrain) y.tail(model.terrain_dim) = set.z.row(i).transpose();
    if (standardize) {
      y = (y - model.transform.offset.head(dy)).cwiseQuotient(model.transform.scale.head(dy));
    }
    const double ll = terrain ? it->second.joint->LogDensity(y) -
                                    it->second.marginal.LogDensity(y.tail(model.terrain_dim))
                              : it->second.marginal.LogDensity(y);
    scores[i] = ll - log_jacobian;
  }
  return scores;
}

ScoreSummary ScoreSampleSet(const MotionModel& model, const SampleSet& set) {
  const Eigen::VectorXd scores = ScoreSamples(model, set);
  ScoreSummary summary;
  for (Eigen::Index i = 0; i < scores.size(); ++i) summary.total_log_likelihood += scores[i];
  summary.samples = set.size();
  summary.mean_log_likelihood = summary.total_log_likelihood / summary.samples;
  return summary;
}

}  // namespace dgmm
