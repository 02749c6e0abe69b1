// Strings in HDF5 files: written fixed-length (H5T_STR_NULLPAD, UTF-8), read only after their
// size and count were checked against the limits of version 2. Variable-length strings (whose
// reads crashed libhdf5 1.10 on corrupt files, in H5HG_read) are refused unless a
// TrustedLegacyRead is active (`dgmm upgrade` of a version-1 file).
#include <algorithm>
#include <cstring>

#include "io/hdf5_util.h"
#include "util/error.h"

namespace dgmm::h5 {
namespace {

thread_local int legacy_depth = 0;

std::string Str(unsigned long long v) { return std::to_string(v); }

// Fixed-length string type of `size` bytes (>= 1), NULLPAD, in character set `cset`.
Datatype FixedStringType(size_t size, H5T_cset_t cset = H5T_CSET_UTF8) {
  Datatype t(H5Tcopy(H5T_C_S1));
  H5Tset_size(t.get(), std::max<size_t>(size, 1));
  H5Tset_strpad(t.get(), H5T_STR_NULLPAD);
  H5Tset_cset(t.get(), cset);
  return t;
}

// The values packed as n fixed-length entries of the longest entry's size; InputError when one
// is longer than kMaxStringBytes (the reader would refuse it).
std::vector<char> Pack(const std::vector<std::string>& values, size_t* size,
                       const std::string& path, const std::string& field) {
  *size = 1;
  for (const auto& v : values) *size = std::max(*size, v.size());
  if (*size > kMaxStringBytes) {
    throw MakeInputError(path, field,
                         "a string of " + Str(*size) + " bytes; at most " + Str(kMaxStringBytes) +
                             " can be stored");
  }
  std::vector<char> buf(values.size() * *size, '\0');
  for (size_t i = 0; i < values.size(); ++i) {
    std::memcpy(buf.data() + i * *size, values[i].data(), values[i].size());
  }
  return buf;
}

hsize_t NumElements(hid_t space) {
  hssize_t n = H5Sget_simple_extent_npoints(space);
  return n < 0 ? 0 : static_cast<hsize_t>(n);
}

void CheckEntries(hsize_t n, long long expected, const std::string& path,
                  const std::string& field) {
  if (expected >= 0 && n != static_cast<hsize_t>(expected)) {
    throw MakeInputError(path, field,
                         Str(n) + " entries, expected " + Str(static_cast<hsize_t>(expected)));
  }
}

// Reads n strings from an attribute or dataset of type `file_type` after checking the type and
// the sizes; `read(mem_type, buffer)` does the read.
template <typename ReadFn>
std::vector<std::string> ReadStringsOf(hid_t file_type, hsize_t n, ReadFn read,
                                       const std::string& path, const std::string& field) {
  if (file_type < 0 || H5Tget_class(file_type) != H5T_STRING) {
    throw MakeInputError(path, field, "expected strings");
  }
  if (n > kMaxStringCount) {
    throw MakeInputError(path, field,
                         "declares " + Str(n) + " strings; at most " + Str(kMaxStringCount) +
                             " expected");
  }
  std::vector<std::string> out;
  out.reserve(n);
  const htri_t vlen = H5Tis_variable_str(file_type);
  if (vlen != 0 && !TrustedLegacyRead::active()) {
    throw MakeInputError(path, field, "expected a fixed-length string");
  }
  if (n == 0) return out;
  if (vlen > 0) {  // version 1, trusted file (dgmm upgrade)
    Datatype mem(H5Tcopy(H5T_C_S1));
    H5Tset_size(mem.get(), H5T_VARIABLE);
    H5Tset_cset(mem.get(), H5Tget_cset(file_type));
    std::vector<char*> buf(n, nullptr);
    if (read(mem.get(), buf.data()) < 0) throw MakeInputError(path, field, "cannot read");
    for (char* s : buf) out.emplace_back(s ? s : "");
    Dataspace space(H5Screate_simple(1, &n, nullptr));
    H5Dvlen_reclaim(mem.get(), space.get(), H5P_DEFAULT, buf.data());
    return out;
  }
  const size_t size = H5Tget_size(file_type);
  const H5T_cset_t cset = H5Tget_cset(file_type);
  if (size == 0 || size > kMaxStringBytes) {
    throw MakeInputError(path, field,
                         "declares strings of " + Str(size) + " bytes; 1 to " +
                             Str(kMaxStringBytes) + " expected");
  }
  if (n * size > kMaxStringListBytes) {
    throw MakeInputError(path, field,
                         "declares " + Str(n) + " strings of " + Str(size) + " bytes; at most " +
                             Str(kMaxStringListBytes) + " bytes in all expected");
  }
  if (cset != H5T_CSET_UTF8 && cset != H5T_CSET_ASCII) {
    throw MakeInputError(path, field, "expected UTF-8 or ASCII strings");
  }
  Datatype mem = FixedStringType(size, cset);
  std::vector<char> buf(n * size, '\0');
  if (read(mem.get(), buf.data()) < 0) throw MakeInputError(path, field, "cannot read");
  for (hsize_t i = 0; i < n; ++i) {
    const char* s = buf.data() + i * size;
    out.emplace_back(s, strnlen(s, size));
  }
  return out;
}

}  // namespace

TrustedLegacyRead::TrustedLegacyRead() { ++legacy_depth; }
TrustedLegacyRead::~TrustedLegacyRead() { --legacy_depth; }
bool TrustedLegacyRead::active() { return legacy_depth > 0; }

void WriteStringAttribute(hid_t obj, const std::string& name, const std::string& value,
                          const std::string& path) {
  size_t size = 0;
  std::vector<char> buf = Pack({value}, &size, path, name);
  Datatype type = FixedStringType(size);
  Dataspace space(H5Screate(H5S_SCALAR));
  Attribute a(H5Acreate2(obj, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT));
  if (!a.valid() || H5Awrite(a.get(), type.get(), buf.data()) < 0) WriteFailed(path, name);
}

void WriteStringListAttribute(hid_t obj, const std::string& name,
                              const std::vector<std::string>& values, const std::string& path) {
  if (values.empty()) return;
  size_t size = 0;
  std::vector<char> buf = Pack(values, &size, path, name);
  Datatype type = FixedStringType(size);
  hsize_t n = values.size();
  Dataspace space(H5Screate_simple(1, &n, nullptr));
  Attribute a(H5Acreate2(obj, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT));
  if (!a.valid() || H5Awrite(a.get(), type.get(), buf.data()) < 0) WriteFailed(path, name);
}

void WriteStrings(hid_t loc, const std::string& name, const std::vector<std::string>& values,
                  const std::string& path) {
  size_t size = 0;
  std::vector<char> buf = Pack(values, &size, path, name);
  Datatype type = FixedStringType(size);
  hsize_t n = values.size();
  Dataspace space(H5Screate_simple(1, &n, nullptr));
  PropertyList dcpl(H5Pcreate(H5P_DATASET_CREATE));
  H5Pset_obj_track_times(dcpl.get(), false);  // same content, same bytes
  Dataset d(H5Dcreate2(loc, name.c_str(), type.get(), space.get(), H5P_DEFAULT, dcpl.get(),
                       H5P_DEFAULT));
  if (!d.valid()) WriteFailed(path, name);
  if (n > 0 && H5Dwrite(d.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buf.data()) < 0) {
    WriteFailed(path, name);
  }
}

std::string ReadStringAttribute(hid_t obj, const std::string& name, const std::string& path,
                                const std::string& field) {
  Attribute a = OpenAttribute(obj, name, path, field);
  Datatype type(H5Aget_type(a.get()));
  Dataspace space(H5Aget_space(a.get()));
  if (!space.valid() || NumElements(space.get()) != 1) {
    throw MakeInputError(path, field, "expected one string");
  }
  auto v = ReadStringsOf(
      type.get(), 1, [&](hid_t mem, void* buf) { return H5Aread(a.get(), mem, buf); }, path, field);
  return v.front();
}

std::vector<std::string> ReadStringListAttribute(hid_t obj, const std::string& name,
                                                 const std::string& path,
                                                 const std::string& field,
                                                 long long expected_count) {
  if (!HasAttribute(obj, name)) return {};
  Attribute a = OpenAttribute(obj, name, path, field);
  Datatype type(H5Aget_type(a.get()));
  Dataspace space(H5Aget_space(a.get()));
  if (!space.valid() || H5Sget_simple_extent_ndims(space.get()) != 1) {
    throw MakeInputError(path, field, "expected a 1-D list of strings");
  }
  CheckEntries(NumElements(space.get()), expected_count, path, field);
  return ReadStringsOf(
      type.get(), NumElements(space.get()),
      [&](hid_t mem, void* buf) { return H5Aread(a.get(), mem, buf); }, path, field);
}

std::vector<std::string> ReadStringsFromDataset(hid_t dataset, const std::string& path,
                                                const std::string& field,
                                                long long expected_count) {
  Datatype type(H5Dget_type(dataset));
  Dataspace space(H5Dget_space(dataset));
  if (!space.valid() || H5Sget_simple_extent_ndims(space.get()) != 1) {
    throw MakeInputError(path, field, "expected a 1-D list of strings");
  }
  PropertyList dcpl(H5Dget_create_plist(dataset));
  const H5D_layout_t layout = dcpl.valid() ? H5Pget_layout(dcpl.get()) : H5D_LAYOUT_ERROR;
  if ((layout != H5D_CONTIGUOUS && layout != H5D_COMPACT) ||
      H5Pget_external_count(dcpl.get()) != 0) {
    throw MakeInputError(path, field, "expected a contiguous or compact list of strings");
  }
  const hsize_t n = NumElements(space.get());
  CheckEntries(n, expected_count, path, field);
  const size_t size = type.valid() ? H5Tget_size(type.get()) : 0;
  if (layout == H5D_CONTIGUOUS && n > 0 && n <= kMaxStringCount && H5Tis_variable_str(type.get()) == 0 &&
      H5Dget_storage_size(dataset) < n * size) {
    throw MakeInputError(path, field, "stores fewer bytes than it declares (corrupt file?)");
  }
  return ReadStringsOf(
      type.get(), n,
      [&](hid_t mem, void* buf) {
        return H5Dread(dataset, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
      },
      path, field);
}

}  // namespace dgmm::h5
