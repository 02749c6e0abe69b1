#pragma once
// Subcommand registry: each app/<name>.cc registers itself with DGMM_REGISTER_COMMAND, so adding a
// subcommand never touches main.cc.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "util/error.h"

namespace dgmm::app {

// Adds a subcommand (with its options and callback) to the top-level app.
using CommandSetup = std::function<void(CLI::App& root)>;

struct CommandRegistration {
  std::string name;
  CommandSetup setup;
};

std::vector<CommandRegistration>& CommandRegistry();

struct CommandRegistrar {
  CommandRegistrar(std::string name, CommandSetup setup);
};

// `dgmm --quiet ...` (or `dgmm <command> ... --quiet`): no progress, stage lines or warnings.
void SetQuiet(bool quiet);
bool Quiet();

// True when stderr is a terminal and not quiet: live progress lines are shown only then.
bool ShowProgress();

// Progress of one stage (a new label or a smaller `done` starts a new stage; the elapsed time runs
// from the stage's first call). On a terminal: "\r<label> <done>/<total> (p%), <elapsed> s, about
// <eta> s left" (the estimate assumes the remaining steps take as long as the finished ones), a
// newline when done == total. Otherwise one line per stage when it completes: "<label>:
// <total>/<total> done in <FormatSeconds>". total < 0: not known yet (a count on a terminal,
// nothing otherwise). Nothing when quiet.
void ReportProgress(const std::string& label, long long done, long long total);

// "dgmm: <text>" on stderr unless quiet: one line per stage of a long command.
void ReportStage(const std::string& text);

// "dgmm: warning: <text>" on stderr unless quiet.
void Warn(const std::string& text);

// Warns for each command with fewer samples than the d + d(d+1)/2 parameters of one full-
// covariance Gaussian over d = pose (+ terrain) dimensions: its EM or DGMM components are then
// fixed by the covariance floor and initial covariance more than by the data.
// The suggested fix names only flags that `what` accepts (--pose-dims/--terrain-dims when
// accepts_dims; --without-terrain when modelling terrain).
void WarnIfUnderdetermined(const SampleSet& set, bool with_terrain, const std::string& what,
                           bool accepts_dims);

// An Options::IsValid message as InputError "<file>: <flag>: <message>", where flag is the
// command-line flag of the first field in `flags` (pairs field name -> flag, e.g. {"n_init",
// "--n-init"}) that the message mentions; "options" when it mentions none.
InputError OptionsError(const std::string& file, const std::string& message,
                        const std::vector<std::pair<std::string, std::string>>& flags);

// The CvOptions::folds for `--folds` (0: chosen from the data, when the flag was not given), after
// checking that a split exists (tune/fold_plan.h ChooseFolds; InputError "<path>: --folds: ..."
// with the fix otherwise). An explicit --folds must be >= 2 and, for folds stratified by command,
// at most the samples of every command (a huge --folds must not run for minutes on empty folds).
// Used by cv and tune.
int CheckedFolds(const SampleSet& set, int folds, bool given, bool group_by_episode,
                 const std::string& path);

// " (did you mean 'tune'?)" for the subcommand of `root` (name or alias) closest to `word` within
// two edits; "" when none is that close.
std::string DidYouMean(const std::string& word, CLI::App& root);

// The set of `path` with the chosen pose and terrain dimensions (tune/dimensions.h) for cv and
// tune; InputError for an empty set, both terrain flags, or --with-terrain without terrain.
SampleSet ReadSetToCrossValidate(const std::string& path, const std::vector<std::string>& pose_dims,
                                 const std::vector<std::string>& terrain_dims, bool with_terrain,
                                 bool without_terrain);

// "1 component", "2 components": the count and the noun, with an 's' unless the count is 1.
std::string Plural(long long count, const std::string& noun);

// Elapsed seconds to the precision that matters: "0.004 s", "0.35 s", "5.2 s", "42 s",
// "3 min 05 s".
std::string FormatSeconds(double seconds);

}  // namespace dgmm::app

#define DGMM_CONCAT_INNER(a, b) a##b
#define DGMM_CONCAT(a, b) DGMM_CONCAT_INNER(a, b)
// DGMM_REGISTER_COMMAND("fit", SetupFit); at namespace scope in app/fit.cc.
#define DGMM_REGISTER_COMMAND(name, setup) \
  static ::dgmm::app::CommandRegistrar DGMM_CONCAT(dgmm_registrar_, __LINE__)(name, setup)
