#pragma once
// A whole output folder replaced at once: files are written into "<target>.tmp-<pid>-<n>" beside
// the target and Commit() swaps it in (renameat2 RENAME_EXCHANGE, so the target path always holds
// either the complete old folder or the complete new one), then removes the old one. Nothing is
// created before the object is, so a run refused earlier leaves no folder behind.
#include <filesystem>
#include <string>

namespace dgmm {

class AtomicDir {
 public:
  // `marker`: a file that identifies an earlier result (e.g. "report.json"). An existing target
  // that is neither empty nor holds the marker is refused (InputError) rather than replaced, so a
  // mistyped -o never deletes unrelated files. Throws InputError when the parent folder is
  // missing or not writable or the target is a file.
  AtomicDir(std::filesystem::path target, const std::string& marker);
  ~AtomicDir();
  AtomicDir(const AtomicDir&) = delete;
  AtomicDir& operator=(const AtomicDir&) = delete;

  // The folder to write into (created by the constructor).
  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }
  // fsyncs every file and the folder, swaps it in and removes the previous result.
  void Commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path temp_;
  int slot_ = -1;
  bool committed_ = false;
};

// The checks of the AtomicDir constructor without creating anything (to refuse early).
void CheckOutputDir(const std::filesystem::path& target, const std::string& marker);

}  // namespace dgmm
