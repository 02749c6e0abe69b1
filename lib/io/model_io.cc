// Motion models as HDF5 (schema: docs/file-format.md). JSON export is in model_json.cc.
#include "io/model_io.h"

#include <cmath>
#include <cstdio>

#include "io/hdf5_util.h"
#include "io/schema.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace dgmm {
namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

std::string Str(long long v) { return std::to_string(v); }

// A double as printf's %.3g would print it (1e+308, 0.5, nan).
std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// Command table of the model: ids (sorted), values and labels. Labels are either absent or
// given for every id that has values.
void WriteModelCommands(hid_t file, const MotionModel& model, const std::string& path) {
  const std::string field = "commands";
  std::vector<int> ids;
  long long dc = -1;
  for (const auto& [id, values] : model.command_values) {
    ids.push_back(id);
    if (dc >= 0 && values.size() != dc) {
      throw MakeInputError(path, field, "command rows have different lengths");
    }
    dc = values.size();
  }
  for (const auto& [id, label] : model.command_labels) {
    if (model.command_values.count(id) == 0) {
      throw MakeInputError(path, field, "label for command " + Str(id) + " without values");
    }
  }
  if (!model.command_labels.empty() && model.command_labels.size() != ids.size()) {
    throw MakeInputError(path, field, "labels must be given for every command or none");
  }
  Eigen::MatrixXd values(static_cast<Eigen::Index>(ids.size()), std::max<long long>(dc, 0));
  std::vector<std::string> labels;
  for (size_t r = 0; r < ids.size(); ++r) {
    values.row(r) = model.command_values.at(ids[r]).transpose();
    if (!model.command_labels.empty()) labels.push_back(model.command_labels.at(ids[r]));
  }
  h5::Group g = h5::CreateGroup(file, field, path);
  h5::WriteInts(g.get(), "ids", {static_cast<hsize_t>(ids.size())}, ids.data(), path);
  io_internal::WriteCommandTable(g.get(), values, model.command_dim_names, labels, path);
}

void ReadModelCommands(hid_t file, MotionModel* model, const std::string& path) {
  h5::Group g = h5::OpenGroup(file, "commands", path);
  auto ids = h5::ReadInts(g.get(), "ids", 1, path);
  Eigen::MatrixXd values;
  std::vector<std::string> labels;
  io_internal::ReadCommandTable(g.get(), "commands", &values, &model->command_dim_names, &labels,
                                path);
  if (values.rows() != static_cast<Eigen::Index>(ids.data.size())) {
    throw MakeInputError(path, "commands/ids",
                         Str(ids.data.size()) + " ids for " + Str(values.rows()) + " rows");
  }
  for (size_t r = 0; r < ids.data.size(); ++r) {
    model->command_values[ids.data[r]] = values.row(r).transpose();
    if (!labels.empty()) model->command_labels[ids.data[r]] = labels[r];
  }
}

void WriteMixture(hid_t parent, int id, const Mixture& mixture, int dim, bool capped,
                  const std::string& path) {
  const std::string field = "mixtures/" + Str(id);
  if (mixture.dim() != dim && !mixture.empty()) {
    throw MakeInputError(path, field,
                         "has " + Str(mixture.dim()) + " dimensions, the model " + Str(dim));
  }
  const hsize_t k = mixture.size(), d = dim;
  std::vector<double> weights(mixture.weights());
  std::vector<double> means(k * d), covariances(k * d * d);
  for (hsize_t i = 0; i < k; ++i) {
    const Gaussian& g = mixture.component(static_cast<int>(i));
    for (hsize_t a = 0; a < d; ++a) {
      means[i * d + a] = g.mean()[a];
      for (hsize_t b = 0; b < d; ++b) covariances[(i * d + a) * d + b] = g.covariance()(a, b);
    }
  }
  h5::Group g = h5::CreateGroup(parent, Str(id), path);
  h5::WriteInt64Attribute(g.get(), "command_id", id, path);
  h5::WriteInt64Attribute(g.get(), "num_components", static_cast<std::int64_t>(k), path);
  if (capped) h5::WriteInt64Attribute(g.get(), "max_components_hit", 1, path);
  h5::WriteDoubles(g.get(), "weights", {k}, weights.data(), path);
  h5::WriteDoubles(g.get(), "means", {k, d}, means.data(), path);
  h5::WriteDoubles(g.get(), "covariances", {k, d, d}, covariances.data(), path);
}

