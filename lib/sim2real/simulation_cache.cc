#include "sim2real/simulation_cache.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "io/sample_set_io.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/parallel_for.h"

namespace dgmm::sim2real {
namespace {

// v2: keyed by the simulator's fingerprint through the KnobSimulator interface.
constexpr const char* kCacheVersion = "dgmm-knob-recording-v4";  // v4: a robot block's placements span 2.5 leg reaches

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
                     "\n" + std::to_string(recording.seed) + "\n" + std::to_string(recording.placements) +
                     "\n" + std::to_string(recording.executions_per_placement);
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
  // Whole rounds of one recording per thread, then the last few share the threads (a recording
  // splits over threads without changing its result, knob_simulator.h).
  const int n = static_cast<int>(todo.size()), full = n / options.threads * options.threads, rest = n - full;
  auto record = [&](int t, int threads) {
    const int r = todo[t];
    batch.sets[r] = simulator.Record(recording, requests[r], threads);
    if (use_cache) WriteCacheEntry(batch.sets[r], paths[r]);
  };
  try {
    ParallelFor(full, options.threads, [&](int t) { record(t, 1); });
    ParallelFor(rest, rest, [&](int t) { record(full + t, options.threads / rest); });
  } catch (const std::exception& e) {
    throw MakeInputError("simulator", "", std::string("re-simulation failed: ") + e.what());
  }
  batch.recorded = static_cast<int>(todo.size());
  batch.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return batch;
}

}  // namespace dgmm::sim2real
