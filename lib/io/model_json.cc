// JSON export of a motion model (schema in docs/file-format.md, "JSON export").
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "io/model_io.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace dgmm {
namespace {

using nlohmann::json;

json Vector(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

json Matrix(const Eigen::MatrixXd& m) {
  json rows = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) rows.push_back(Vector(m.row(r).transpose()));
  return rows;
}

// Means (K x d) and covariances (K x d x d) of the components, optionally mapped by
// y_raw = offset + scale .* y, i.e. mean -> offset + scale .* mean, S -> D S D, D = diag(scale).
void Components(const Mixture& mixture, const Standardization* to_raw, int dim, json* means,
                json* covariances) {
  *means = json::array();
  *covariances = json::array();
  for (const Gaussian& g : mixture.components()) {
    Eigen::VectorXd mean = g.mean();
    Eigen::MatrixXd cov = g.covariance();
    if (to_raw) {
      const Eigen::VectorXd scale = to_raw->scale.head(dim);
      mean = to_raw->offset.head(dim) + scale.cwiseProduct(mean);
      cov = scale.asDiagonal() * cov * scale.asDiagonal();
    }
    means->push_back(Vector(mean));
    covariances->push_back(Matrix(cov));
  }
}

}  // namespace

json DgmmOptionsJson(const DgmmOptions& o) {
  const bool prior = o.covariance_rule == DgmmOptions::CovarianceRule::kPrior;
  return {{"variant", VariantName(o.variant)},
          {"k", o.k},
          {"covariance_rule", CovarianceRuleName(o.covariance_rule)},
          {"prior_pseudo_count", prior ? o.prior_pseudo_count : 0.0},
          {"initial_covariance_rule", InitialCovarianceRuleName(o.initial_covariance_rule)},
          {"initial_covariance_fraction", o.initial_covariance_fraction},
          {"initial_covariance_diagonal", Vector(o.initial_covariance_diagonal)},
          {"covariance_floor", o.covariance_floor},
          {"covariance_floor_relative", o.covariance_floor_relative}};
}

void WriteModelJson(const MotionModel& model, const std::string& path) {
  json j;
  j["dgmm_format"] = "model";
  j["dgmm_format_version"] = 1;
  j["kind"] = model.kind;
  j["pose_dim"] = model.pose_dim;
  j["terrain_dim"] = model.terrain_dim;
  j["pose_names"] = model.pose_names;
  j["pose_units"] = model.pose_units;
  j["terrain_names"] = model.terrain_names;
  j["command_dim_names"] = model.command_dim_names;
  j["seed"] = model.seed;
  const DgmmOptions& o = model.dgmm_options;
  j["dgmm_options"] = DgmmOptionsJson(o);
  const bool has_transform = !model.transform.empty();
  if (has_transform &&
      (model.transform.offset.size() < model.dim() || model.transform.scale.size() < model.dim())) {
    throw MakeInputError(path, "transform", "has fewer entries than the model's dimensions");
  }
  j["transform"] = has_transform ? json{{"offset", Vector(model.transform.offset)},
                                        {"scale", Vector(model.transform.scale)}}
                                 : json(nullptr);
  j["metadata"] = model.metadata;

  std::set<int> ids;
  for (const auto& [id, v] : model.command_values) ids.insert(id);
  for (const auto& [id, m] : model.mixtures) ids.insert(id);
  json commands = json::array();
  for (int id : ids) {
    json c;
    c["id"] = id;
    auto label = model.command_labels.find(id);
    c["label"] = label == model.command_labels.end() ? std::to_string(id) : label->second;
    auto values = model.command_values.find(id);
    c["values"] = values == model.command_values.end() ? json::array() : Vector(values->second);
    auto it = model.mixtures.find(id);
    const Mixture empty(model.dim());
    const Mixture& mixture = it == model.mixtures.end() ? empty : it->second;
    const double total = mixture.empty() ? 0.0 : mixture.total_weight();
    json normalised = json::array();
    for (double w : mixture.weights()) normalised.push_back(w / total);
    c["num_components"] = mixture.size();
    c["raw_weights"] = mixture.weights();
    c["weights"] = normalised;
    Components(mixture, nullptr, model.dim(), &c["means"], &c["covariances"]);
    if (has_transform) {
      json raw;
      Components(mixture, &model.transform, model.dim(), &raw["means"], &raw["covariances"]);
      c["raw_units"] = raw;
    }
    commands.push_back(c);
  }
  j["commands"] = commands;

  AtomicFile output(path);
  {
    std::ofstream out(output.temp_path());
    out << j.dump(2) << "\n";
    out.close();
    if (!out) throw MakeInputError(path, "", "cannot write (disk full?)");
  }
  output.Commit();
}

}  // namespace dgmm