// Largest |C - C^T| relative to the largest |C| entry (0 for a symmetric matrix).
double RelativeAsymmetry(const Eigen::MatrixXd& c) {
  const double scale = c.cwiseAbs().maxCoeff();
  if (!(scale > 0)) return 0;
  return (c - c.transpose()).cwiseAbs().maxCoeff() / scale;
}

// One mixture, every dataset checked against (K, d) / (K, d, d) before it is read; covariances
// as stored must be symmetric (kMaxRelativeAsymmetry) and positive definite.
Mixture ReadMixture(hid_t parent, const std::string& name, int dim, const std::string& path) {
  constexpr double kMaxRelativeAsymmetry = 1e-12;  // docs/file-format.md, version 2
  const std::string field = "mixtures/" + name;
  h5::Group g = h5::OpenGroup(parent, name, path);
  auto weights = h5::ReadDoubles(g.get(), "weights", 1, path);
  const long long k = static_cast<long long>(weights.dims[0]), d = dim;
  if (k == 0) {
    throw MakeInputError(path, field + "/weights", "0 components; at least one expected");
  }
  if (h5::HasAttribute(g.get(), "num_components") &&
      h5::ReadInt64Attribute(g.get(), "num_components", path, field + "/num_components") != k) {
    throw MakeInputError(path, field + "/num_components",
                         "differs from the " + Str(k) + " weights");
  }
  if (static_cast<double>(k) * d * d > static_cast<double>(h5::kMaxDenseElements)) {
    throw MakeInputError(path, field,
                         Str(k) + " components of dimension " + Str(d) + "; at most " +
                             Str(h5::kMaxDenseElements) + " covariance entries expected");
  }
  auto means = h5::ReadDoubles(g.get(), "means", {k, d}, path);
  auto covariances = h5::ReadDoubles(g.get(), "covariances", {k, d, d}, path);
  Mixture mixture(dim);
  double total = 0;
  for (long long i = 0; i < k; ++i) {
    const double w = weights.data[i];
    total += w;
    if (!std::isfinite(w) || w <= 0 || !std::isfinite(total)) {
      throw MakeInputError(path, field + "/weights",
                           "component " + Str(i) + " has weight " + Num(w) +
                               (std::isfinite(total) ? "" : " (the sum overflows)") +
                               ", expected finite and > 0 with a finite sum");
    }
    Eigen::VectorXd mean = Eigen::Map<Eigen::VectorXd>(means.data.data() + i * d, dim);
    Eigen::MatrixXd cov = Eigen::Map<RowMatrix>(covariances.data.data() + i * d * d, dim, dim);
    if (!cov.allFinite()) {
      throw MakeInputError(path, field + "/covariances",
                           "component " + Str(i) + " is not finite");
    }
    if (const double a = RelativeAsymmetry(cov); a > kMaxRelativeAsymmetry) {
      throw MakeInputError(path, field + "/covariances",
                           "component " + Str(i) + " is not symmetric (relative asymmetry " +
                               Num(a) + ", at most 1e-12 expected)");
    }
    auto gaussian = Gaussian::Create(std::move(mean), std::move(cov));
    if (!gaussian) {
      throw MakeInputError(
          path, field,
          "component " + Str(i) + ": mean not finite or covariance not positive definite");
    }
    mixture.Add(w, *std::move(gaussian));
  }
  return mixture;
}

void WriteOptions(hid_t file, const DgmmOptions& o, const std::string& path) {
  h5::Group g = h5::CreateGroup(file, "dgmm_options", path);
  h5::WriteStringAttribute(g.get(), "variant", VariantName(o.variant), path);
  h5::WriteDoubleAttribute(g.get(), "k", o.k, path);
  h5::WriteDoubleAttribute(g.get(), "covariance_floor", o.covariance_floor, path);
  h5::WriteDoubleAttribute(g.get(), "covariance_floor_relative", o.covariance_floor_relative, path);
  h5::WriteStringAttribute(g.get(), "covariance_rule", CovarianceRuleName(o.covariance_rule), path);
  const bool prior = o.covariance_rule == DgmmOptions::CovarianceRule::kPrior;
  h5::WriteDoubleAttribute(g.get(), "prior_pseudo_count", prior ? o.prior_pseudo_count : 0.0, path);
  h5::WriteStringAttribute(g.get(), "initial_covariance_rule",
                           InitialCovarianceRuleName(o.initial_covariance_rule), path);
  h5::WriteDoubleAttribute(g.get(), "initial_covariance_fraction", o.initial_covariance_fraction,
                           path);
  const hsize_t n = o.initial_covariance_diagonal.size();
  h5::WriteDoubles(g.get(), "initial_covariance_diagonal", {n},
                   o.initial_covariance_diagonal.data(), path);
}

