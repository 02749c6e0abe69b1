// Files, groups and attributes (datasets are in hdf5_dataset.cc).
#include "io/hdf5_util.h"

#include <filesystem>
#include <fstream>
#include <mutex>

#include "util/error.h"

namespace dgmm::h5 {
namespace {

Datatype VlenStringType() {
  Datatype t(H5Tcopy(H5T_C_S1));
  H5Tset_size(t.get(), H5T_VARIABLE);
  H5Tset_cset(t.get(), H5T_CSET_UTF8);
  return t;
}

PropertyList NoTimesGroupPlist() {
  PropertyList p(H5Pcreate(H5P_GROUP_CREATE));
  H5Pset_obj_track_times(p.get(), false);  // same content, same bytes
  return p;
}

[[noreturn]] void WriteFailed(const std::string& path, const std::string& field) {
  throw MakeInputError(path, field, "cannot write (HDF5 error; disk full or not writable?)");
}

Attribute OpenAttribute(hid_t obj, const std::string& name, const std::string& path,
                        const std::string& field) {
  if (!HasAttribute(obj, name)) throw MakeInputError(path, field, "missing");
  Attribute a(H5Aopen(obj, name.c_str(), H5P_DEFAULT));
  if (!a.valid()) throw MakeInputError(path, field, "cannot open (corrupt file?)");
  return a;
}

// Reads n strings (vlen or fixed length) from an attribute or dataset of type `file_type`.
template <typename ReadFn>
std::vector<std::string> ReadStringsOf(hid_t file_type, hsize_t n, ReadFn read,
                                       const std::string& path, const std::string& field) {
  if (H5Tget_class(file_type) != H5T_STRING) {
    throw MakeInputError(path, field, "expected strings");
  }
  std::vector<std::string> out;
  out.reserve(n);
  if (n == 0) return out;
  if (H5Tis_variable_str(file_type) > 0) {
    Datatype mem = VlenStringType();
    std::vector<char*> buf(n, nullptr);
    if (read(mem.get(), buf.data()) < 0) throw MakeInputError(path, field, "cannot read");
    for (char* s : buf) out.emplace_back(s ? s : "");
    Dataspace space(H5Screate_simple(1, &n, nullptr));
    H5Dvlen_reclaim(mem.get(), space.get(), H5P_DEFAULT, buf.data());
  } else {
    size_t size = H5Tget_size(file_type);
    Datatype mem(H5Tcopy(H5T_C_S1));
    H5Tset_size(mem.get(), size);
    std::vector<char> buf(n * size, '\0');
    if (read(mem.get(), buf.data()) < 0) throw MakeInputError(path, field, "cannot read");
    for (hsize_t i = 0; i < n; ++i) {
      std::string s(buf.data() + i * size, size);
      out.push_back(s.substr(0, s.find('\0')));
    }
  }
  return out;
}

hsize_t NumElements(hid_t space) {
  hssize_t n = H5Sget_simple_extent_npoints(space);
  return n < 0 ? 0 : static_cast<hsize_t>(n);
}

template <typename T>
void WriteScalarAttribute(hid_t obj, const std::string& name, hid_t file_type, hid_t mem_type,
                          const T& value, const std::string& path) {
  Dataspace space(H5Screate(H5S_SCALAR));
  Attribute a(H5Acreate2(obj, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT));
  if (!a.valid() || H5Awrite(a.get(), mem_type, &value) < 0) WriteFailed(path, name);
}

template <typename T>
T ReadScalarAttribute(hid_t obj, const std::string& name, hid_t mem_type, const std::string& path,
                      const std::string& field) {
  Attribute a = OpenAttribute(obj, name, path, field);
  Dataspace space(H5Aget_space(a.get()));
  Datatype type(H5Aget_type(a.get()));
  H5T_class_t cls = H5Tget_class(type.get());
  if (NumElements(space.get()) != 1 || (cls != H5T_INTEGER && cls != H5T_FLOAT)) {
    throw MakeInputError(path, field, "expected a single number");
  }
  T value{};
  if (H5Aread(a.get(), mem_type, &value) < 0) throw MakeInputError(path, field, "cannot read");
  return value;
}

}  // namespace

void Init() {
  static std::once_flag once;
  std::call_once(once, [] { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); });
}

