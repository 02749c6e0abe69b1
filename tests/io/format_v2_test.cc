// Format version 2 (docs/file-format.md): fixed-length strings and checksummed metadata on write;
// on read, variable-length strings, version 1, huge declared shapes, asymmetric covariances and
// overflowing weights are one InputError each, raised before anything is read; dgmm upgrade
// converts a trusted version-1 file with the same content.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cstring>
#include <filesystem>

#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "io/upgrade.h"
#include "tests/io/io_test_util.h"
#include "util/error.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

// The InputError message of f(), or "" when it did not throw.
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Replaces the string attribute `name` of object `obj` (path in file) by a variable-length one.
void InjectVlenString(const std::string& file, const std::string& obj, const std::string& name,
                      const std::string& value) {
  hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  hid_t o = H5Oopen(f, obj.c_str(), H5P_DEFAULT);
  H5Adelete(o, name.c_str());
  hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  hid_t space = H5Screate(H5S_SCALAR);
  hid_t a = H5Acreate2(o, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
  const char* c = value.c_str();
  H5Awrite(a, type, &c);
  H5Aclose(a);
  H5Sclose(space);
  H5Tclose(type);
  H5Oclose(o);
  H5Fclose(f);
}

void SetVersion(const std::string& file, std::int64_t version) {
  hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  hid_t a = H5Aopen(f, "dgmm_format_version", H5P_DEFAULT);
  H5Awrite(a, H5T_NATIVE_INT64, &version);
  H5Aclose(a);
  H5Fclose(f);
}

void OverwriteDoubles(const std::string& file, const std::string& dataset,
                      const std::vector<double>& values) {
  hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  hid_t d = H5Dopen2(f, dataset.c_str(), H5P_DEFAULT);
  H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data());
  H5Dclose(d);
  H5Fclose(f);
}

TEST(FormatV2, FilesAreWrittenWithChecksumsAndFixedLengthStrings) {
  const fs::path dir = test::TestDir();
  const std::string set = (dir / "set.h5").string(), model = (dir / "m.h5").string();
  WriteSampleSet(test::RandomSet({.n = 20}, 3), set);
  WriteModel(test::RandomModel(2, 1, 2, 3, true), model);
  for (const std::string& file : {set, model}) {
    hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    H5F_info2_t info{};
    ASSERT_GE(H5Fget_info2(f, &info), 0);
    EXPECT_GE(info.super.version, 2u) << file << ": superblock without checksums";
    hid_t a = H5Aopen(f, "dgmm_format", H5P_DEFAULT);
    hid_t t = H5Aget_type(a);
    EXPECT_EQ(H5Tis_variable_str(t), 0) << file;
    EXPECT_EQ(H5Tget_strpad(t), H5T_STR_NULLPAD);
    EXPECT_EQ(H5Tget_cset(t), H5T_CSET_UTF8);
    H5Tclose(t);
    H5Aclose(a);
    std::int64_t version = 0;
    a = H5Aopen(f, "dgmm_format_version", H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_INT64, &version);
    EXPECT_EQ(version, 2);
    H5Aclose(a);
    H5Fclose(f);
  }
}

TEST(FormatV2, VariableLengthStringsAreRefused) {
  const fs::path dir = test::TestDir();
  const std::string model = (dir / "m.h5").string(), set = (dir / "s.h5").string();
  WriteModel(test::RandomModel(2, 0, 2, 1, false), model);
  InjectVlenString(model, "/", "kind", "dgmm");
  std::string e = ErrorOf([&] { ReadModel(model); });
  EXPECT_NE(e.find("kind: expected a fixed-length string"), std::string::npos) << e;

  WriteSampleSet(test::RandomSet({.n = 5}, 1), set);
  InjectVlenString(set, "/", "dgmm_format", "sample_set");
  e = ErrorOf([&] { ReadSampleSet(set); });
  EXPECT_NE(e.find("dgmm_format: expected a fixed-length string"), std::string::npos) << e;
}

