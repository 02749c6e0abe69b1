#pragma once
// Internal to dgmm::io: RAII owners for HDF5 handles and typed helpers for the small set of
// HDF5 objects our files use (string/number attributes, dense and chunked datasets). Every
// failure becomes an InputError "<path>: <field>: <problem>"; HDF5's own error printing is off.
#include <hdf5.h>

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace dgmm::h5 {

// Owns one hid_t and closes it with Close (H5Fclose, H5Dclose, ...). Move-only. A failed close
// is not ignored silently for files: see CloseFile.
template <herr_t (*Close)(hid_t)>
class Handle {
 public:
  Handle() = default;
  explicit Handle(hid_t id) : id_(id) {}
  ~Handle() { reset(); }
  Handle(Handle&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)) {}
  Handle& operator=(Handle&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, H5I_INVALID_HID);
    }
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;

  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }
  void reset() {
    if (id_ >= 0) Close(id_);
    id_ = H5I_INVALID_HID;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
};

// H5Fclose, once: after a failed flush (full disk) a failed close must not be retried nor left
// to libhdf5's exit handler (both crashed with SIGSEGV); Init() turns that handler off.
herr_t CloseFile(hid_t file);
using File = Handle<CloseFile>;
using Group = Handle<H5Gclose>;
using Dataset = Handle<H5Dclose>;
using Dataspace = Handle<H5Sclose>;
using Attribute = Handle<H5Aclose>;
using Datatype = Handle<H5Tclose>;
using PropertyList = Handle<H5Pclose>;

// Turns off HDF5's automatic error-stack printing and its exit-time flush of files still open
// (idempotent; every entry point calls it).
void Init();

// --- Limits of version 2 (docs/file-format.md, "Format version 2") ----------------------------
inline constexpr hsize_t kMaxStringBytes = hsize_t{1} << 20;          // one string
inline constexpr hsize_t kMaxStringCount = 1000000;                   // entries of a list
inline constexpr hsize_t kMaxStringListBytes = hsize_t{64} << 20;     // all entries together
inline constexpr hsize_t kMaxChunkBytes = hsize_t{64} << 20;          // one chunk
inline constexpr hsize_t kMaxDenseElements = hsize_t{1} << 27;        // a table read whole
inline constexpr hsize_t kMaxRows = 2147483647;                       // samples (int indices)
inline constexpr hsize_t kMaxColumns = 10000;                         // dimensions
// Declared raw bytes may exceed the bytes stored by at most this factor (deflate's best ratio is
// about 1032) plus kStorageSlackBytes, so a small file cannot make us allocate gigabytes.
inline constexpr hsize_t kMaxCompressionRatio = 1100;
inline constexpr hsize_t kStorageSlackBytes = hsize_t{1} << 20;

// While one of these lives (on this thread), version-1 files and variable-length strings are
// read: only `dgmm upgrade` uses it, for files the user trusts.
class TrustedLegacyRead {
 public:
  TrustedLegacyRead();
  ~TrustedLegacyRead();
  TrustedLegacyRead(const TrustedLegacyRead&) = delete;
  TrustedLegacyRead& operator=(const TrustedLegacyRead&) = delete;
  static bool active();
};

// --- Files -------------------------------------------------------------------------------
// Creates (truncates) `file_path`; errors name `display_path` (the user's target path).
File CreateFile(const std::string& file_path, const std::string& display_path);
// Opens read-only. InputError for a missing file, a folder, a file that is not HDF5, or a
// truncated one.
File OpenFile(const std::string& path);
// The root attribute dgmm_format ("sample_set", "model"); InputError for foreign HDF5 files, for
// version 1 (unless TrustedLegacyRead::active()) and any other version.
std::string ReadFormat(hid_t file, const std::string& path);
// The dgmm_format_version the file declares (checked as ReadFormat does, but 1 is returned).
std::int64_t ReadFormatVersion(hid_t file, const std::string& path);
// Writes dgmm_format and dgmm_format_version on the root group.
void WriteFormat(hid_t file, const std::string& format, const std::string& path);
inline constexpr int kFormatVersion = 2;

// InputError "<path>: <field>: cannot write (HDF5 error; disk full or not writable?)".
[[noreturn]] void WriteFailed(const std::string& path, const std::string& field);
// The attribute `name` of obj; InputError "<path>: <field>: missing" when absent.
Attribute OpenAttribute(hid_t obj, const std::string& name, const std::string& path,
                        const std::string& field);

// --- Groups and existence -----------------------------------------------------------------
Group CreateGroup(hid_t loc, const std::string& name, const std::string& path);
Group OpenGroup(hid_t loc, const std::string& name, const std::string& path);
bool Exists(hid_t loc, const std::string& name);
bool HasAttribute(hid_t obj, const std::string& name);

// --- Attributes ---------------------------------------------------------------------------
void WriteStringAttribute(hid_t obj, const std::string& name, const std::string& value,
                          const std::string& path);
void WriteDoubleAttribute(hid_t obj, const std::string& name, double value,
                          const std::string& path);
void WriteInt64Attribute(hid_t obj, const std::string& name, std::int64_t value,
                         const std::string& path);