File CreateFile(const std::string& file_path, const std::string& display_path) {
  Init();
  File f(H5Fcreate(file_path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT));
  if (!f.valid()) throw MakeInputError(display_path, "output path", "cannot create HDF5 file");
  return f;
}

File OpenFile(const std::string& path) {
  Init();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw MakeInputError(path, "", "file not found");
  if (std::filesystem::is_directory(path, ec)) {
    throw MakeInputError(path, "", "is a folder, expected an HDF5 file");
  }
  if (!std::ifstream(path).good()) throw MakeInputError(path, "", "cannot open for reading");
  htri_t is_hdf5 = H5Fis_hdf5(path.c_str());
  if (is_hdf5 <= 0) {
    throw MakeInputError(path, "", "not an HDF5 file (expected a dgmm sample set or model)");
  }
  File f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT));
  if (!f.valid()) {
    throw MakeInputError(path, "", "cannot open HDF5 file (truncated or corrupt)");
  }
  return f;
}

std::string ReadFormat(hid_t file, const std::string& path) {
  if (!HasAttribute(file, "dgmm_format")) {
    throw MakeInputError(path, "dgmm_format",
                         "attribute missing: an HDF5 file not written by dgmm");
  }
  std::string format = ReadStringAttribute(file, "dgmm_format", path, "dgmm_format");
  if (format != "sample_set" && format != "model") {
    throw MakeInputError(path, "dgmm_format", "unknown kind '" + format + "'");
  }
  std::int64_t version =
      ReadInt64Attribute(file, "dgmm_format_version", path, "dgmm_format_version");
  if (version != kFormatVersion) {
    throw MakeInputError(path, "dgmm_format_version",
                         "unsupported version " + std::to_string(version) + " (this dgmm reads " +
                             std::to_string(kFormatVersion) + ")");
  }
  return format;
}

void WriteFormat(hid_t file, const std::string& format, const std::string& path) {
  WriteStringAttribute(file, "dgmm_format", format, path);
  WriteInt64Attribute(file, "dgmm_format_version", kFormatVersion, path);
}

Group CreateGroup(hid_t loc, const std::string& name, const std::string& path) {
  PropertyList gcpl = NoTimesGroupPlist();
  Group g(H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, gcpl.get(), H5P_DEFAULT));
  if (!g.valid()) WriteFailed(path, name);
  return g;
}

Group OpenGroup(hid_t loc, const std::string& name, const std::string& path) {
  if (!Exists(loc, name)) throw MakeInputError(path, name, "group missing");
  Group g(H5Gopen2(loc, name.c_str(), H5P_DEFAULT));
  if (!g.valid()) throw MakeInputError(path, name, "not a group or corrupt");
  return g;
}

bool Exists(hid_t loc, const std::string& name) {
  return H5Lexists(loc, name.c_str(), H5P_DEFAULT) > 0;
}

bool HasAttribute(hid_t obj, const std::string& name) { return H5Aexists(obj, name.c_str()) > 0; }

void WriteStringAttribute(hid_t obj, const std::string& name, const std::string& value,
                          const std::string& path) {
  Datatype type = VlenStringType();
  const char* c = value.c_str();
  WriteScalarAttribute(obj, name, type.get(), type.get(), c, path);
}

void WriteDoubleAttribute(hid_t obj, const std::string& name, double value,
                          const std::string& path) {
  WriteScalarAttribute(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, value, path);
}

void WriteInt64Attribute(hid_t obj, const std::string& name, std::int64_t value,
                         const std::string& path) {
  WriteScalarAttribute(obj, name, H5T_STD_I64LE, H5T_NATIVE_INT64, value, path);
}

void WriteUint64Attribute(hid_t obj, const std::string& name, std::uint64_t value,
                          const std::string& path) {
  WriteScalarAttribute(obj, name, H5T_STD_U64LE, H5T_NATIVE_UINT64, value, path);
}