TEST(FormatV2, VersionOneIsRefusedWithTheWayToUpgrade) {
  const fs::path dir = test::TestDir();
  const std::string set = (dir / "s.h5").string();
  WriteSampleSet(test::RandomSet({.n = 5}, 1), set);
  SetVersion(set, 1);
  const std::string e = ErrorOf([&] { ReadSampleSet(set); });
  EXPECT_NE(e.find("dgmm_format_version: 1 is the old format; convert a trusted file with dgmm "
                   "upgrade"),
            std::string::npos)
      << e;
  SetVersion(set, 3);
  EXPECT_NE(ErrorOf([&] { ReadSampleSet(set); }).find("unsupported version 3"), std::string::npos);
}

// A version-1 file as dgmm 1 wrote it: variable-length root strings, version 1, no checksums
// (earliest format bounds). Objects are copied, root attributes copied byte for byte.
void MakeVersionOne(const std::string& from, const std::string& to) {
  hid_t src = H5Fopen(from.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  hid_t dst = H5Fcreate(to.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  auto copy = [](hid_t g, const char* name, const H5L_info_t*, void* data) -> herr_t {
    return H5Ocopy(g, name, *static_cast<hid_t*>(data), name, H5P_DEFAULT, H5P_DEFAULT);
  };
  H5Literate(src, H5_INDEX_NAME, H5_ITER_INC, nullptr, copy, &dst);
  auto copy_attr = [](hid_t loc, const char* name, const H5A_info_t*, void* data) -> herr_t {
    hid_t a = H5Aopen(loc, name, H5P_DEFAULT);
    hid_t t = H5Aget_type(a), space = H5Aget_space(a);
    std::vector<char> buf(H5Tget_size(t) * H5Sget_simple_extent_npoints(space));
    H5Aread(a, t, buf.data());
    hid_t b = H5Acreate2(*static_cast<hid_t*>(data), name, t, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(b, t, buf.data());
    H5Aclose(b);
    H5Sclose(space);
    H5Tclose(t);
    H5Aclose(a);
    return 0;
  };
  H5Aiterate2(src, H5_INDEX_NAME, H5_ITER_INC, nullptr, copy_attr, &dst);
  H5Fclose(dst);
  for (const char* attr : {"dgmm_format", "source", "kind"}) {
    if (H5Aexists(src, attr) <= 0) continue;
    hid_t a = H5Aopen(src, attr, H5P_DEFAULT);
    hid_t t = H5Aget_type(a);
    std::vector<char> buf(H5Tget_size(t) + 1, '\0');
    H5Aread(a, t, buf.data());
    H5Tclose(t);
    H5Aclose(a);
    InjectVlenString(to, "/", attr, std::string(buf.data()));
  }
  H5Fclose(src);
  SetVersion(to, 1);
}

TEST(FormatV2, UpgradeConvertsATrustedVersionOneFile) {
  const fs::path dir = test::TestDir();
  const SampleSet original = test::RandomSet({.n = 30}, 5);
  WriteSampleSet(original, dir / "v2.h5");
  MakeVersionOne((dir / "v2.h5").string(), (dir / "v1.h5").string());
  EXPECT_NE(ErrorOf([&] { ReadSampleSet(dir / "v1.h5"); }).find("dgmm upgrade"),
            std::string::npos);
  const UpgradeSummary s = UpgradeFile(dir / "v1.h5", dir / "up.h5");
  EXPECT_TRUE(s.written);
  EXPECT_EQ(s.from_version, 1);
  EXPECT_EQ(s.kind, "sample_set");
  test::ExpectSameSet(original, ReadSampleSet(dir / "up.h5"));
  // Idempotent: a version-2 input writes nothing.
  EXPECT_FALSE(UpgradeFile(dir / "up.h5", dir / "again.h5").written);
  EXPECT_FALSE(fs::exists(dir / "again.h5"));
}

TEST(FormatV2, UpgradeConvertsATrustedVersionOneModel) {
  const fs::path dir = test::TestDir();
  const MotionModel original = test::RandomModel(2, 1, 3, 8, true);
  WriteModel(original, dir / "v2.h5");
  MakeVersionOne((dir / "v2.h5").string(), (dir / "v1.h5").string());
  EXPECT_NE(ErrorOf([&] { ReadModel(dir / "v1.h5"); }).find("dgmm upgrade"), std::string::npos);
  const UpgradeSummary s = UpgradeFile(dir / "v1.h5", dir / "up.h5");
  EXPECT_TRUE(s.written);
  EXPECT_EQ(s.kind, "model");
  test::ExpectSameModel(original, ReadModel(dir / "up.h5"));
}

TEST(FormatV2, HugeDeclaredShapeIsRefusedBeforeAnyAllocation) {
  const fs::path dir = test::TestDir();
  const std::string set = (dir / "s.h5").string();
  WriteSampleSet(test::RandomSet({.n = 5}, 1), set);
  {
    hid_t f = H5Fopen(set.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    H5Ldelete(f, "x", H5P_DEFAULT);
    hsize_t dims[2] = {hsize_t{4} << 40, 8}, maxdims[2] = {H5S_UNLIMITED, 8}, chunk[2] = {64, 8};
    hid_t space = H5Screate_simple(2, dims, maxdims);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(dcpl, 2, chunk);
    hid_t d = H5Dcreate2(f, "x", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    H5Dclose(d);
    H5Pclose(dcpl);
    H5Sclose(space);
    H5Fclose(f);
  }
  const std::string e = ErrorOf([&] { ReadSampleSet(set); });
  EXPECT_NE(e.find("x: "), std::string::npos) << e;
  EXPECT_TRUE(e.find("at most") != std::string::npos || e.find("stores") != std::string::npos)
      << e;
}

TEST(FormatV2, AsymmetricCovarianceAndOverflowingWeightsAreRefused) {
  const fs::path dir = test::TestDir();
  const std::string model = (dir / "m.h5").string();
  WriteModel(test::RandomModel(2, 0, 1, 1, false), model);
  const MotionModel m = ReadModel(model);
  const int k = m.mixtures.begin()->second.size();
  std::vector<double> covariances;
  for (int i = 0; i < k; ++i) {
    covariances.insert(covariances.end(), {2.0, 0.5, 0.1, 2.0});  // positive definite, asymmetric
  }
  OverwriteDoubles(model, "mixtures/0/covariances", covariances);
  std::string e = ErrorOf([&] { ReadModel(model); });
  EXPECT_NE(e.find("not symmetric"), std::string::npos) << e;

  WriteModel(test::RandomModel(2, 0, 1, 1, false), model);
  if (k >= 2) {
    OverwriteDoubles(model, "mixtures/0/weights", std::vector<double>(k, 1e308));
    e = ErrorOf([&] { ReadModel(model); });
    EXPECT_NE(e.find("finite sum"), std::string::npos) << e;
  }
}

TEST(FormatV2, StringTypedDatasetIsNamedAsSuch) {
  const fs::path dir = test::TestDir();
  const std::string set = (dir / "s.h5").string();
  WriteSampleSet(test::RandomSet({.n = 5}, 1), set);
  {
    hid_t f = H5Fopen(set.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    H5Ldelete(f, "command", H5P_DEFAULT);
    hsize_t n = 5;
    hid_t space = H5Screate_simple(1, &n, nullptr);
    hid_t t = H5Tcopy(H5T_C_S1);
    H5Tset_size(t, 4);
    hid_t d = H5Dcreate2(f, "command", t, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dclose(d);
    H5Tclose(t);
    H5Sclose(space);
    H5Fclose(f);
  }
  const std::string e = ErrorOf([&] { ReadSampleSet(set); });
  EXPECT_NE(e.find("command: expected int32 little-endian integers, found strings"),
            std::string::npos)
      << e;
}

}  // namespace
}  // namespace dgmm
