#include "app/cv_flags.h"

#include "app/command.h"
#include "util/error.h"

namespace dgmm::app {

void AddCvFlags(CLI::App* cmd, CvFlags* flags) {
  cmd->add_option("set", flags->path, "Sample set (.h5)")->required();
  cmd->add_option("--folds", flags->folds,
                  "Folds, >= 2 (whole episodes when the set has enough, else stratified by "
                  "command); default: chosen from the data (leave-one-episode-out for up to 10 "
                  "episodes, else 10 folds; stratified: at most the smallest command's samples)");
  cmd->add_option("--repeats", flags->repeats, "Repeats with new folds")->capture_default_str();
  cmd->add_option("--seed", flags->seed, "Seed of folds and merges (the same for every evaluation)")
      ->capture_default_str();
  cmd->add_option("--threads", flags->threads, "Worker threads (0: all cores)")
      ->capture_default_str();
  cmd->add_flag("--shuffle-training", flags->shuffle_training,
                "Stream each training fold in a seeded random order (default: recorded order)");
  cmd->add_flag("--stratified", flags->stratified,
                "Folds stratified by command even when the set has episodes (default: whole "
                "episodes per fold when it has them)");
  cmd->add_option("--pose-dims", flags->pose_dims,
                  "Pose dimensions to model, by name (default: all)")
      ->delimiter(',');
  cmd->add_option("--terrain-dims", flags->terrain_dims,
                  "Terrain dimensions to condition on, by name (default: all)")
      ->delimiter(',');
  cmd->add_flag("--json", flags->json, "Print JSON");
}

void NoteFoldsGiven(const CLI::App& cmd, CvFlags* flags) { flags->folds_given = cmd.count("--folds") > 0; }

SampleSet ReadCvSet(const CvFlags& flags) {
  if (flags.folds_given && flags.folds < 2) {
    throw MakeInputError(flags.path, "--folds", "must be >= 2 (omit --folds to choose from the data)");
  }
  if (flags.repeats < 1) throw MakeInputError(flags.path, "--repeats", "must be >= 1");
  return ReadSetToCrossValidate(flags.path, flags.pose_dims, flags.terrain_dims, flags.with_terrain,
                                flags.without_terrain);
}

void SetCvOptions(const CvFlags& flags, const SampleSet& set, CvOptions* cv) {
  cv->folds = CheckedFolds(set, flags.folds, flags.folds_given, !flags.stratified, flags.path);
  cv->group_by_episode = !flags.stratified;
  cv->repeats = flags.repeats;
  cv->seed = flags.seed;
  cv->threads = flags.threads;
  cv->shuffle_training = flags.shuffle_training;
}

}  // namespace dgmm::app
