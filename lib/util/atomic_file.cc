#include "util/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <system_error>

#include "util/error.h"
#include "util/temp_registry.h"

namespace dgmm {

bool SyncPath(const std::filesystem::path& path, bool is_directory) {
  const int fd = ::open(path.c_str(), (is_directory ? O_RDONLY | O_DIRECTORY : O_RDONLY) | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  ::close(fd);
  return ok;
}

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
  RemoveStaleTemps(dir, target_.filename().string());
  temp_ = NextTempPath(dir, target_.filename().string());
  slot_ = RegisterTempPath(temp_);
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
  }
  UnregisterTempPath(slot_);
}

void AtomicFile::Commit() {
  if (!SyncPath(temp_, false)) {
    throw MakeInputError(target_.string(), "output path", "cannot write (fsync failed)");
  }
  std::error_code ec;
  std::filesystem::rename(temp_, target_, ec);
  if (ec) {
    throw MakeInputError(target_.string(), "output path", "cannot write: " + ec.message());
  }
  committed_ = true;
  UnregisterTempPath(slot_);
  slot_ = -1;
  std::filesystem::path dir = target_.parent_path();
  SyncPath(dir.empty() ? "." : dir, true);  // the rename itself survives a crash
}

}  // namespace dgmm
