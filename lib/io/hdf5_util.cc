// Files, groups and number attributes (strings: hdf5_strings.cc, datasets: hdf5_dataset.cc).
#include "io/hdf5_util.h"

#include <filesystem>
#include <fstream>
#include <mutex>

#include "util/error.h"

namespace dgmm::h5 {
namespace {

PropertyList NoTimesGroupPlist() {
  PropertyList p(H5Pcreate(H5P_GROUP_CREATE));
  H5Pset_obj_track_times(p.get(), false);  // same content, same bytes
  return p;
}

template <typename T>
void WriteScalarAttribute(hid_t obj, const std::string& name, hid_t file_type, hid_t mem_type,
                          const T& value, const std::string& path) {
  Dataspace space(H5Screate(H5S_SCALAR));
  Attribute a(H5Acreate2(obj, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT));
  if (!a.valid() || H5Awrite(a.get(), mem_type, &value) < 0) WriteFailed(path, name);
}

// One number of exactly the file type `file_type` (the schema's), checked before the read.
template <typename T>
T ReadScalarAttribute(hid_t obj, const std::string& name, hid_t file_type, hid_t mem_type,
                      const char* expected, const std::string& path, const std::string& field) {
  Attribute a = OpenAttribute(obj, name, path, field);
  Dataspace space(H5Aget_space(a.get()));
  Datatype type(H5Aget_type(a.get()));
  if (!space.valid() || !type.valid() || H5Sget_simple_extent_npoints(space.get()) != 1 ||
      H5Tequal(type.get(), file_type) <= 0) {
    throw MakeInputError(path, field, std::string("expected a single ") + expected);
  }
  T value{};
  if (H5Aread(a.get(), mem_type, &value) < 0) throw MakeInputError(path, field, "cannot read");
  return value;
}

}  // namespace

void WriteFailed(const std::string& path, const std::string& field) {
  throw MakeInputError(path, field, "cannot write (HDF5 error; disk full or not writable?)");
}

Attribute OpenAttribute(hid_t obj, const std::string& name, const std::string& path,
                        const std::string& field) {
  if (!HasAttribute(obj, name)) throw MakeInputError(path, field, "missing");
  Attribute a(H5Aopen(obj, name.c_str(), H5P_DEFAULT));
  if (!a.valid()) throw MakeInputError(path, field, "cannot open (corrupt file?)");
  return a;
}

herr_t CloseFile(hid_t file) {
  // After a failed flush (disk full) H5Fclose fails too and leaves the file half closed: closing
  // it again, or letting libhdf5's exit handler flush it, crashed (SIGSEGV in H5F__close). The
  // id is dropped instead (Init() turned the exit handler off); the caller's AtomicFile removes
  // the temporary file.
  return H5Fclose(file);
}

void Init() {
  static std::once_flag once;
  std::call_once(once, [] {
    // No flush of still-open files at exit: after a failed write it crashed (exit 139).
    H5dont_atexit();
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  });
}

File CreateFile(const std::string& file_path, const std::string& display_path) {
  Init();
  // Version 2: checksummed superblock, object headers and B-trees (libver bounds V110..LATEST).
  PropertyList fapl(H5Pcreate(H5P_FILE_ACCESS));
  if (H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_V110, H5F_LIBVER_LATEST) < 0) {
    throw MakeInputError(display_path, "output path", "cannot set HDF5 format bounds");
  }
  PropertyList fcpl(H5Pcreate(H5P_FILE_CREATE));
  H5Pset_obj_track_times(fcpl.get(), false);
  File f(H5Fcreate(file_path.c_str(), H5F_ACC_TRUNC, fcpl.get(), fapl.get()));
  if (!f.valid()) throw MakeInputError(display_path, "output path", "cannot create HDF5 file");
  return f;
}

