#include "em/em_model.h"

#include <vector>

#include "util/error.h"

namespace dgmm {

EmModelResult FitEmMotionModel(const SampleSet& set, const EmOptions& options, bool with_terrain,
                               const std::string& source, const std::function<void(long long, long long)>& progress) {
  EmModelResult out;
  MotionModel& model = out.model;
  model = ModelHeaderFor(set, with_terrain);
  model.kind = "em";
  model.seed = options.seed;
  const int dim = model.dim();
  const bool terrain = model.terrain_dim > 0;
  std::map<int, std::vector<int>> rows;  // rows of each command, in set order
  for (int i = 0; i < set.size(); ++i) rows[set.command(i)].push_back(i);
  if (rows.empty()) throw MakeInputError(source, "samples", "the set has no samples");
  long long done = 0;
  for (const auto& [id, members] : rows) {
    const std::string label = id < static_cast<int>(set.command_labels.size()) ? set.command_labels[id] : "";
    const int n = static_cast<int>(members.size());
    const std::string where = "command " + std::to_string(id) + " '" + label + "'";
    if (n < options.components) {
      throw MakeInputError(source, where,
                           std::to_string(n) + " samples are fewer than --components " +
                               std::to_string(options.components));
    }
    Eigen::MatrixXd Y(n, dim);
    for (int r = 0; r < n; ++r) {
      Y.row(r).head(set.pose_dim()) = set.x.row(members[r]);
      if (terrain) Y.row(r).tail(set.terrain_dim()) = set.z.row(members[r]);
    }
    EmResult fit = FitEm(Y, options);
    if (fit.summary.failed) {
      throw MakeInputError(source, where,
                           "EM failed: every restart lost a positive definite covariance "
                           "(duplicate or collinear samples?); increase --reg-covar");
    }
    model.mixtures[id] = std::move(fit.mixture);
    out.summaries[id] = fit.summary;
    if (progress) progress(done += n, set.size());
  }
  return out;
}

}  // namespace dgmm
