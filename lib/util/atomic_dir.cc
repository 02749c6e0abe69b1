#include "util/atomic_dir.h"

#include <fcntl.h>
#include <stdio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <system_error>

#include "util/atomic_file.h"
#include "util/error.h"
#include "util/temp_registry.h"

namespace dgmm {
namespace fs = std::filesystem;

namespace {

fs::path ParentOf(const fs::path& target) {
  fs::path dir = target.parent_path();
  return dir.empty() ? fs::path(".") : dir;
}

// The target without a trailing slash ("out/" -> "out").
fs::path Normalised(fs::path target) {
  while (!target.empty() && !target.has_filename() && target.has_parent_path() &&
         target != target.root_path()) {
    target = target.parent_path();
  }
  return target;
}

}  // namespace

void CheckOutputDir(const fs::path& raw_target, const std::string& marker) {
  const fs::path target = Normalised(raw_target);
  const std::string shown = raw_target.string();
  std::error_code ec;
  const fs::path dir = ParentOf(target);
  if (target.filename().empty() || target.filename() == "." || target.filename() == "..") {
    throw MakeInputError(shown, "-o", "expected a folder name (not . or ..)");
  }
  if (!fs::is_directory(dir, ec)) {
    throw MakeInputError(shown, "-o", "folder '" + dir.string() + "' does not exist");
  }
  if (::access(dir.c_str(), W_OK) != 0) {
    throw MakeInputError(shown, "-o", "folder '" + dir.string() + "' is not writable");
  }
  if (fs::exists(target, ec) && !fs::is_directory(target, ec)) {
    throw MakeInputError(shown, "-o", "is a file, expected a folder for the report");
  }
  if (fs::is_directory(target, ec) && !fs::is_empty(target, ec) &&
      !fs::exists(target / marker, ec)) {
    throw MakeInputError(shown, "-o",
                         "folder exists and holds no " + marker +
                             " (not an earlier result); choose a new or empty folder");
  }
}

AtomicDir::AtomicDir(fs::path target, const std::string& marker)
    : target_(Normalised(std::move(target))) {
  CheckOutputDir(target_, marker);
  const fs::path dir = ParentOf(target_);
  RemoveStaleTemps(dir, target_.filename().string());
  temp_ = NextTempPath(dir, target_.filename().string());
  slot_ = RegisterTempPath(temp_);
  std::error_code ec;
  if (!fs::create_directory(temp_, ec) || ec) {
    UnregisterTempPath(slot_);
    throw MakeInputError(target_.string(), "-o", "cannot create a folder beside it: " + ec.message());
  }
}

AtomicDir::~AtomicDir() {
  std::error_code ec;
  if (!committed_) fs::remove_all(temp_, ec);
  UnregisterTempPath(slot_);
}

void AtomicDir::Commit() {
  std::error_code ec;
  for (const auto& entry : fs::recursive_directory_iterator(temp_, ec)) {
    if (entry.is_regular_file() && !SyncPath(entry.path(), false)) {
      throw MakeInputError(entry.path().string(), "", "cannot write (fsync failed)");
    }
  }
  SyncPath(temp_, true);
  const fs::path dir = ParentOf(target_);
  if (!fs::exists(target_, ec)) {
    fs::rename(temp_, target_, ec);
    if (ec) throw MakeInputError(target_.string(), "-o", "cannot write: " + ec.message());
  } else if (::renameat2(AT_FDCWD, temp_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) ==
             0) {
    // temp_ now holds the previous result: still registered, removed below.
  } else {
    // No RENAME_EXCHANGE on this file system: move the old result aside, then the new one in.
    const fs::path old = NextTempPath(dir, target_.filename().string());
    fs::rename(target_, old, ec);
    if (ec) throw MakeInputError(target_.string(), "-o", "cannot replace: " + ec.message());
    fs::rename(temp_, target_, ec);
    if (ec) {
      std::error_code back;
      fs::rename(old, target_, back);
      throw MakeInputError(target_.string(), "-o", "cannot write: " + ec.message());
    }
    temp_ = old;
  }
  committed_ = true;
  SyncPath(dir, true);
  fs::remove_all(temp_, ec);
}

}  // namespace dgmm
