#include "util/atomic_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "util/error.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("dgmm_atomic_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_, fs::perms::owner_all, ec);
    fs::remove_all(dir_, ec);
  }
  fs::path dir_;
};

TEST_F(AtomicFileTest, CommitRenamesOntoTarget) {
  const fs::path target = dir_ / "out.txt";
  {
    std::ofstream(target) << "old";
    AtomicFile file(target);
    EXPECT_NE(file.temp_path(), target);
    EXPECT_EQ(file.temp_path().parent_path(), target.parent_path());
    std::ofstream(file.temp_path()) << "new";
    std::string before;
    std::ifstream(target) >> before;
    EXPECT_EQ(before, "old");  // the target is untouched until Commit()
    file.Commit();
    EXPECT_FALSE(fs::exists(file.temp_path()));
  }
  std::string content;
  std::ifstream(target) >> content;
  EXPECT_EQ(content, "new");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator{}), 1);
}

TEST_F(AtomicFileTest, DestructorRemovesUncommittedTemp) {
  const fs::path target = dir_ / "out.txt";
  fs::path temp;
  {
    AtomicFile file(target);
    temp = file.temp_path();
    std::ofstream(temp) << "partial";
    ASSERT_TRUE(fs::exists(temp));
  }
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_FALSE(fs::exists(target));
}

TEST_F(AtomicFileTest, TwoWritersGetDistinctTemps) {
  AtomicFile a(dir_ / "x"), b(dir_ / "x");
  EXPECT_NE(a.temp_path(), b.temp_path());
}

TEST_F(AtomicFileTest, MissingOrUnusableFolderThrowsInputError) {
  EXPECT_THROW(AtomicFile{dir_ / "missing" / "out.txt"}, InputError);
  std::ofstream(dir_ / "plain") << "x";
  EXPECT_THROW(AtomicFile{dir_ / "plain" / "out.txt"}, InputError);
  EXPECT_THROW(AtomicFile{dir_}, InputError);  // a folder, not a file name
  try {
    AtomicFile{dir_ / "missing" / "out.txt"};
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("out.txt"), std::string::npos) << e.what();
  }
}

TEST_F(AtomicFileTest, UnwritableFolderThrowsInputError) {
  if (::geteuid() == 0) GTEST_SKIP() << "root can write to read-only folders";
  const fs::path ro = dir_ / "ro";
  fs::create_directories(ro);
  fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec);
  EXPECT_THROW(AtomicFile(ro / "out.txt"), InputError);
}

TEST_F(AtomicFileTest, CommitFailureThrowsInputError) {
  const fs::path target = dir_ / "out.txt";
  AtomicFile file(target);
  // Nothing was written to the temp path: the rename fails.
  EXPECT_THROW(file.Commit(), InputError);
}

}  // namespace
}  // namespace dgmm
