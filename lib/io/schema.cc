#include "io/schema.h"

#include <cmath>

#include "io/hdf5_util.h"
#include "util/error.h"

namespace dgmm::io_internal {
namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

std::string Str(long long v) { return std::to_string(v); }

void CheckCount(const std::vector<std::string>& names, long long expected, const std::string& path,
                const std::string& field) {
  if (!names.empty() && static_cast<long long>(names.size()) != expected) {
    throw MakeInputError(path, field, Str(names.size()) + " entries, expected " + Str(expected));
  }
}

// Adds attributes names/units to an existing dataset.
void WriteNamesOn(hid_t file, const std::string& dataset, const std::vector<std::string>& names,
                  const std::vector<std::string>& units, const std::string& path) {
  h5::Dataset d(H5Dopen2(file, dataset.c_str(), H5P_DEFAULT));
  if (!d.valid()) throw MakeInputError(path, dataset, "cannot write (HDF5 error)");
  h5::WriteStringListAttribute(d.get(), "names", names, path);
  h5::WriteStringListAttribute(d.get(), "units", units, path);
}

void ReadNamesOf(hid_t file, const std::string& dataset, long long cols,
                 std::vector<std::string>* names, std::vector<std::string>* units,
                 const std::string& path) {
  h5::Dataset d(H5Dopen2(file, dataset.c_str(), H5P_DEFAULT));
  if (!d.valid()) throw MakeInputError(path, dataset, "cannot open (corrupt file?)");
  *names = h5::ReadStringListAttribute(d.get(), "names", path, dataset + "/names", cols);
  *units = h5::ReadStringListAttribute(d.get(), "units", path, dataset + "/units", cols);
  CheckCount(*names, cols, path, dataset + "/names");
  CheckCount(*units, cols, path, dataset + "/units");
}

// Columns of a per-sample dataset of the given rank (0 for 1-D), checked before any read: type,
// n rows (any number up to h5::kMaxRows when n < 0), at most h5::kMaxColumns columns.
long long CheckPerSample(hid_t file, const std::string& name, hid_t type, int rank, long long n,
                         const std::string& path, long long* rows = nullptr) {
  h5::DatasetSpec spec{type, std::vector<long long>(rank, -1)};
  spec.max_elements = hsize_t{1} << 40;  // memory is bounded by the stored bytes (CheckDataset)
  std::vector<hsize_t> dims = h5::DatasetDims(file, name, path);  // the dataspace only
  if (n >= 0 && static_cast<int>(dims.size()) == rank && static_cast<long long>(dims[0]) != n) {
    throw MakeInputError(path, name,
                         std::to_string(dims[0]) + " rows, expected one per sample (" +
                             std::to_string(n) + ")");
  }
  h5::OpenCheckedDataset(file, name, spec, path, &dims);
  if (rank == 2 && (dims[1] == 0 || dims[1] > h5::kMaxColumns)) {
    throw MakeInputError(path, name,
                         std::to_string(dims[1]) + " columns; 1 to " +
                             std::to_string(h5::kMaxColumns) + " expected");
  }
  if (rows) *rows = static_cast<long long>(dims[0]);
  return rank == 2 ? static_cast<long long>(dims[1]) : 0;
}

}  // namespace

void WriteTransform(hid_t file, const Standardization& transform, const std::string& path) {
  if (transform.empty()) return;
  h5::Group g = h5::CreateGroup(file, "transform", path);
  h5::WriteDoubles(g.get(), "offset", {static_cast<hsize_t>(transform.offset.size())},
                   transform.offset.data(), path);
  h5::WriteDoubles(g.get(), "scale", {static_cast<hsize_t>(transform.scale.size())},
                   transform.scale.data(), path);
}

Standardization ReadTransform(hid_t file, long long expected_dim, const std::string& path) {
  Standardization t;
  if (!h5::Exists(file, "transform")) return t;
  h5::Group g = h5::OpenGroup(file, "transform", path);
  auto offset = h5::ReadDoubles(g.get(), "offset", 1, path);
  auto scale = h5::ReadDoubles(g.get(), "scale", 1, path);
  if (static_cast<long long>(offset.data.size()) != expected_dim ||
      static_cast<long long>(scale.data.size()) != expected_dim) {
    throw MakeInputError(path, "transform",
                         "offset/scale have " + Str(offset.data.size()) + "/" +
                             Str(scale.data.size()) + " entries, expected " + Str(expected_dim));
  }
  t.offset = Eigen::Map<Eigen::VectorXd>(offset.data.data(), expected_dim);
  t.scale = Eigen::Map<Eigen::VectorXd>(scale.data.data(), expected_dim);
  if (!t.offset.allFinite() || !t.scale.allFinite() || (t.scale.array() <= 0).any()) {
    throw MakeInputError(path, "transform", "offsets must be finite and scales finite and > 0");
  }
  return t;
}

void WriteMetadata(hid_t file, const std::map<std::string, std::string>& metadata,
                   const std::string& path) {
  h5::Group g = h5::CreateGroup(file, "metadata", path);
  for (const auto& [key, value] : metadata) h5::WriteStringAttribute(g.get(), key, value, path);
}

