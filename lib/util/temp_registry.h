#pragma once
// The temporary files and folders this process is writing ("<name>.tmp-<pid>-<n>"), removed when
// SIGINT, SIGTERM or SIGHUP ends the process (the handler unlinks them, then re-raises the signal
// with its default action), and the stale ones that dead processes left behind.
#include <filesystem>
#include <string>

namespace dgmm {

// Registers a live temporary path (file or flat folder); the first call installs the signal
// handlers. Returns a slot for Unregister (-1 when the fixed table of 256 slots is full: the path
// is then only removed by its owner's destructor).
int RegisterTempPath(const std::filesystem::path& path);
void UnregisterTempPath(int slot);

// "<stem>.tmp-<pid>-<n>" for this process, n counting up per process.
std::filesystem::path NextTempPath(const std::filesystem::path& dir, const std::string& stem);

// Removes "<stem>.tmp-<pid>-<n>" entries of `dir` whose process no longer runs (files and
// folders). Returns how many were removed.
int RemoveStaleTemps(const std::filesystem::path& dir, const std::string& stem);

// True when `name` is "<stem>.tmp-<pid>-<n>" for some stem (sets *pid).
bool IsTempName(const std::string& name, const std::string& stem, long* pid);

}  // namespace dgmm
