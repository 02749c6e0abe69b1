#include "render/display.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

#include "render/heat_map.h"

namespace dgmm {
namespace {

// Sets DISPLAY for one test and restores the value the program started with.
class ScopedDisplay {
 public:
  explicit ScopedDisplay(const char* value) {
    if (const char* old = std::getenv("DISPLAY")) old_ = old;
    if (value) {
      ::setenv("DISPLAY", value, 1);
    } else {
      ::unsetenv("DISPLAY");
    }
  }
  ~ScopedDisplay() {
    if (old_) {
      ::setenv("DISPLAY", old_->c_str(), 1);
    } else {
      ::unsetenv("DISPLAY");
    }
  }

 private:
  std::optional<std::string> old_;
};

TEST(DisplayTest, UnsetDisplayIsOneClearLine) {
  ScopedDisplay none(nullptr);
  auto problem = DisplayProblem();
  ASSERT_TRUE(problem.has_value());
  EXPECT_NE(problem->find("cannot open an X display"), std::string::npos);
  EXPECT_NE(problem->find("xvfb-run -a"), std::string::npos);
  EXPECT_EQ(problem->find('\n'), std::string::npos);
  EXPECT_THROW(RequireDisplay(), std::runtime_error);
}

TEST(DisplayTest, DeadDisplayIsReportedWithItsName) {
  ScopedDisplay dead(":4711");
  auto problem = DisplayProblem();
  ASSERT_TRUE(problem.has_value());
  EXPECT_NE(problem->find("DISPLAY=:4711"), std::string::npos);
}

TEST(DisplayTest, RenderingWithoutDisplayThrowsAndWritesNothing) {
  ScopedDisplay none(nullptr);
  HeatMapSpec spec;
  spec.background = SampleGrid([](double x, double y) { return x * y; }, {0, 1, 0, 1}, 10, 10);
  auto path = std::filesystem::temp_directory_path() / "dgmm_no_display.png";
  std::filesystem::remove(path);
  EXPECT_THROW(RenderHeatMap(spec, path.string()), std::runtime_error);
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(DisplayTest, TheTestDisplayWorks) {
  if (std::getenv("DISPLAY") == nullptr) GTEST_SKIP() << "not run under xvfb-run";
  EXPECT_FALSE(DisplayProblem().has_value());
}

}  // namespace
}  // namespace dgmm