// A string attribute parsed by `parse`; absent (a file written before issue #10): `fallback`.
template <typename T, typename Parse>
T ReadRule(hid_t g, const char* name, const std::string& path, const char* expected, T fallback,
           Parse parse) {
  if (!h5::HasAttribute(g, name)) return fallback;
  const std::string field = std::string("dgmm_options/") + name;
  const std::string value = h5::ReadStringAttribute(g, name, path, field);
  if (auto parsed = parse(value)) return *parsed;
  throw MakeInputError(path, field, "'" + value + "', expected " + expected);
}

// An optional float64 attribute; absent: `fallback`.
double ReadOptionalDouble(hid_t g, const char* name, const std::string& path, double fallback) {
  if (!h5::HasAttribute(g, name)) return fallback;
  return h5::ReadDoubleAttribute(g, name, path, std::string("dgmm_options/") + name);
}

DgmmOptions ReadOptions(hid_t file, const std::string& path) {
  DgmmOptions o;
  h5::Group g = h5::OpenGroup(file, "dgmm_options", path);
  o.variant = ReadRule(g.get(), "variant", path, "faithful or improved",
                       DgmmOptions::Variant::kFaithful, ParseVariant);
  o.k = h5::ReadDoubleAttribute(g.get(), "k", path, "dgmm_options/k");
  o.covariance_floor =
      h5::ReadDoubleAttribute(g.get(), "covariance_floor", path, "dgmm_options/covariance_floor");
  // Items of issue #10; a model written before them used the blend, identity S0 and an
  // absolute floor.
  o.covariance_floor_relative = ReadOptionalDouble(g.get(), "covariance_floor_relative", path, 0);
  o.covariance_rule = ReadRule(g.get(), "covariance_rule", path, "literal, blend or prior",
                               DgmmOptions::CovarianceRule::kBlend, ParseCovarianceRule);
  o.prior_pseudo_count = ReadOptionalDouble(g.get(), "prior_pseudo_count", path, 0);
  o.initial_covariance_rule =
      ReadRule(g.get(), "initial_covariance_rule", path, "identity, data or user",
               DgmmOptions::InitialCovarianceRule::kIdentity, ParseInitialCovarianceRule);
  o.initial_covariance_fraction = ReadOptionalDouble(g.get(), "initial_covariance_fraction", path,
                                                     o.initial_covariance_fraction);
  auto diag = h5::ReadDoubles(g.get(), "initial_covariance_diagonal", 1, path);
  o.initial_covariance_diagonal =
      Eigen::Map<Eigen::VectorXd>(diag.data.data(), static_cast<Eigen::Index>(diag.data.size()));
  if (!std::isfinite(o.k) || o.k <= 0) {
    throw MakeInputError(path, "dgmm_options/k", Num(o.k) + ", expected finite and > 0");
  }
  if (!std::isfinite(o.covariance_floor) || o.covariance_floor < 0) {
    throw MakeInputError(path, "dgmm_options/covariance_floor",
                         Num(o.covariance_floor) + ", expected finite and >= 0");
  }
  if (!o.initial_covariance_diagonal.allFinite() ||
      (o.initial_covariance_diagonal.array() <= 0).any()) {
    throw MakeInputError(path, "dgmm_options/initial_covariance_diagonal",
                         "expected finite values > 0");
  }
  if (o.covariance_rule != DgmmOptions::CovarianceRule::kPrior) o.prior_pseudo_count = 1.0;
  std::string error;
  if (!o.IsValid(&error)) throw MakeInputError(path, "dgmm_options", error);
  return o;
}

}  // namespace

