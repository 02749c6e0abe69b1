#pragma once
// Fitting and scoring straight from a sample set file, chunk by chunk: memory is bounded by the
// chunk size whatever the file size.
#include <cstddef>
#include <functional>
#include <map>
#include <string>

#include "core/motion_model.h"

namespace dgmm {

// Called after each chunk with samples done and the total.
using StreamProgress = std::function<void(long long done, long long total)>;

// Same model as LearnMotionModel(ReadSampleSet(path), options), streaming the samples through
// a MotionModelLearner. Throws InputError naming the file.
// Two passes: the first resolves the options against the file's pooled within-command variance
// (ResolveMotionModelOptions), the second streams the samples through the learner. The first
// keeps the samples it read for the second while they fit in keep_bytes, so a file that fits is
// read and decompressed once; a larger one is read twice and memory stays bounded. *warning
// (if given) receives ResolveDgmmOptions' scale warning (empty when none).
inline constexpr std::size_t kStreamKeepBytes = std::size_t{128} << 20;
MotionModel LearnMotionModelFromFile(const std::string& path, const MotionModelOptions& options,
                                     int chunk_rows = 65536, const StreamProgress& progress = {},
                                     std::string* warning = nullptr,
                                     std::size_t keep_bytes = kStreamKeepBytes);

// Score of one command of the set: sum log p(x | c [, z]) over its samples.
struct CommandScore {
  std::string label;
  double total_log_likelihood = 0;
  long long samples = 0;
};
struct FileScore {
  ScoreSummary summary;                    // whole set, as ScoreSampleSet
  std::map<int, CommandScore> by_command;  // set command index -> its share
};
// ScoreSampleSet over the file, chunk by chunk, with a per-command breakdown.
FileScore ScoreSampleSetFile(const MotionModel& model, const std::string& path,
                             int chunk_rows = 65536, const StreamProgress& progress = {});

}  // namespace dgmm
