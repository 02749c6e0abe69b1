#include "io/streaming.h"

#include "core/data_scale.h"
#include "io/sample_stream.h"
#include "util/error.h"

namespace dgmm {

namespace {

// Calls visit(command, y) for every sample of the file in order, y = x || z when terrain; then
// progress(done, total) after each chunk.
template <typename Visit>
void ForEachJoint(const std::string& path, bool with_terrain, int chunk_rows,
                  const StreamProgress& progress, Visit visit) {
  SampleSetReader reader(path, chunk_rows);
  const SampleSet& h = reader.header();
  const bool terrain = with_terrain && h.terrain_dim() > 0;
  const int dx = h.pose_dim(), dz = terrain ? h.terrain_dim() : 0;
  Eigen::VectorXd y(dx + dz);
  SampleSet chunk;
  long long done = 0;
  while (reader.Next(&chunk)) {
    for (int i = 0; i < chunk.size(); ++i) {
      y.head(dx) = chunk.x.row(i).transpose();
      if (terrain) y.tail(dz) = chunk.z.row(i).transpose();
      visit(chunk.command[i], y);
    }
    done += chunk.size();
    if (progress) progress(done, reader.size());
  }
}

}  // namespace

MotionModel LearnMotionModelFromFile(const std::string& path, const MotionModelOptions& options_in,
                                     int chunk_rows, const StreamProgress& progress,
                                     std::string* warning) {
  const SampleSet h = SampleSetReader(path, chunk_rows).header();
  const bool terrain = options_in.with_terrain && h.terrain_dim() > 0;
  try {
    // Pass 1: the data's scale (the header carries names; its per-sample arrays are empty).
    DataScaleAccumulator scale(h.pose_dim() + (terrain ? h.terrain_dim() : 0));
    ForEachJoint(path, terrain, chunk_rows, {},
                 [&](int command, const Eigen::VectorXd& y) { scale.Add(command, y); });
    const MotionModelOptions options =
        scale.samples() > 0
            ? ResolveMotionModelOptions(h, options_in, scale.PooledVariance(), warning)
            : options_in;
    // Pass 2: the DGMM.
    MotionModelLearner learner(ModelHeaderFor(h, options.with_terrain), options);
    ForEachJoint(path, terrain, chunk_rows, progress,
                 [&](int command, const Eigen::VectorXd& y) { learner.Add(command, y); });
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
