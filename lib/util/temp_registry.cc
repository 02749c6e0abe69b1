#include "util/temp_registry.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <mutex>

namespace dgmm {
namespace {

constexpr int kSlots = 256;
constexpr int kMaxPath = 4096;
struct Slot {
  std::atomic<bool> used{false};
  char path[kMaxPath];
};
Slot slots[kSlots];
std::atomic<int> counter{0};

// Async-signal-safe removal of a file, or of a folder and the files (one level of subfolders)
// in it: open/getdents64/unlinkat/close only.
void RemoveSignalSafe(int dir_fd, const char* name, int depth) {
  if (unlinkat(dir_fd, name, 0) == 0 || errno != EISDIR) return;
  int fd = openat(dir_fd, name, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd >= 0) {
    alignas(8) char buf[4096];
    for (;;) {
      long n = syscall(SYS_getdents64, fd, buf, sizeof buf);
      if (n <= 0) break;
      for (long off = 0; off < n;) {
        struct Entry {
          unsigned long long ino;
          long long off;
          unsigned short reclen;
          unsigned char type;
          char name[1];
        };
        const Entry* e = reinterpret_cast<const Entry*>(buf + off);
        off += e->reclen;
        if (std::strcmp(e->name, ".") == 0 || std::strcmp(e->name, "..") == 0) continue;
        if (depth < 2) RemoveSignalSafe(fd, e->name, depth + 1);
      }
    }
    close(fd);
  }
  unlinkat(dir_fd, name, AT_REMOVEDIR);
}

void OnSignal(int sig) {
  for (Slot& s : slots) {
    if (s.used.load()) RemoveSignalSafe(AT_FDCWD, s.path, 0);
  }
  signal(sig, SIG_DFL);
  raise(sig);
}

void InstallHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction old {};
      sigaction(sig, nullptr, &old);
      if (old.sa_handler == SIG_IGN) continue;  // e.g. nohup: keep ignoring
      struct sigaction sa {};
      sa.sa_handler = OnSignal;
      sigemptyset(&sa.sa_mask);
      sigaction(sig, &sa, nullptr);
    }
  });
}

bool ProcessRuns(long pid) {
  if (pid <= 0) return false;
  return kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM;
}

}  // namespace

int RegisterTempPath(const std::filesystem::path& path) {
  InstallHandlers();
  const std::string p = std::filesystem::absolute(path).string();
  if (p.size() + 1 > kMaxPath) return -1;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (slots[i].used.load()) continue;
    std::memcpy(slots[i].path, p.c_str(), p.size() + 1);
    if (slots[i].used.compare_exchange_strong(expected, true)) return i;
  }
  return -1;
}

void UnregisterTempPath(int slot) {
  if (slot >= 0 && slot < kSlots) slots[slot].used.store(false);
}

std::filesystem::path NextTempPath(const std::filesystem::path& dir, const std::string& stem) {
  return dir / (stem + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
}

bool IsTempName(const std::string& name, const std::string& stem, long* pid) {
  const std::string prefix = stem + ".tmp-";
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return false;
  const std::string rest = name.substr(prefix.size());
  const size_t dash = rest.find('-');
  if (dash == std::string::npos || dash == 0 || dash + 1 == rest.size()) return false;
  for (size_t i = 0; i < rest.size(); ++i) {
    if (i != dash && (rest[i] < '0' || rest[i] > '9')) return false;
  }
  if (dash > 9) return false;
  *pid = std::stol(rest.substr(0, dash));
  return true;
}

int RemoveStaleTemps(const std::filesystem::path& dir, const std::string& stem) {
  namespace fs = std::filesystem;
  int removed = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    long pid = 0;
    const std::string name = it->path().filename().string();
    if (!IsTempName(name, stem, &pid) || ProcessRuns(pid)) continue;
    std::error_code rm;
    if (fs::remove_all(it->path(), rm) > 0 && !rm) ++removed;
  }
  return removed;
}

}  // namespace dgmm
