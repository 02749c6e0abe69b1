#include "io/streaming.h"

#include "io/sample_stream.h"
#include "util/error.h"

namespace dgmm {

MotionModel LearnMotionModelFromFile(const std::string& path, const MotionModelOptions& options,
                                     int chunk_rows, const StreamProgress& progress) {
  SampleSetReader reader(path, chunk_rows);
  const SampleSet& h = reader.header();
  const bool terrain = options.with_terrain && h.terrain_dim() > 0;
  try {
    MotionModelLearner learner(ModelHeaderFor(h, options.with_terrain), options);
    const int dx = h.pose_dim(), dz = terrain ? h.terrain_dim() : 0;
    Eigen::VectorXd y(dx + dz);
    SampleSet chunk;
    long long done = 0;
    while (reader.Next(&chunk)) {
      for (int i = 0; i < chunk.size(); ++i) {
        y.head(dx) = chunk.x.row(i).transpose();
        if (terrain) y.tail(dz) = chunk.z.row(i).transpose();
        learner.Add(chunk.command[i], y);
      }
      done += chunk.size();
      if (progress) progress(done, reader.size());
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
