#include "app/command.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>

#include "io/sample_set_io.h"
#include "tune/dimensions.h"
#include "tune/fold_plan.h"
#include "util/error.h"

namespace dgmm::app {

std::vector<CommandRegistration>& CommandRegistry() {
  static std::vector<CommandRegistration> registry;
  return registry;
}

CommandRegistrar::CommandRegistrar(std::string name, CommandSetup setup) {
  CommandRegistry().push_back({std::move(name), std::move(setup)});
}

namespace {
bool g_quiet = false;
struct Stage {
  std::string label;
  long long last_done = -1;
  std::chrono::steady_clock::time_point start;
};
Stage g_stage;
}  // namespace

void SetQuiet(bool quiet) { g_quiet = quiet; }
bool Quiet() { return g_quiet; }

bool ShowProgress() { return !g_quiet && ::isatty(STDERR_FILENO) == 1; }

void ReportProgress(const std::string& label, long long done, long long total) {
  if (g_quiet) return;
  const auto now = std::chrono::steady_clock::now();
  if (label != g_stage.label || done < g_stage.last_done) {
    g_stage.label = label;
    g_stage.start = now;
  }
  g_stage.last_done = done;
  const double elapsed = std::chrono::duration<double>(now - g_stage.start).count();
  if (total < 0) {  // total unknown: a running count on a terminal, nothing otherwise
    if (ShowProgress()) std::fprintf(stderr, "\r%s %lld, %.0f s", label.c_str(), done, elapsed);
  } else if (ShowProgress()) {
    std::fprintf(stderr, "\r%s %lld/%lld (%.0f%%), %.0f s", label.c_str(), done, total,
                 total > 0 ? 100.0 * static_cast<double>(done) / static_cast<double>(total) : 100.0,
                 elapsed);
    if (done > 0 && done < total) {
      std::fprintf(stderr, ", about %.0f s left   ",
                   elapsed * static_cast<double>(total - done) / static_cast<double>(done));
    } else {
      std::fprintf(stderr, "                    ");
    }
    if (done >= total) std::fprintf(stderr, "\n");
  } else if (done >= total) {
    std::fprintf(stderr, "dgmm: %s: %lld/%lld done in %s\n", label.c_str(), done, total,
                 FormatSeconds(elapsed).c_str());
  }
  std::fflush(stderr);
}

void ReportStage(const std::string& text) {
  if (g_quiet) return;
  std::fprintf(stderr, "dgmm: %s\n", text.c_str());
  std::fflush(stderr);
}

void WarnIfUnderdetermined(const SampleSet& set, bool with_terrain, const std::string& what,
                           bool accepts_dims) {
  const bool terrain = with_terrain && set.terrain_dim() > 0;
  const int d = set.pose_dim() + (terrain ? set.terrain_dim() : 0);
  const int parameters = d + d * (d + 1) / 2;
  std::vector<int> count(set.num_commands(), 0);
  for (int i = 0; i < set.size(); ++i) ++count[set.command[i]];
  std::string list;
  for (int c = 0; c < set.num_commands(); ++c) {
    if (count[c] >= parameters) continue;
    const std::string name = c < static_cast<int>(set.command_labels.size()) ? set.command_labels[c]
                                                                               : std::to_string(c);
    list += (list.empty() ? "" : ", ") + ("'" + name + "' (" + std::to_string(count[c]) + ")");
  }
  if (list.empty()) return;
  std::vector<std::string> fixes = {"record more samples"};
  if (accepts_dims)
    fixes.push_back("model fewer dimensions with dgmm " + what + " --pose-dims/--terrain-dims");
  if (terrain) fixes.push_back("drop the terrain with dgmm " + what + " --without-terrain");
  std::string fix;
  for (size_t i = 0; i < fixes.size(); ++i) {
    fix += (i == 0 ? "" : i + 1 == fixes.size() ? ", or " : ", ") + fixes[i];
  }
  Warn(what + ": fewer samples than the " + std::to_string(parameters) +
       " parameters of one Gaussian in d = " + std::to_string(d) + " for command(s) " + list +
       "; their components rest on the covariance floor and prior more than on data (" + fix + ")");
}

InputError OptionsError(const std::string& file, const std::string& message,
                        const std::vector<std::pair<std::string, std::string>>& flags) {
  for (const auto& [field, flag] : flags) {
    if (message.find(field) != std::string::npos) return MakeInputError(file, flag, message);
  }
  return MakeInputError(file, "options", message);
}

int CheckedFolds(const SampleSet& set, int folds, bool given, bool group_by_episode,
                 const std::string& path) {
  if (given && folds < 2) {
    throw MakeInputError(
        path, "--folds",
        fmt::format("must be >= 2, got {} (omit --folds to choose from the data)", folds));
  }
  FoldPlan plan;
  try {
    plan = ChooseFolds(set, given ? folds : 0, group_by_episode);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
  if (!given) return 0;
  if (plan.by_episode) return folds;
  std::map<int, int> per_command;
  for (int i = 0; i < set.size(); ++i) ++per_command[set.command[i]];
  for (const auto& [id, count] : per_command) {
    if (folds <= count) continue;
    const std::string label =
        id < static_cast<int>(set.command_labels.size()) ? " '" + set.command_labels[id] + "'" : "";
    throw MakeInputError(path, "--folds",
                         fmt::format("{}, but command {}{} has {} ({} in all); at most {} "
                                     "folds expected (use --folds {} or omit --folds to choose "
                                     "from the data)",
                                     plan.reason, id, label, Plural(count, "sample"), set.size(),
                                     count, std::max(2, count)));
  }
  return folds;
}

namespace {
// Levenshtein distance (insertions, deletions, substitutions).
size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
      diagonal = up;
    }
  }
  return row[b.size()];
}
}  // namespace

