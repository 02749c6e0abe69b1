// HDF5 sample sets: exact round trips and one-line errors for files that are not what we expect.
#include "io/sample_set_io.h"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <filesystem>

#include "tests/io/io_test_util.h"
#include "util/error.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;
using test::RandomSet;
using test::RandomSetShape;

// The message of the InputError `f` throws ("" when it throws none).
template <typename F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SampleSetIo, RoundTripIsExactWithoutTerrain) {
  const fs::path dir = test::TestDir();
  const SampleSet set = RandomSet({.n = 50, .dx = 3}, 1);
  WriteSampleSet(set, dir / "s.h5");
  test::ExpectSameSet(set, ReadSampleSet(dir / "s.h5"));
  EXPECT_EQ(DgmmFileKind(dir / "s.h5"), "sample_set");
}

TEST(SampleSetIo, RoundTripIsExactWithEverything) {
  const fs::path dir = test::TestDir();
  for (std::uint64_t seed = 0; seed < 5; ++seed) {
    RandomSetShape shape{.n = 200,
                         .dx = 3,
                         .dz = 2,
                         .commands = 4,
                         .command_dims = 2,
                         .episodes = true,
                         .transform = true};
    const SampleSet set = RandomSet(shape, seed);
    WriteSampleSet(set, dir / "s.h5");
    test::ExpectSameSet(set, ReadSampleSet(dir / "s.h5"));
  }
}

TEST(SampleSetIo, RoundTripAcrossManyChunks) {
  const fs::path dir = test::TestDir();
  // More rows than one HDF5 chunk (16384) and than one write slice (65536).
  const SampleSet set = RandomSet(
      {.n = 70001, .dx = 2, .dz = 1, .commands = 3, .command_dims = 1, .episodes = true}, 7);
  WriteSampleSet(set, dir / "s.h5");
  test::ExpectSameSet(set, ReadSampleSet(dir / "s.h5"));
}

TEST(SampleSetIo, InvalidSetIsRejectedAndLeavesNothing) {
  const fs::path dir = test::TestDir();
  SampleSet set = RandomSet({.n = 10}, 2);
  set.x(3, 1) = std::nan("");
  const std::string e = ErrorOf([&] { WriteSampleSet(set, dir / "s.h5"); });
  EXPECT_NE(e.find("s.h5"), std::string::npos) << e;
  EXPECT_NE(e.find("NaN"), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(dir / "s.h5"));
  EXPECT_EQ(test::CountTempFiles(dir), 0);
}

TEST(SampleSetIo, UnwritableFolderIsAnInputError) {
  const std::string e =
      ErrorOf([&] { WriteSampleSet(RandomSet({.n = 3}, 1), "/no/such/folder/s.h5"); });
  EXPECT_NE(e.find("/no/such/folder/s.h5"), std::string::npos) << e;
}

TEST(SampleSetIo, MissingTextAndTruncatedFilesAreInputErrors) {
  const fs::path dir = test::TestDir();
  const std::string missing = (dir / "missing.h5").string();
  EXPECT_NE(ErrorOf([&] { ReadSampleSet(missing); }).find("not found"), std::string::npos);

  const std::string text = (dir / "text.h5").string();
  test::WriteText(text, "eruptions,waiting\n3.6,79\n");
  EXPECT_NE(ErrorOf([&] { ReadSampleSet(text); }).find("not an HDF5 file"), std::string::npos);

  const std::string full = (dir / "full.h5").string();
  WriteSampleSet(RandomSet({.n = 5000, .dx = 4}, 3), full);
  const std::string cut = (dir / "cut.h5").string();
  fs::copy_file(full, cut);
  fs::resize_file(cut, fs::file_size(full) / 2);
  const std::string e = ErrorOf([&] { ReadSampleSet(cut); });
  EXPECT_NE(e.find(cut), std::string::npos) << e;
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;
}

TEST(SampleSetIo, ForeignHdf5FilesAreInputErrors) {
  const fs::path dir = test::TestDir();
  const std::string foreign = (dir / "foreign.h5").string();
  {
    hid_t f = H5Fcreate(foreign.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    hsize_t dims[2] = {3, 2};
    hid_t space = H5Screate_simple(2, dims, nullptr);
    hid_t d = H5Dcreate2(f, "x", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dclose(d);
    H5Sclose(space);
    H5Fclose(f);
  }
  const std::string e = ErrorOf([&] { ReadSampleSet(foreign); });
  EXPECT_NE(e.find("dgmm_format"), std::string::npos) << e;
  EXPECT_NE(ErrorOf([&] { DgmmFileKind(foreign); }), "");

  // dgmm_format present but the datasets are missing or have the wrong shape.
  const std::string partial = (dir / "partial.h5").string();
  WriteSampleSet(RandomSet({.n = 5, .dx = 2}, 4), partial);
  {
    hid_t f = H5Fopen(partial.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    H5Ldelete(f, "command", H5P_DEFAULT);
    H5Fclose(f);
  }
  const std::string missing = ErrorOf([&] { ReadSampleSet(partial); });
  EXPECT_NE(missing.find("command: dataset missing"), std::string::npos) << missing;
  {
    hid_t f = H5Fopen(partial.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    hsize_t dims[1] = {4};
    hid_t space = H5Screate_simple(1, dims, nullptr);
    hid_t d = H5Dcreate2(f, "command", H5T_STD_I32LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dclose(d);
    H5Sclose(space);
    H5Fclose(f);
  }
  const std::string shape = ErrorOf([&] { ReadSampleSet(partial); });
  EXPECT_NE(shape.find("command: 4 rows, expected one per sample (5)"), std::string::npos) << shape;
}

}  // namespace
}  // namespace dgmm
