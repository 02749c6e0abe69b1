#pragma once
// A motion model: for every discrete command c a mixture over y = x || z (pose change, then
// terrain); p(x | c) is its marginal over x and p(x | c, z) its conditional (eq. 15).
#include <Eigen/Dense>
#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "core/dgmm.h"
#include "core/mixture.h"
#include "core/sample_set.h"

namespace dgmm {

struct MotionModel {
  std::string kind = "dgmm";  // "dgmm", "em", "corrected", ...
  int pose_dim = 0;
  int terrain_dim = 0;        // 0 when fitted without terrain
  std::vector<std::string> pose_names, pose_units, terrain_names;
  std::vector<std::string> command_dim_names;
  std::map<int, Eigen::VectorXd> command_values;  // command id -> its row of the command table
  std::map<int, std::string> command_labels;
  std::map<int, Mixture> mixtures;                // command id -> mixture over y (dim pose+terrain)
  std::map<int, bool> max_components_hit;         // command id -> a component cap stopped growth
  DgmmOptions dgmm_options;                       // when kind == "dgmm"
  std::uint64_t seed = 0;
  Standardization transform;                      // of y, copied from the training set
  std::map<std::string, std::string> metadata;    // free-form (e.g. EM options as JSON)

  int dim() const { return pose_dim + terrain_dim; }
  bool HasCommand(int command) const { return mixtures.count(command) > 0; }
  // The command's mixture; throws InputError "unknown command <c>" when absent.
  const Mixture& MixtureFor(int command) const;
  // log p(x | c): marginal over the pose dimensions.
  double LogLikelihood(int command, const Eigen::Ref<const Eigen::VectorXd>& x) const;
  // log p(x | c, z) (eq. 15); requires terrain_dim > 0.
  double LogLikelihood(int command, const Eigen::Ref<const Eigen::VectorXd>& x,
                       const Eigen::Ref<const Eigen::VectorXd>& z) const;
  // p(x | c, z) as a mixture over x.
  Mixture Conditional(int command, const Eigen::Ref<const Eigen::VectorXd>& z) const;
  // p(x | c, z) (or p(x | c) for an empty z) in the raw units of x and z, whatever the model's
  // standardisation: z standardised before conditioning, the mixture mapped back. InputError for
  // a z given to a model without terrain or of the wrong size.
  Mixture RawPoseDistribution(int command, const Eigen::VectorXd& z) const;
  // How much training data lies near a conditioning value z (raw units; continuous commands and
  // terrain): sum_k w_k E_k[exp(-1/2 |H^-1 (z' - z)|^2)], the kernel-weighted count of training
  // samples around z under the command's marginal over z (weights are sample counts), with
  // H = diag(0.1 sd_j), sd_j the marginal's standard deviation of z_j. Closed form:
  // w_k (2 pi)^(d/2) det(H) N(z; mu_k, S_k + H^2). Near 0 outside the range the model saw.
  // *at_data (if given): the same count at the densest of the components' means, the scale to
  // compare with (small sets have few samples near any point).
  double SamplesNear(int command, const Eigen::VectorXd& z, double* at_data = nullptr) const;
};

// Options for learning one DGMM per command from a sample set.
struct MotionModelOptions {
  DgmmOptions dgmm;
  bool with_terrain = true;  // model y = x || z (if the set has terrain) or x alone
  std::uint64_t seed = 1;
};

// Streaming learner: one Dgmm per command, fed one sample at a time (no history kept), e.g. from
// a chunked HDF5 reader. `header` carries dims, names, command table and transform.
class MotionModelLearner {
 public:
  // options.dgmm must be resolved for dim(y) (DgmmOptions::IsValid(dim); InputError otherwise).
  MotionModelLearner(MotionModel header, const MotionModelOptions& options);
  // y = x || z when the header has terrain_dim > 0, else x alone.
  void Add(int command, const Eigen::Ref<const Eigen::VectorXd>& y);
  // The model so far (mixtures copied from the learners).
  MotionModel Finish() const;
  const std::map<int, Dgmm>& learners() const { return learners_; }

 private:
  MotionModel header_;
  MotionModelOptions options_;
  std::mt19937_64 rng_;
  std::map<int, Dgmm> learners_;
};

// A model with no mixtures yet, carrying the set's dims, names, command table, transform and
// source: y = x || z when with_terrain and the set has terrain, else x alone.
MotionModel ModelHeaderFor(const SampleSet& set, bool with_terrain);

// The options with the DGMM's S0 and floor resolved against the set's pooled within-command
// variance of y (core/data_scale.h, ResolveDgmmOptions); *warning as there. For kUser the
// diagonal must have dim(y) entries (InputError otherwise).
MotionModelOptions ResolveMotionModelOptions(const SampleSet& set, const MotionModelOptions& options,
                                             std::string* warning = nullptr);
// As above with v given (e.g. from a file pass); `header` supplies names and dimensions only.
MotionModelOptions ResolveMotionModelOptions(const SampleSet& header,
                                             const MotionModelOptions& options,
                                             const Eigen::VectorXd& v, std::string* warning);

// Streams the samples in set order through one Dgmm per command (a command with no samples has
// no model), after resolving the options against the set (ResolveMotionModelOptions, a first
// pass). The rng is seeded once from options.seed, so same seed, same model.
MotionModel LearnMotionModel(const SampleSet& set, const MotionModelOptions& options);

// Total log-likelihood of the set under the model: sum_i log p(x_i | c_i [, z_i]), using the
// terrain when the model has it. Always in the raw units of x: when the model carries a
// standardisation, raw sets are standardised first and log|scale_x| is subtracted. Throws
// InputError on dimension mismatch, unknown command or a transform that differs from the set's.
struct ScoreSummary {
  double total_log_likelihood = 0;
  double mean_log_likelihood = 0;
  int samples = 0;
};
ScoreSummary ScoreSampleSet(const MotionModel& model, const SampleSet& set);
// log p(x_i | c_i [, z_i]) of every sample, in the raw units of x, with the checks above.
Eigen::VectorXd ScoreSamples(const MotionModel& model, const SampleSet& set);

// The model's command id for command index `index` of `set`: by label when both have labels (an
// unknown label is an InputError "<source>: command: unknown command ..." listing the model's),
// else the index itself.
int ModelCommandId(const MotionModel& model, const SampleSet& set, int index, const std::string& source = "");

}  // namespace dgmm
