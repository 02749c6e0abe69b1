#pragma once
// Runs the built `dgmm` binary ($DGMM_EXE) in end-to-end tests.
#include <filesystem>
#include <string>
#include <vector>

namespace dgmm::test {

struct RunResult {
  int exit_code = -1;  // -1: killed by a signal (a crash)
  std::string out;     // stdout
  std::string err;     // stderr
};

// Runs dgmm with the arguments (no shell); `env` entries "K=V" are added to the environment.
RunResult RunDgmm(const std::vector<std::string>& args, const std::vector<std::string>& env = {});

// Runs `dgmm args...` with a display (scripts/with-display.sh: $DISPLAY when set, else
// xvfb-run -a) through the shell (arguments must not need quoting); stdout and stderr go through
// files in `dir`; xvfb-run's own stderr lines are dropped.
RunResult RunUnderXvfb(const std::vector<std::string>& args, const std::filesystem::path& dir);

// A fresh empty folder under the test temp dir, removed by the caller or left for inspection.
std::filesystem::path MakeTempDir(const std::string& name);

// Path of a file under the source tree, e.g. SourcePath("datasets/old_faithful.csv").
std::filesystem::path SourcePath(const std::string& relative);

// Number of non-empty lines in s.
int CountLines(const std::string& s);

}  // namespace dgmm::test
