#pragma once
// The rendering tests' PNGs: one folder per test process, removed when the process exits.
#include <filesystem>
#include <string>

namespace dgmm::test {

// <temp>/dgmm-render-tests-<pid>/<name>; the folder is created on first use and removed, with
// everything in it, when the test program exits.
std::filesystem::path OutputPath(const std::string& name);

}  // namespace dgmm::test
