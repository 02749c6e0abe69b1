#include "util/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <system_error>

#include "util/error.h"

namespace dgmm {
namespace {
std::atomic<int> counter{0};
}  // namespace

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  namespace fs = std::filesystem;
  fs::path dir = target_.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw MakeInputError(target_.string(), "output path",
                         "folder '" + dir.string() + "' does not exist");
  }
  if (fs::is_directory(target_, ec)) {
    throw MakeInputError(target_.string(), "output path", "is a folder, expected a file name");
  }
  if (::access(dir.c_str(), W_OK) != 0) {
    throw MakeInputError(target_.string(), "output path",
                         "folder '" + dir.string() + "' is not writable");
  }
  temp_ = dir / (target_.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                 std::to_string(counter++));
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
  }
}

void AtomicFile::Commit() {
  std::error_code ec;
  std::filesystem::rename(temp_, target_, ec);
  if (ec) {
    throw MakeInputError(target_.string(), "output path", "cannot write: " + ec.message());
  }
  committed_ = true;
}

}  // namespace dgmm
