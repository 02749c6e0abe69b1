#include "sim2real/simulation_cache.h"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <mutex>
#include <thread>

#include "io/sample_set_io.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

// v2: keyed by the simulator's fingerprint through the KnobSimulator interface.
constexpr const char* kCacheVersion = "dgmm-knob-recording-v2";

std::uint64_t Fnv1a(const std::string& s, std::uint64_t h = 1469598103934665603ull) {
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

void WriteCacheEntry(const SampleSet& set, const std::string& path) {
  try {
    AtomicFile file(path);
    WriteSampleSet(set, file.temp_path().string());
    file.Commit();
  } catch (const std::exception&) {
    // The cache is an optimisation: a read-only folder only costs time.
  }
}

}  // namespace

bool RecordingOptions::IsValid(std::string* error) const {
  if (threads < 1) {
    if (error) *error = "threads >= 1";
    return false;
  }
  return true;
}

std::string DefaultCacheDir() {
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/dgmm";
  if (const char* h = std::getenv("HOME"); h && *h) return std::string(h) + "/.cache/dgmm";
  return "";
}

std::string RecordingKey(const KnobSimulator& simulator, const Recording& recording,
                         const std::vector<KnobValue>& values) {
  std::string text = std::string(kCacheVersion) + "\n" + simulator.Fingerprint() + "\n" + recording.protocol +
                     "\n" + std::to_string(recording.seed) + "\n" + std::to_string(recording.placements);
  for (const auto& v : values) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "=%.17g", v.value);
    text += "\n" + simulator.knobs().at(v.knob).name + buf;
  }
  return HashHex(text);
}

std::string HashHex(const std::string& text) {
  char hex[33];
  std::snprintf(hex, sizeof hex, "%016llx%016llx", static_cast<unsigned long long>(Fnv1a(text)),
                static_cast<unsigned long long>(Fnv1a(text, 0x9e3779b97f4a7c15ull)));
  return hex;
}

void ParallelFor(int n, int threads, const std::function<void(int)>& f) {
  std::atomic<int> next{0};
  std::mutex mu;
  std::exception_ptr failure;
  auto worker = [&] {
    for (int t = next++; t < n; t = next++) {
      try {
        f(t);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mu);
        if (!failure) failure = std::current_exception();
      }
    }
  };
  const int k = std::max(1, std::min(threads, n));
  std::vector<std::thread> pool;
  for (int t = 1; t < k; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

RecordingBatch RecordBatch(const KnobSimulator& simulator, const Recording& recording,
                           const std::vector<std::vector<KnobValue>>& requests, const RecordingOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "recording options", error);
  namespace fs = std::filesystem;
  const auto start = std::chrono::steady_clock::now();
  RecordingBatch batch;
  batch.sets.resize(requests.size());
  const std::string dir = options.cache_dir.empty() ? DefaultCacheDir() : options.cache_dir;
  const bool use_cache = !dir.empty() && dir != "-";
  if (use_cache) {
    std::error_code ec;
    fs::create_directories(dir, ec);
  }
  std::vector<std::string> paths(requests.size());
  std::vector<int> todo;
  for (size_t r = 0; r < requests.size(); ++r) {
    if (use_cache) {
      paths[r] = (fs::path(dir) / (RecordingKey(simulator, recording, requests[r]) + ".h5")).string();
      std::error_code ec;
      if (fs::exists(paths[r], ec)) {
        try {
          batch.sets[r] = ReadSampleSet(paths[r]);
          ++batch.from_cache;
          continue;
        } catch (const std::exception&) {
          // A damaged cache entry is recorded again and overwritten.
        }
      }
    }
    todo.push_back(static_cast<int>(r));
  }
  // Parallel over recordings when there are several; one recording gets every thread.
  const int outer = std::min<int>(options.threads, static_cast<int>(todo.size()));
  const int inner = std::max(1, options.threads / std::max(1, outer));
  try {
    ParallelFor(static_cast<int>(todo.size()), outer, [&](int t) {
      const int r = todo[t];
      batch.sets[r] = simulator.Record(recording, requests[r], inner);
      if (use_cache) WriteCacheEntry(batch.sets[r], paths[r]);
    });
  } catch (const std::exception& e) {
    throw MakeInputError("simulator", "", std::string("re-simulation failed: ") + e.what());
  }
  batch.recorded = static_cast<int>(todo.size());
  batch.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return batch;
}

}  // namespace dgmm::sim2real
