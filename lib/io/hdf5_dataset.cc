// Datasets: small dense tables, strings, and chunked per-sample arrays read by hyperslab.
#include <algorithm>
#include <cstdio>

#include "io/hdf5_util.h"
#include "util/error.h"

namespace dgmm::h5 {

namespace {

PropertyList NoTimesDatasetPlist() {
  PropertyList p(H5Pcreate(H5P_DATASET_CREATE));
  H5Pset_obj_track_times(p.get(), false);  // same content, same bytes
  return p;
}

void WriteDense(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims,
                hid_t file_type, hid_t mem_type, const void* data, const std::string& path) {
  Dataspace space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr));
  PropertyList dcpl = NoTimesDatasetPlist();
  Dataset d(
      H5Dcreate2(loc, name.c_str(), file_type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT));
  if (!d.valid()) WriteFailed(path, name);
  hsize_t n = 1;
  for (hsize_t v : dims) n *= v;
  if (n > 0 && H5Dwrite(d.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    WriteFailed(path, name);
  }
}

Dataset OpenDataset(hid_t loc, const std::string& name, const std::string& path) {
  if (!Exists(loc, name)) throw MakeInputError(path, name, "dataset missing");
  H5O_info_t info{};
  if (H5Oget_info_by_name2(loc, name.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT) < 0 ||
      info.type != H5O_TYPE_DATASET) {
    throw MakeInputError(path, name, "not a dataset or corrupt");
  }
  Dataset d(H5Dopen2(loc, name.c_str(), H5P_DEFAULT));
  if (!d.valid()) throw MakeInputError(path, name, "not a dataset or corrupt");
  return d;
}

std::vector<hsize_t> DimsOf(hid_t dataset) {
  Dataspace space(H5Dget_space(dataset));
  int rank = H5Sget_simple_extent_ndims(space.get());
  std::vector<hsize_t> dims(std::max(rank, 0));
  if (rank > 0) H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  return dims;
}

std::string DimsText(const std::vector<hsize_t>& dims) {
  std::string s = "(";
  for (size_t i = 0; i < dims.size(); ++i) s += (i ? ", " : "") + std::to_string(dims[i]);
  return s + ")";
}

template <typename T>
std::vector<T> ReadAll(hid_t loc, const std::string& name, const std::vector<long long>& extents,
                       hid_t file_type, hid_t mem_type, std::vector<hsize_t>* dims,
                       const std::string& path) {
  DatasetSpec spec{file_type, extents};
  Dataset d = OpenCheckedDataset(loc, name, spec, path, dims);
  hsize_t n = 1;
  for (hsize_t v : *dims) n *= v;
  std::vector<T> data(n);
  if (n > 0 && H5Dread(d.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0) {
    throw MakeInputError(path, name, "cannot read (truncated or corrupt file)");
  }
  return data;
}

// Filters dgmm writes (shuffle, deflate) or h5py users may add (fletcher32); others refused.
bool KnownFilter(H5Z_filter_t f) {
  return f == H5Z_FILTER_DEFLATE || f == H5Z_FILTER_SHUFFLE || f == H5Z_FILTER_FLETCHER32;
}

}  // namespace

void WriteDoubles(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims,
                  const double* data, const std::string& path) {
  WriteDense(loc, name, dims, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, data, path);
}

void WriteInts(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims,
               const int* data, const std::string& path) {
  WriteDense(loc, name, dims, H5T_STD_I32LE, H5T_NATIVE_INT, data, path);
}

DoubleArray ReadDoubles(hid_t loc, const std::string& name, int rank, const std::string& path) {
  DoubleArray a;
  return ReadDoubles(loc, name, std::vector<long long>(std::max(rank, 0), -1), path);
}

DoubleArray ReadDoubles(hid_t loc, const std::string& name, const std::vector<long long>& extents,
                        const std::string& path) {
  DoubleArray a;
  a.data = ReadAll<double>(loc, name, extents, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &a.dims, path);
  return a;
}

IntArray ReadInts(hid_t loc, const std::string& name, int rank, const std::string& path) {
  IntArray a;
  a.data = ReadAll<int>(loc, name, std::vector<long long>(std::max(rank, 0), -1), H5T_STD_I32LE,
                        H5T_NATIVE_INT, &a.dims, path);
  return a;
}

std::vector<std::string> ReadStrings(hid_t loc, const std::string& name, const std::string& path,
                                     long long expected_count) {
  Dataset d = OpenDataset(loc, name, path);
  return ReadStringsFromDataset(d.get(), path, name, expected_count);
}

std::vector<hsize_t> DatasetDims(hid_t loc, const std::string& name, const std::string& path) {
  Dataset d = OpenDataset(loc, name, path);
  return DimsOf(d.get());
}

namespace {

// The element type the schema expects.
void CheckType(hid_t dataset, const DatasetSpec& spec, bool is_double, const std::string& path,
               const std::string& field) {
  Datatype type(H5Dget_type(dataset));
  if (!type.valid() || H5Tequal(type.get(), spec.type) <= 0) {
    throw MakeInputError(path, field,
                         std::string("expected ") +
                             (is_double ? "float64 little-endian numbers"
                                        : "int32 little-endian integers") +
                             (type.valid() && H5Tget_class(type.get()) == H5T_STRING
                                  ? ", found strings"
                                  : ""));
  }
}

// The shape against the schema's rank and extents, with overflow-safe element count (returned in
// *elements).
std::vector<hsize_t> CheckShape(hid_t dataset, const DatasetSpec& spec, const std::string& path,
                                const std::string& field, long double* elements) {
  Dataspace space(H5Dget_space(dataset));
  const int rank = space.valid() ? H5Sget_simple_extent_ndims(space.get()) : -1;
  if (rank < 0 || rank > 32) throw MakeInputError(path, field, "corrupt dataspace");
  std::vector<hsize_t> dims(rank);
  if (rank > 0) H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  if (rank != static_cast<int>(spec.extents.size())) {
    throw MakeInputError(path, field,
                         "expected " + std::to_string(spec.extents.size()) +
                             " dimensions, found shape " + DimsText(dims));
  }
  *elements = 1;
  for (int i = 0; i < rank; ++i) {
    if (spec.extents[i] >= 0 && dims[i] != static_cast<hsize_t>(spec.extents[i])) {
      throw MakeInputError(path, field,
                           "shape " + DimsText(dims) + ": dimension " + std::to_string(i) +
                               " should be " + std::to_string(spec.extents[i]));
    }
    if (dims[i] > spec.max_extent) {
      throw MakeInputError(path, field,
                           "shape " + DimsText(dims) + ": at most " +
                               std::to_string(spec.max_extent) + " per dimension expected");
    }
    *elements *= static_cast<long double>(dims[i]);
  }
  if (*elements > static_cast<long double>(spec.max_elements)) {
    char declared[32];
    std::snprintf(declared, sizeof declared, "%.3Lg", *elements);
    throw MakeInputError(path, field,
                         "declares shape " + DimsText(dims) + " (" + declared +
                             " values); at most " + std::to_string(spec.max_elements) +
                             " expected");
  }
  return dims;
}

// Chunks of the dataset's rank and bounded size, and only the filters we read.
void CheckChunks(hid_t dcpl, int rank, bool is_double, const std::string& path, const std::string& field) {
  hsize_t chunk[32];
  const int chunk_rank = H5Pget_chunk(dcpl, 32, chunk);
  long double chunk_bytes = is_double ? 8 : 4;
  for (int i = 0; i < chunk_rank; ++i) chunk_bytes *= static_cast<long double>(chunk[i]);
  if (chunk_rank != rank || chunk_bytes <= 0 || chunk_bytes > static_cast<long double>(kMaxChunkBytes)) {
    throw MakeInputError(path, field,
                         "chunks of rank " + std::to_string(chunk_rank) + " and " +
                             std::to_string(static_cast<unsigned long long>(chunk_bytes)) +
                             " bytes; rank " + std::to_string(rank) + " and at most " +
                             std::to_string(kMaxChunkBytes) + " bytes expected");
  }
  const int filters = H5Pget_nfilters(dcpl);
  if (filters < 0 || filters > 8) throw MakeInputError(path, field, "corrupt filter pipeline");
  for (int i = 0; i < filters; ++i) {
    unsigned flags = 0;
    size_t nelmts = 0;
    H5Z_filter_t id = H5Pget_filter2(dcpl, i, &flags, &nelmts, nullptr, 0, nullptr, nullptr);
    if (!KnownFilter(id)) {
      throw MakeInputError(path, field,
                           "uses HDF5 filter " + std::to_string(id) +
                               "; expected only shuffle, deflate or fletcher32");
    }
  }
}

// Storage in the file, in a layout we read, holding at least what the shape declares (compressed
// at most kMaxCompressionRatio : 1), so a few corrupt bytes cannot ask for gigabytes.
void CheckStorage(hid_t dataset, int rank, hsize_t raw_bytes, bool is_double, const std::string& path,
                  const std::string& field) {
  PropertyList dcpl(H5Dget_create_plist(dataset));
  if (!dcpl.valid()) throw MakeInputError(path, field, "corrupt dataset properties");
  if (H5Pget_external_count(dcpl.get()) != 0) {
    throw MakeInputError(path, field, "stored in external files; expected the data in the file");
  }
  const H5D_layout_t layout = H5Pget_layout(dcpl.get());
  if (layout == H5D_CHUNKED) {
    CheckChunks(dcpl.get(), rank, is_double, path, field);
  } else if (layout != H5D_CONTIGUOUS && layout != H5D_COMPACT) {
    throw MakeInputError(path, field, "unsupported storage layout (virtual?)");
  }
  const hsize_t stored = H5Dget_storage_size(dataset);
  const bool plausible =
      layout == H5D_CHUNKED
          ? raw_bytes <= stored * kMaxCompressionRatio + kStorageSlackBytes
          : layout == H5D_COMPACT || raw_bytes == 0 || stored >= raw_bytes;
  if (!plausible) {
    throw MakeInputError(path, field,
                         "declares " + std::to_string(raw_bytes) + " bytes but stores " +
                             std::to_string(stored) + " (truncated or corrupt file)");
  }
}

}  // namespace

std::vector<hsize_t> CheckDataset(hid_t dataset, const DatasetSpec& spec, const std::string& path,
                                  const std::string& field) {
  const bool is_double = H5Tequal(spec.type, H5T_IEEE_F64LE) > 0;
  CheckType(dataset, spec, is_double, path, field);
  long double elements = 1;
  std::vector<hsize_t> dims = CheckShape(dataset, spec, path, field, &elements);
  const hsize_t raw_bytes = static_cast<hsize_t>(elements) * (is_double ? 8 : 4);
  CheckStorage(dataset, static_cast<int>(dims.size()), raw_bytes, is_double, path, field);
  return dims;
}

Dataset OpenCheckedDataset(hid_t loc, const std::string& name, const DatasetSpec& spec,
                           const std::string& path, std::vector<hsize_t>* dims) {
  Dataset d = OpenDataset(loc, name, path);
  std::vector<hsize_t> checked = CheckDataset(d.get(), spec, path, name);
  if (dims) *dims = std::move(checked);
  return d;
}

RowAppender::RowAppender(hid_t loc, const std::string& name, bool is_double, hsize_t cols,
                         hsize_t chunk_rows, const std::string& path)
    : is_double_(is_double), cols_(cols), name_(name), path_(path) {
  int rank = cols == 0 ? 1 : 2;
  hsize_t dims[2] = {0, cols}, maxdims[2] = {H5S_UNLIMITED, cols};
  hsize_t chunk[2] = {std::max<hsize_t>(chunk_rows, 1), std::max<hsize_t>(cols, 1)};
  Dataspace space(H5Screate_simple(rank, dims, maxdims));
  PropertyList dcpl = NoTimesDatasetPlist();
  H5Pset_chunk(dcpl.get(), rank, chunk);
  H5Pset_shuffle(dcpl.get());
  H5Pset_deflate(dcpl.get(), 4);
  hid_t type = is_double ? H5T_IEEE_F64LE : H5T_STD_I32LE;
  dataset_ = Dataset(
      H5Dcreate2(loc, name.c_str(), type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT));
  if (!dataset_.valid()) WriteFailed(path, name);
}

void RowAppender::Append(const void* data, hsize_t rows) {
  if (rows == 0) return;
  int rank = cols_ == 0 ? 1 : 2;
  hsize_t new_dims[2] = {rows_ + rows, cols_};
  if (H5Dset_extent(dataset_.get(), new_dims) < 0) WriteFailed(path_, name_);
  Dataspace file_space(H5Dget_space(dataset_.get()));
  hsize_t start[2] = {rows_, 0}, count[2] = {rows, cols_};
  H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr);
  Dataspace mem_space(H5Screate_simple(rank, count, nullptr));
  hid_t mem_type = is_double_ ? H5T_NATIVE_DOUBLE : H5T_NATIVE_INT;
  if (H5Dwrite(dataset_.get(), mem_type, mem_space.get(), file_space.get(), H5P_DEFAULT, data) <
      0) {
    WriteFailed(path_, name_);
  }
  rows_ += rows;
}

void ReadRows(hid_t dataset, bool is_double, hsize_t start, hsize_t count, hsize_t cols, void* out,
              const std::string& path, const std::string& field) {
  if (count == 0) return;
  int rank = cols == 0 ? 1 : 2;
  Dataspace file_space(H5Dget_space(dataset));
  hsize_t offset[2] = {start, 0}, extent[2] = {count, cols};
  if (H5Sselect_hyperslab(file_space.get(), H5S_SELECT_SET, offset, nullptr, extent, nullptr) < 0) {
    throw MakeInputError(path, field, "rows out of range");
  }
  Dataspace mem_space(H5Screate_simple(rank, extent, nullptr));
  hid_t mem_type = is_double ? H5T_NATIVE_DOUBLE : H5T_NATIVE_INT;
  if (H5Dread(dataset, mem_type, mem_space.get(), file_space.get(), H5P_DEFAULT, out) < 0) {
    throw MakeInputError(path, field, "cannot read (truncated or corrupt file)");
  }
}

}  // namespace dgmm::h5
