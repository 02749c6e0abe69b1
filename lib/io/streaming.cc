#include "io/streaming.h"

#include <cstddef>
#include <vector>

#include "core/data_scale.h"
#include "io/sample_stream.h"
#include "util/error.h"

namespace dgmm {

namespace {

std::size_t ChunkBytes(const SampleSet& c) {
  return sizeof(double) * static_cast<std::size_t>(c.x.size() + c.z.size()) +
         sizeof(int) * static_cast<std::size_t>(c.command.size() + c.episode.size() +
                                                c.step.size());
}

// Calls visit(command, y) for every sample of `chunk` in order, y = x || z when terrain.
template <typename Visit>
void VisitChunk(const SampleSet& chunk, bool terrain, Eigen::VectorXd* y, Visit visit) {
  const int dx = chunk.pose_dim(), dz = terrain ? chunk.terrain_dim() : 0;
  y->resize(dx + dz);
  for (int i = 0; i < chunk.size(); ++i) {
    y->head(dx) = chunk.x.row(i).transpose();
    if (terrain) y->tail(dz) = chunk.z.row(i).transpose();
    visit(chunk.command[i], *y);
  }
}

// Calls visit(command, y) for every sample of the file in order, y = x || z when terrain; then
// progress(done, total) after each chunk. With `keep`, the chunks are kept there as long as
// their total stays under keep_bytes (*keep is emptied when they do not all fit).
template <typename Visit>
void ForEachJoint(const std::string& path, bool with_terrain, int chunk_rows,
                  const StreamProgress& progress, Visit visit,
                  std::vector<SampleSet>* keep = nullptr, std::size_t keep_bytes = 0) {
  SampleSetReader reader(path, chunk_rows);
  const bool terrain = with_terrain && reader.header().terrain_dim() > 0;
  Eigen::VectorXd y;
  SampleSet chunk;
  long long done = 0;
  std::size_t kept_bytes = 0;
  bool keeping = keep != nullptr;
  while (reader.Next(&chunk)) {
    VisitChunk(chunk, terrain, &y, visit);
    done += chunk.size();
    if (progress) progress(done, reader.size());
    if (!keeping) continue;
    kept_bytes += ChunkBytes(chunk);
    if (kept_bytes > keep_bytes) {
      keeping = false;
      std::vector<SampleSet>().swap(*keep);
    } else {
      keep->push_back(std::move(chunk));
      chunk = SampleSet();
    }
  }
}

}  // namespace

MotionModel LearnMotionModelFromFile(const std::string& path, const MotionModelOptions& options_in,
                                     int chunk_rows, const StreamProgress& progress,
                                     std::string* warning, std::size_t keep_bytes) {
  long long total = 0;
  const SampleSet h = [&] {
    const SampleSetReader reader(path, chunk_rows);
    total = reader.size();
    return reader.header();
  }();
  const bool terrain = options_in.with_terrain && h.terrain_dim() > 0;
  try {
    // Pass 1: the data's scale (the header carries names; its per-sample arrays are empty).
    DataScaleAccumulator scale(h.pose_dim() + (terrain ? h.terrain_dim() : 0));
    std::vector<SampleSet> kept;
    ForEachJoint(
        path, terrain, chunk_rows, {},
        [&](int command, const Eigen::VectorXd& y) { scale.Add(command, y); }, &kept, keep_bytes);
    const MotionModelOptions options =
        scale.samples() > 0
            ? ResolveMotionModelOptions(h, options_in, scale.PooledVariance(), warning)
            : options_in;
    // Pass 2: the DGMM.
    MotionModelLearner learner(ModelHeaderFor(h, options.with_terrain), options);
    const auto learn = [&](int command, const Eigen::VectorXd& y) { learner.Add(command, y); };
    if (kept.empty()) {  // the samples did not fit in memory: read the file again
      ForEachJoint(path, terrain, chunk_rows, progress, learn);
    } else {
      Eigen::VectorXd y;
      long long done = 0;
      for (const SampleSet& chunk : kept) {
        VisitChunk(chunk, terrain, &y, learn);
        done += chunk.size();
        if (progress) progress(done, total);
      }
    }
    return learner.Finish();
  } catch (const InputError& e) {
    if (std::string(e.what()).rfind(path, 0) == 0) throw;
    throw MakeInputError(path, "", e.what());
  }
}

FileScore ScoreSampleSetFile(const MotionModel& model, const std::string& path, int chunk_rows,
                             const StreamProgress& progress) {
  SampleSetReader reader(path, chunk_rows);
  const SampleSet& h = reader.header();
  FileScore score;
  try {
    SampleSet chunk;
    long long done = 0;
    while (reader.Next(&chunk)) {
      std::map<int, std::vector<int>> rows;
      for (int i = 0; i < chunk.size(); ++i) rows[chunk.command[i]].push_back(i);
      for (const auto& [command, members] : rows) {
        const ScoreSummary s = ScoreSampleSet(model, chunk.Subset(members));
        CommandScore& c = score.by_command[command];
        c.total_log_likelihood += s.total_log_likelihood;
        c.samples += s.samples;
        score.summary.total_log_likelihood += s.total_log_likelihood;
      }
      done += chunk.size();
      if (progress) progress(done, reader.size());
    }
  } catch (const InputError& e) {
    if (std::string(e.what()).rfind(path, 0) == 0) throw;
    throw MakeInputError(path, "", e.what());
  }
  for (auto& [command, c] : score.by_command) {
    c.label = command < static_cast<int>(h.command_labels.size()) ? h.command_labels[command]
                                                                  : std::to_string(command);
  }
  score.summary.samples = static_cast<int>(reader.size());
  score.summary.mean_log_likelihood =
      score.summary.total_log_likelihood / static_cast<double>(reader.size());
  return score;
}

}  // namespace dgmm