File OpenFile(const std::string& path) {
  Init();
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) throw MakeInputError(path, "", "file not found");
  if (fs::is_directory(path, ec)) {
    throw MakeInputError(path, "", "is a folder, expected an HDF5 file");
  }
  if (!fs::is_regular_file(path, ec)) {
    throw MakeInputError(path, "", "not a regular file, expected an HDF5 file");
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

std::int64_t ReadFormatVersion(hid_t file, const std::string& path) {
  if (!HasAttribute(file, "dgmm_format_version")) {
    throw MakeInputError(path, "dgmm_format_version",
                         "attribute missing: an HDF5 file not written by dgmm");
  }
  const std::int64_t version =
      ReadInt64Attribute(file, "dgmm_format_version", path, "dgmm_format_version");
  if (version == 1 && !TrustedLegacyRead::active()) {
    throw MakeInputError(path, "dgmm_format_version",
                         "1 is the old format; convert a trusted file with dgmm upgrade");
  }
  if (version != 1 && version != kFormatVersion) {
    throw MakeInputError(path, "dgmm_format_version",
                         "unsupported version " + std::to_string(version) + " (this dgmm reads " +
                             std::to_string(kFormatVersion) + ")");
  }
  if (version == kFormatVersion) {
    // Version 2 is written with checksummed metadata; an older superblock is not ours.
    H5F_info2_t info{};
    if (H5Fget_info2(file, &info) < 0 || info.super.version < 2) {
      throw MakeInputError(path, "superblock",
                           "version " + std::to_string(info.super.version) +
                               " without checksums; expected a file written by dgmm (>= 2)");
    }
  }
  return version;
}

std::string ReadFormat(hid_t file, const std::string& path) {
  if (!HasAttribute(file, "dgmm_format")) {
    throw MakeInputError(path, "dgmm_format",
                         "attribute missing: an HDF5 file not written by dgmm");
  }
  // The version first: it is a plain number, and it decides how strings may be read.
  ReadFormatVersion(file, path);
  std::string format = ReadStringAttribute(file, "dgmm_format", path, "dgmm_format");
  if (format != "sample_set" && format != "model") {
    throw MakeInputError(path, "dgmm_format", "unknown kind '" + format.substr(0, 80) + "'");
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
  H5O_info_t info{};
  if (H5Oget_info_by_name2(loc, name.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT) < 0 ||
      info.type != H5O_TYPE_GROUP) {
    throw MakeInputError(path, name, "not a group or corrupt");
  }
  Group g(H5Gopen2(loc, name.c_str(), H5P_DEFAULT));
  if (!g.valid()) throw MakeInputError(path, name, "not a group or corrupt");
  return g;
}

bool Exists(hid_t loc, const std::string& name) {
  return H5Lexists(loc, name.c_str(), H5P_DEFAULT) > 0;
}

bool HasAttribute(hid_t obj, const std::string& name) { return H5Aexists(obj, name.c_str()) > 0; }

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

double ReadDoubleAttribute(hid_t obj, const std::string& name, const std::string& path,
                           const std::string& field) {
  return ReadScalarAttribute<double>(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                                     "float64 number", path, field);
}

std::int64_t ReadInt64Attribute(hid_t obj, const std::string& name, const std::string& path,
                                const std::string& field) {
  return ReadScalarAttribute<std::int64_t>(obj, name, H5T_STD_I64LE, H5T_NATIVE_INT64,
                                           "int64 number", path, field);
}

std::uint64_t ReadUint64Attribute(hid_t obj, const std::string& name, const std::string& path,
                                  const std::string& field) {
  return ReadScalarAttribute<std::uint64_t>(obj, name, H5T_STD_U64LE, H5T_NATIVE_UINT64,
                                            "uint64 number", path, field);
}

std::vector<std::string> AttributeNames(hid_t obj, const std::string& path) {
  std::vector<std::string> names;
  auto collect = [](hid_t, const char* name, const H5A_info_t*, void* data) -> herr_t {
    auto* out = static_cast<std::vector<std::string>*>(data);
    if (out->size() >= 10000) return -1;  // more attributes than any dgmm file has
    out->emplace_back(name);
    return 0;
  };
  hsize_t idx = 0;
  if (H5Aiterate2(obj, H5_INDEX_NAME, H5_ITER_INC, &idx, collect, &names) < 0) {
    throw MakeInputError(path, "attributes", "cannot list (corrupt file or over 10000?)");
  }
  return names;
}

std::vector<std::string> LinkNames(hid_t group, const std::string& path) {
  std::vector<std::string> names;
  auto collect = [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
    auto* out = static_cast<std::vector<std::string>*>(data);
    if (out->size() >= 1000000) return -1;
    out->emplace_back(name);
    return 0;
  };
  hsize_t idx = 0;
  if (H5Literate(group, H5_INDEX_NAME, H5_ITER_INC, &idx, collect, &names) < 0) {
    throw MakeInputError(path, "groups", "cannot list (corrupt file?)");
  }
  return names;
}

}  // namespace dgmm::h5
