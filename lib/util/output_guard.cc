#include "util/output_guard.h"

#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "util/error.h"

namespace dgmm {

bool SameFile(const std::string& a, const std::string& b) {
  struct stat sa {}, sb {};
  if (::stat(a.c_str(), &sa) != 0 || ::stat(b.c_str(), &sb) != 0) return false;
  return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

bool SameContent(const std::string& a, const std::string& b) {
  std::error_code ec;
  namespace fs = std::filesystem;
  if (!fs::is_regular_file(a, ec) || !fs::is_regular_file(b, ec)) return false;
  if (fs::file_size(a, ec) != fs::file_size(b, ec) || ec) return false;
  std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
  std::vector<char> ba(1 << 16), bb(1 << 16);
  while (fa && fb) {
    fa.read(ba.data(), ba.size());
    fb.read(bb.data(), bb.size());
    if (fa.gcount() != fb.gcount() ||
        !std::equal(ba.begin(), ba.begin() + fa.gcount(), bb.begin())) {
      return false;
    }
  }
  return !fa.bad() && !fb.bad();
}

void RefuseOutputThatIsAnInput(const std::string& output, const std::vector<std::string>& inputs,
                               const std::string& flag) {
  for (const std::string& input : inputs) {
    if (!input.empty() && SameFile(output, input)) {
      throw MakeInputError(output, flag,
                           "is the same file as the input " + input +
                               "; choose another output path (the input would be overwritten)");
    }
  }
}

}  // namespace dgmm
