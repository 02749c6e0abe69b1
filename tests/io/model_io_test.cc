// HDF5 models: exact round trips, and errors for the wrong kind of file.
#include "io/model_io.h"

#include <gtest/gtest.h>
#include <hdf5.h>

#include <filesystem>
#include <fstream>

#include "io/sample_set_io.h"
#include "tests/io/io_test_util.h"
#include "util/error.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

TEST(ModelIo, RoundTripIsExact) {
  const fs::path dir = test::TestDir();
  for (bool transform : {false, true}) {
    for (std::uint64_t seed = 0; seed < 3; ++seed) {
      const MotionModel model = test::RandomModel(3, seed % 2 ? 2 : 0, 4, seed, transform);
      WriteModel(model, dir / "m.h5");
      test::ExpectSameModel(model, ReadModel(dir / "m.h5"));
      EXPECT_EQ(DgmmFileKind(dir / "m.h5"), "model");
    }
  }
}

TEST(ModelIo, SameModelGivesTheSameBytes) {
  const fs::path dir = test::TestDir();
  const MotionModel model = test::RandomModel(2, 1, 3, 4, true);
  WriteModel(model, dir / "a.h5");
  WriteModel(model, dir / "b.h5");
  std::ifstream a(dir / "a.h5", std::ios::binary), b(dir / "b.h5", std::ios::binary);
  const std::string bytes_a{std::istreambuf_iterator<char>(a), {}};
  const std::string bytes_b{std::istreambuf_iterator<char>(b), {}};
  EXPECT_FALSE(bytes_a.empty());
  EXPECT_TRUE(bytes_a == bytes_b) << "no timestamps or other run-dependent bytes expected";
}

TEST(ModelIo, WrongKindsOfFileAreInputErrors) {
  const fs::path dir = test::TestDir();
  WriteSampleSet(test::RandomSet({.n = 4}, 1), dir / "set.h5");
  try {
    ReadModel(dir / "set.h5");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("expected a model"), std::string::npos) << e.what();
  }
  WriteModel(test::RandomModel(2, 0, 2, 1, false), dir / "m.h5");
  EXPECT_THROW(ReadSampleSet(dir / "m.h5"), InputError);
  test::WriteText(dir / "text.h5", "not hdf5");
  EXPECT_THROW(ReadModel(dir / "text.h5"), InputError);
}

TEST(ModelIo, NonPositiveDefiniteCovarianceInAFileIsAnInputError) {
  const fs::path dir = test::TestDir();
  const std::string path = (dir / "m.h5").string();
  WriteModel(test::RandomModel(2, 0, 2, 1, false), path);
  {
    hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    hid_t d = H5Dopen2(f, "mixtures/0/covariances", H5P_DEFAULT);
    std::vector<double> zeros(2 * 2 * 2, 0.0);
    H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, zeros.data());
    H5Dclose(d);
    H5Fclose(f);
  }
  try {
    ReadModel(path);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("positive definite"), std::string::npos) << e.what();
  }
}

TEST(ModelIo, InconsistentCommandTableIsRejected) {
  const fs::path dir = test::TestDir();
  MotionModel model = test::RandomModel(2, 0, 2, 1, false);
  model.command_labels[7] = "no values";
  EXPECT_THROW(WriteModel(model, dir / "m.h5"), InputError);
  EXPECT_FALSE(fs::exists(dir / "m.h5"));
  EXPECT_EQ(test::CountTempFiles(dir), 0);
}

}  // namespace
}  // namespace dgmm