void WriteStringListAttribute(hid_t obj, const std::string& name,
                              const std::vector<std::string>& values, const std::string& path) {
  if (values.empty()) return;
  Datatype type = VlenStringType();
  std::vector<const char*> ptrs;
  for (const auto& v : values) ptrs.push_back(v.c_str());
  hsize_t n = values.size();
  Dataspace space(H5Screate_simple(1, &n, nullptr));
  Attribute a(H5Acreate2(obj, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT));
  if (!a.valid() || H5Awrite(a.get(), type.get(), ptrs.data()) < 0) WriteFailed(path, name);
}

std::string ReadStringAttribute(hid_t obj, const std::string& name, const std::string& path,
                                const std::string& field) {
  Attribute a = OpenAttribute(obj, name, path, field);
  Datatype type(H5Aget_type(a.get()));
  Dataspace space(H5Aget_space(a.get()));
  if (NumElements(space.get()) != 1) throw MakeInputError(path, field, "expected one string");
  auto v = ReadStringsOf(
      type.get(), 1, [&](hid_t mem, void* buf) { return H5Aread(a.get(), mem, buf); }, path, field);
  return v.front();
}

double ReadDoubleAttribute(hid_t obj, const std::string& name, const std::string& path,
                           const std::string& field) {
  return ReadScalarAttribute<double>(obj, name, H5T_NATIVE_DOUBLE, path, field);
}

std::int64_t ReadInt64Attribute(hid_t obj, const std::string& name, const std::string& path,
                                const std::string& field) {
  return ReadScalarAttribute<std::int64_t>(obj, name, H5T_NATIVE_INT64, path, field);
}

std::uint64_t ReadUint64Attribute(hid_t obj, const std::string& name, const std::string& path,
                                  const std::string& field) {
  return ReadScalarAttribute<std::uint64_t>(obj, name, H5T_NATIVE_UINT64, path, field);
}

std::vector<std::string> ReadStringListAttribute(hid_t obj, const std::string& name,
                                                 const std::string& path,
                                                 const std::string& field) {
  if (!HasAttribute(obj, name)) return {};
  Attribute a = OpenAttribute(obj, name, path, field);
  Datatype type(H5Aget_type(a.get()));
  Dataspace space(H5Aget_space(a.get()));
  return ReadStringsOf(
      type.get(), NumElements(space.get()),
      [&](hid_t mem, void* buf) { return H5Aread(a.get(), mem, buf); }, path, field);
}

std::vector<std::string> AttributeNames(hid_t obj, const std::string& path) {
  std::vector<std::string> names;
  auto collect = [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->emplace_back(name);
    return 0;
  };
  hsize_t idx = 0;
  if (H5Aiterate2(obj, H5_INDEX_NAME, H5_ITER_INC, &idx, collect, &names) < 0) {
    throw MakeInputError(path, "attributes", "cannot list (corrupt file?)");
  }
  return names;
}

std::vector<std::string> LinkNames(hid_t group, const std::string& path) {
  std::vector<std::string> names;
  auto collect = [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->emplace_back(name);
    return 0;
  };
  hsize_t idx = 0;
  if (H5Literate(group, H5_INDEX_NAME, H5_ITER_INC, &idx, collect, &names) < 0) {
    throw MakeInputError(path, "groups", "cannot list (corrupt file?)");
  }
  return names;
}

std::vector<std::string> ReadStringsFromDataset(hid_t dataset, const std::string& path,
                                                const std::string& field) {
  Datatype type(H5Dget_type(dataset));
  Dataspace space(H5Dget_space(dataset));
  if (H5Sget_simple_extent_ndims(space.get()) != 1) {
    throw MakeInputError(path, field, "expected a 1-D list of strings");
  }
  return ReadStringsOf(
      type.get(), NumElements(space.get()),
      [&](hid_t mem, void* buf) {
        return H5Dread(dataset, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
      },
      path, field);
}

}  // namespace dgmm::h5