std::string DidYouMean(const std::string& word, CLI::App& root) {
  std::string best;
  size_t best_distance = 3;
  for (CLI::App* sub : root.get_subcommands([](CLI::App*) { return true; })) {
    std::vector<std::string> names = sub->get_aliases();
    names.push_back(sub->get_name());
    for (const std::string& name : names) {
      const size_t d = EditDistance(word, name);
      if (d < best_distance) best_distance = d, best = sub->get_name();
    }
  }
  return best.empty() ? "" : " (did you mean '" + best + "'?)";
}

SampleSet ReadSetToCrossValidate(const std::string& path, const std::vector<std::string>& pose_dims,
                                 const std::vector<std::string>& terrain_dims, bool with_terrain,
                                 bool without_terrain) {
  if (with_terrain && without_terrain) {
    throw MakeInputError("", "--with-terrain/--without-terrain", "give at most one");
  }
  SampleSet set = SelectDimensions(ReadSampleSet(path), pose_dims, terrain_dims);
  if (set.size() == 0) throw MakeInputError(path, "samples", "the set is empty");
  if (with_terrain && set.terrain_dim() == 0) {
    throw MakeInputError(path, "z", "--with-terrain needs a set with terrain");
  }
  return set;
}

std::string Plural(long long count, const std::string& noun) {
  return std::to_string(count) + " " + noun + (count == 1 ? "" : "s");
}

std::string FormatSeconds(double seconds) {
  if (!(seconds >= 0) || !std::isfinite(seconds)) return "? s";
  if (seconds < 0.001) return "under 1 ms";
  if (seconds < 10) return fmt::format("{:.2g} s", seconds);
  if (seconds < 120) return fmt::format("{:.0f} s", seconds);
  const long long whole = std::llround(seconds);
  return fmt::format("{} min {:02d} s", whole / 60, static_cast<int>(whole % 60));
}

void Warn(const std::string& text) {
  if (g_quiet) return;
  std::fprintf(stderr, "dgmm: warning: %s\n", text.c_str());
  std::fflush(stderr);
}

}  // namespace dgmm::app