std::map<std::string, std::string> ReadMetadata(hid_t file, const std::string& path) {
  std::map<std::string, std::string> metadata;
  if (!h5::Exists(file, "metadata")) return metadata;
  h5::Group g = h5::OpenGroup(file, "metadata", path);
  for (const std::string& key : h5::AttributeNames(g.get(), path)) {
    metadata[key] = h5::ReadStringAttribute(g.get(), key, path, "metadata/" + key);
  }
  return metadata;
}

void WriteCommandTable(hid_t group, const Eigen::MatrixXd& values,
                       const std::vector<std::string>& dim_names,
                       const std::vector<std::string>& labels, const std::string& path) {
  RowMatrix rows = values;
  h5::WriteDoubles(group, "values",
                   {static_cast<hsize_t>(values.rows()), static_cast<hsize_t>(values.cols())},
                   rows.data(), path);
  h5::Dataset d(H5Dopen2(group, "values", H5P_DEFAULT));
  h5::WriteStringListAttribute(d.get(), "dim_names", dim_names, path);
  if (!labels.empty()) h5::WriteStrings(group, "labels", labels, path);
}

void ReadCommandTable(hid_t group, const std::string& group_name, Eigen::MatrixXd* values,
                      std::vector<std::string>* dim_names, std::vector<std::string>* labels,
                      const std::string& path) {
  const std::string field = group_name + "/values";
  auto v = h5::ReadDoubles(group, "values", 2, path);
  const long long rows = static_cast<long long>(v.dims[0]);
  const long long cols = static_cast<long long>(v.dims[1]);
  *values = Eigen::Map<RowMatrix>(v.data.data(), rows, cols);
  if (!values->allFinite()) throw MakeInputError(path, field, "non-finite command value");
  h5::Dataset d(H5Dopen2(group, "values", H5P_DEFAULT));
  *dim_names =
      h5::ReadStringListAttribute(d.get(), "dim_names", path, field + "/dim_names", cols);
  CheckCount(*dim_names, cols, path, field + "/dim_names");
  labels->clear();
  if (h5::Exists(group, "labels")) *labels = h5::ReadStrings(group, "labels", path, rows);
  CheckCount(*labels, rows, path, group_name + "/labels");
}

void WriteSampleSetHeader(hid_t file, const SampleSet& header, const std::string& path) {
  h5::WriteFormat(file, "sample_set", path);
  h5::WriteStringAttribute(file, "source", header.source, path);
  h5::Group commands = h5::CreateGroup(file, "commands", path);
  WriteCommandTable(commands.get(), header.commands, header.command_dim_names,
                    header.command_labels, path);
  WriteNamesOn(file, "x", header.x_names, header.x_units, path);
  if (header.terrain_dim() > 0) WriteNamesOn(file, "z", header.z_names, header.z_units, path);
  WriteTransform(file, header.transform, path);
  WriteMetadata(file, header.metadata, path);
}

SampleSet ReadSampleSetHeader(hid_t file, const std::string& path, long long* num_samples) {
  if (h5::ReadFormat(file, path) != "sample_set") {
    throw MakeInputError(path, "dgmm_format", "is a model, expected a sample set");
  }
  SampleSet s;
  if (h5::HasAttribute(file, "source")) {
    s.source = h5::ReadStringAttribute(file, "source", path, "source");
  }
  long long n = 0;
  const long long dx = CheckPerSample(file, "x", H5T_IEEE_F64LE, 2, -1, path, &n);
  if (n == 0) throw MakeInputError(path, "x", "0 rows; a sample set needs at least one sample");
  CheckPerSample(file, "command", H5T_STD_I32LE, 1, n, path);
  long long dz = 0;
  if (h5::Exists(file, "z")) dz = CheckPerSample(file, "z", H5T_IEEE_F64LE, 2, n, path);
  bool has_episode = h5::Exists(file, "episode"), has_step = h5::Exists(file, "step");
  if (has_episode != has_step) {
    throw MakeInputError(path, has_episode ? "step" : "episode",
                         "missing (episode and step come together)");
  }
  if (has_episode) {
    CheckPerSample(file, "episode", H5T_STD_I32LE, 1, n, path);
    CheckPerSample(file, "step", H5T_STD_I32LE, 1, n, path);
  }
  h5::Group commands = h5::OpenGroup(file, "commands", path);
  ReadCommandTable(commands.get(), "commands", &s.commands, &s.command_dim_names, &s.command_labels,
                   path);
  if (s.commands.rows() == 0) throw MakeInputError(path, "commands/values", "no commands");
  ReadNamesOf(file, "x", dx, &s.x_names, &s.x_units, path);
  s.x.resize(0, dx);
  s.z.resize(0, dz);
  if (dz > 0) ReadNamesOf(file, "z", dz, &s.z_names, &s.z_units, path);
  s.transform = ReadTransform(file, dx + dz, path);
  s.metadata = ReadMetadata(file, path);
  *num_samples = n;
  return s;
}

}  // namespace dgmm::io_internal
