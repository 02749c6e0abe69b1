// Datasets: small dense tables, strings, and chunked per-sample arrays read by hyperslab.
#include <algorithm>

#include "io/hdf5_util.h"
#include "util/error.h"

namespace dgmm::h5 {

namespace {

[[noreturn]] void WriteFailed(const std::string& path, const std::string& field) {
  throw MakeInputError(path, field, "cannot write (HDF5 error; disk full or not writable?)");
}

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
std::vector<T> ReadAll(hid_t loc, const std::string& name, int rank, H5T_class_t cls,
                       hid_t mem_type, std::vector<hsize_t>* dims, const std::string& path) {
  Dataset d = OpenDataset(loc, name, path);
  Datatype type(H5Dget_type(d.get()));
  if (H5Tget_class(type.get()) != cls) {
    throw MakeInputError(
        path, name, cls == H5T_FLOAT ? "expected floating-point numbers" : "expected integers");
  }
  *dims = DimsOf(d.get());
  if (static_cast<int>(dims->size()) != rank) {
    throw MakeInputError(
        path, name,
        "expected " + std::to_string(rank) + " dimensions, found shape " + DimsText(*dims));
  }
  hsize_t n = 1;
  for (hsize_t v : *dims) n *= v;
  std::vector<T> data(n);
  if (n > 0 && H5Dread(d.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) < 0) {
    throw MakeInputError(path, name, "cannot read (truncated or corrupt file)");
  }
  return data;
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

void WriteStrings(hid_t loc, const std::string& name, const std::vector<std::string>& values,
                  const std::string& path) {
  Datatype type(H5Tcopy(H5T_C_S1));
  H5Tset_size(type.get(), H5T_VARIABLE);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  std::vector<const char*> ptrs;
  for (const auto& v : values) ptrs.push_back(v.c_str());
  WriteDense(loc, name, {static_cast<hsize_t>(values.size())}, type.get(), type.get(), ptrs.data(),
             path);
}

DoubleArray ReadDoubles(hid_t loc, const std::string& name, int rank, const std::string& path) {
  DoubleArray a;
  a.data = ReadAll<double>(loc, name, rank, H5T_FLOAT, H5T_NATIVE_DOUBLE, &a.dims, path);
  return a;
}

IntArray ReadInts(hid_t loc, const std::string& name, int rank, const std::string& path) {
  IntArray a;
  a.data = ReadAll<int>(loc, name, rank, H5T_INTEGER, H5T_NATIVE_INT, &a.dims, path);
  return a;
}

std::vector<std::string> ReadStrings(hid_t loc, const std::string& name, const std::string& path) {
  Dataset d = OpenDataset(loc, name, path);
  return ReadStringsFromDataset(d.get(), path, name);
}

std::vector<hsize_t> DatasetDims(hid_t loc, const std::string& name, const std::string& path) {
  Dataset d = OpenDataset(loc, name, path);
  return DimsOf(d.get());
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
