#pragma once
// The project's robots (datasets/robots) as the simulator's tests read them.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace dgmm::sim::test {

inline const std::filesystem::path kRobots = std::filesystem::path(DGMM_SOURCE_DIR) / "datasets" / "robots";

inline std::string ReadText(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace dgmm::sim::test
