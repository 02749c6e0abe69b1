#pragma once
// Recordings of the simulator at knob values (knob_simulator.h), read from an on-disk cache or
// recorded, several in parallel. The cache key is the simulator's Fingerprint(), the recording
// (protocol, seed, placements, executions) and the knob values by name: equal keys give equal sets.
#include <functional>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim2real/knob_simulator.h"

namespace dgmm::sim2real {

struct RecordingOptions {
  std::string cache_dir;  // empty: DefaultCacheDir(); "-": no cache
  int threads = 1;        // recordings in parallel (>= 1; the app maps 0 to all cores)
  bool IsValid(std::string* error) const;
};

// $XDG_CACHE_HOME/dgmm, else $HOME/.cache/dgmm; empty when neither is set.
std::string DefaultCacheDir();

// 32 hex digits of `text`: two 64-bit FNV-1a hashes with different offsets (a cache key, not a
// cryptographic hash; a simulator's Fingerprint() may use it too).
std::string HashHex(const std::string& text);

// Hex key of one recording: hash of (cache version, fingerprint, protocol, seed, placements,
// knob name = value for each value in order).
std::string RecordingKey(const KnobSimulator& simulator, const Recording& recording,
                         const std::vector<KnobValue>& values);

struct RecordingBatch {
  std::vector<SampleSet> sets;  // one per request, in order
  int from_cache = 0, recorded = 0;
  double wall_seconds = 0;
};

// The recording at each request's knob values (empty request: nominal). Results do not depend on
// options.threads. Throws InputError naming the simulation that failed.
RecordingBatch RecordBatch(const KnobSimulator& simulator, const Recording& recording,
                           const std::vector<std::vector<KnobValue>>& requests, const RecordingOptions& options);

}  // namespace dgmm::sim2real