void WriteUint64Attribute(hid_t obj, const std::string& name, std::uint64_t value,
                          const std::string& path);
// Strings are written fixed-length (H5T_STR_NULLPAD, UTF-8, size of the longest entry, >= 1).
// A 1-D list of strings (n >= 1; an empty list is written as no attribute).
void WriteStringListAttribute(hid_t obj, const std::string& name,
                              const std::vector<std::string>& values, const std::string& path);

// Readers throw InputError "<path>: <field>: missing" when the attribute is absent; `field`
// is how the attribute is named in messages (e.g. "x/names").
std::string ReadStringAttribute(hid_t obj, const std::string& name, const std::string& path,
                                const std::string& field);
double ReadDoubleAttribute(hid_t obj, const std::string& name, const std::string& path,
                           const std::string& field);
std::int64_t ReadInt64Attribute(hid_t obj, const std::string& name, const std::string& path,
                                const std::string& field);
std::uint64_t ReadUint64Attribute(hid_t obj, const std::string& name, const std::string& path,
                                  const std::string& field);
// Empty when the attribute is absent. With expected_count >= 0, a list of another length is an
// InputError raised before the strings are read.
std::vector<std::string> ReadStringListAttribute(hid_t obj, const std::string& name,
                                                 const std::string& path, const std::string& field,
                                                 long long expected_count = -1);
// Names of all attributes of obj, in name order.
std::vector<std::string> AttributeNames(hid_t obj, const std::string& path);
// Names of the links (groups/datasets) in a group, in name order.
std::vector<std::string> LinkNames(hid_t group, const std::string& path);

// --- Datasets -----------------------------------------------------------------------------
// Small dense datasets (row-major data, any dims incl. zero-sized ones), not chunked.
void WriteDoubles(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims,
                  const double* data, const std::string& path);
void WriteInts(hid_t loc, const std::string& name, const std::vector<hsize_t>& dims,
               const int* data, const std::string& path);
void WriteStrings(hid_t loc, const std::string& name, const std::vector<std::string>& values,
                  const std::string& path);

// A whole dataset read into row-major storage; `rank` must match and the dataset pass
// CheckDataset with at most kMaxDenseElements elements (InputError otherwise).
struct DoubleArray {
  std::vector<hsize_t> dims;
  std::vector<double> data;
};
struct IntArray {
  std::vector<hsize_t> dims;
  std::vector<int> data;
};
DoubleArray ReadDoubles(hid_t loc, const std::string& name, int rank, const std::string& path);
// The same with every extent given (-1: any), checked before the read.
DoubleArray ReadDoubles(hid_t loc, const std::string& name, const std::vector<long long>& extents,
                        const std::string& path);
IntArray ReadInts(hid_t loc, const std::string& name, int rank, const std::string& path);
std::vector<std::string> ReadStrings(hid_t loc, const std::string& name, const std::string& path,
                                     long long expected_count = -1);
// Strings of an open 1-D dataset (fixed length; vlen only under TrustedLegacyRead).
std::vector<std::string> ReadStringsFromDataset(hid_t dataset, const std::string& path,
                                                const std::string& field,
                                                long long expected_count = -1);

// Dims of an existing dataset (InputError when missing).
std::vector<hsize_t> DatasetDims(hid_t loc, const std::string& name, const std::string& path);

// What the schema expects of a dataset: its exact file type (H5T_IEEE_F64LE or H5T_STD_I32LE),
// one extent per dimension (-1: any, up to `max_extent`) and the largest element count.
struct DatasetSpec {
  hid_t type;
  std::vector<long long> extents;
  hsize_t max_extent = kMaxRows;
  hsize_t max_elements = kMaxDenseElements;
};
// Checks an open dataset against `spec` and the file before anything is read: type, rank,
// extents, element count, storage layout (no external or virtual storage, known filters only,
// chunks at most kMaxChunkBytes) and stored bytes against the declared ones. Returns the dims.
std::vector<hsize_t> CheckDataset(hid_t dataset, const DatasetSpec& spec, const std::string& path,
                                  const std::string& field);
// Opens `name` under loc and checks it (InputError when missing or not as expected).
Dataset OpenCheckedDataset(hid_t loc, const std::string& name, const DatasetSpec& spec,
                           const std::string& path, std::vector<hsize_t>* dims = nullptr);

// A per-sample dataset of `cols` columns (0 means 1-D) growing along rows: chunked
// (chunk_rows x cols), shuffle + deflate. Element type double or int32.
class RowAppender {
 public:
  RowAppender(hid_t loc, const std::string& name, bool is_double, hsize_t cols, hsize_t chunk_rows,
              const std::string& path);
  // Appends rows (row-major, rows x max(cols, 1) values).
  void Append(const void* data, hsize_t rows);

 private:
  Dataset dataset_;
  bool is_double_;
  hsize_t cols_;
  hsize_t rows_ = 0;
  std::string name_, path_;
};

// Reads rows [start, start + count) of a 1-D or 2-D per-sample dataset (hyperslab).
void ReadRows(hid_t dataset, bool is_double, hsize_t start, hsize_t count, hsize_t cols, void* out,
              const std::string& path, const std::string& field);

}  // namespace dgmm::h5
