#pragma once
// Write-then-rename output files: readers never see a partial file, and a failed or interrupted
// run (exception, SIGINT/SIGTERM/SIGHUP) leaves nothing behind at the target path.
#include <filesystem>
#include <string>

namespace dgmm {

// Owns "<target>.tmp-<pid>-<n>" in the target's folder (registered for removal on SIGINT/
// SIGTERM, util/temp_registry.h; stale ones of dead processes are removed on construction).
// Commit() fsyncs the file, renames it onto the target and fsyncs the folder; the destructor
// removes the temporary file if Commit() was never reached.
class AtomicFile {
 public:
  // Throws InputError naming `target` when its folder does not exist or is not writable.
  explicit AtomicFile(std::filesystem::path target);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  // Path to write to (a temporary file beside the target).
  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }
  // Atomically replaces the target with the temporary file. Throws InputError on failure.
  void Commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  int slot_ = -1;
  bool committed_ = false;
};

// fsync of a file or folder by path; false when it cannot be opened or synced.
bool SyncPath(const std::filesystem::path& path, bool is_directory);

}  // namespace dgmm