void WriteModel(const MotionModel& model, const std::string& path) {
  if (model.pose_dim <= 0 || model.terrain_dim < 0) {
    throw MakeInputError(path, "pose_dim", "a model needs at least one pose dimension");
  }
  if (!model.transform.empty() &&
      (model.transform.offset.size() < model.dim() || model.transform.scale.size() < model.dim())) {
    throw MakeInputError(path, "transform", "has fewer entries than the model's dimensions");
  }
  h5::Init();
  AtomicFile output(path);
  {
    h5::File file = h5::CreateFile(output.temp_path().string(), path);
    const hid_t f = file.get();
    h5::WriteFormat(f, "model", path);
    h5::WriteStringAttribute(f, "kind", model.kind, path);
    h5::WriteInt64Attribute(f, "pose_dim", model.pose_dim, path);
    h5::WriteInt64Attribute(f, "terrain_dim", model.terrain_dim, path);
    h5::WriteUint64Attribute(f, "seed", model.seed, path);
    h5::WriteStringListAttribute(f, "pose_names", model.pose_names, path);
    h5::WriteStringListAttribute(f, "pose_units", model.pose_units, path);
    h5::WriteStringListAttribute(f, "terrain_names", model.terrain_names, path);
    WriteModelCommands(f, model, path);
    h5::Group mixtures = h5::CreateGroup(f, "mixtures", path);
    for (const auto& [id, mixture] : model.mixtures) {
      auto hit = model.max_components_hit.find(id);
      WriteMixture(mixtures.get(), id, mixture, model.dim(),
                   hit != model.max_components_hit.end() && hit->second, path);
    }
    WriteOptions(f, model.dgmm_options, path);
    Standardization t = model.transform;
    io_internal::WriteTransform(f, t, path);
    io_internal::WriteMetadata(f, model.metadata, path);
    if (H5Fflush(f, H5F_SCOPE_GLOBAL) < 0) {
      throw MakeInputError(path, "", "cannot write (disk full?)");
    }
  }
  output.Commit();
}

MotionModel ReadModel(const std::string& path) {
  h5::File file = h5::OpenFile(path);
  const hid_t f = file.get();
  if (h5::ReadFormat(f, path) != "model") {
    throw MakeInputError(path, "dgmm_format", "is a sample set, expected a model");
  }
  MotionModel model;
  model.kind = h5::ReadStringAttribute(f, "kind", path, "kind");
  const std::int64_t pose_dim = h5::ReadInt64Attribute(f, "pose_dim", path, "pose_dim");
  const std::int64_t terrain_dim = h5::ReadInt64Attribute(f, "terrain_dim", path, "terrain_dim");
  if (pose_dim <= 0 || terrain_dim < 0 || pose_dim + terrain_dim > 10000) {
    throw MakeInputError(path, "pose_dim",
                         "invalid dimensions " + Str(pose_dim) + "+" + Str(terrain_dim));
  }
  model.pose_dim = static_cast<int>(pose_dim);
  model.terrain_dim = static_cast<int>(terrain_dim);
  model.seed = h5::ReadUint64Attribute(f, "seed", path, "seed");
  model.pose_names = h5::ReadStringListAttribute(f, "pose_names", path, "pose_names");
  model.pose_units = h5::ReadStringListAttribute(f, "pose_units", path, "pose_units");
  model.terrain_names = h5::ReadStringListAttribute(f, "terrain_names", path, "terrain_names");
  ReadModelCommands(f, &model, path);
  h5::Group mixtures = h5::OpenGroup(f, "mixtures", path);
  for (const std::string& name : h5::LinkNames(mixtures.get(), path)) {
    const std::string field = "mixtures/" + name;
    h5::Group g = h5::OpenGroup(mixtures.get(), name, path);
    const std::int64_t id = h5::ReadInt64Attribute(g.get(), "command_id", path, field + "/command_id");
    if (model.command_values.count(static_cast<int>(id)) == 0 || id != static_cast<int>(id) ||
        model.mixtures.count(static_cast<int>(id)) > 0) {
      throw MakeInputError(path, field + "/command_id",
                           Str(id) + " is not a unique id of /commands/ids");
    }
    model.mixtures[static_cast<int>(id)] = ReadMixture(mixtures.get(), name, model.dim(), path);
    if (h5::HasAttribute(g.get(), "max_components_hit")) {
      const std::int64_t hit =
          h5::ReadInt64Attribute(g.get(), "max_components_hit", path, field + "/max_components_hit");
      if (hit != 0 && hit != 1) {
        throw MakeInputError(path, field + "/max_components_hit", Str(hit) + ", expected 0 or 1");
      }
      model.max_components_hit[static_cast<int>(id)] = hit == 1;
    }
  }
  if (model.mixtures.empty()) {
    throw MakeInputError(path, "mixtures", "none; a model needs at least one mixture");
  }
  model.dgmm_options = ReadOptions(f, path);
  if (h5::Exists(f, "transform")) {
    auto dims = h5::DatasetDims(f, "transform/offset", path);
    const long long n = dims.empty() ? 0 : static_cast<long long>(dims[0]);
    if (n < model.dim()) {
      throw MakeInputError(path, "transform", "has fewer entries than the model's dimensions");
    }
    model.transform = io_internal::ReadTransform(f, n, path);
  }
  model.metadata = io_internal::ReadMetadata(f, path);
  return model;
}

}  // namespace dgmm
