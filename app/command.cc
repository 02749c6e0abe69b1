#include "app/command.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <map>

#include <fmt/format.h>

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
  if (ShowProgress()) {
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
    std::fprintf(stderr, "dgmm: %s: %lld/%lld done in %.1f s\n", label.c_str(), done, total, elapsed);
  }
  std::fflush(stderr);
}

void ReportStage(const std::string& text) {
  if (g_quiet) return;
  std::fprintf(stderr, "dgmm: %s\n", text.c_str());
  std::fflush(stderr);
}

void WarnIfUnderdetermined(const SampleSet& set, bool with_terrain, const std::string& what) {
  const int d = set.pose_dim() + (with_terrain ? set.terrain_dim() : 0);
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
  Warn(what + ": fewer samples than the " + std::to_string(parameters) +
       " parameters of one Gaussian in d = " + std::to_string(d) + " for command(s) " + list +
       "; their components rest on the covariance floor and prior more than on data (record more "
       "samples, or use --pose-dims/--terrain-dims or --without-terrain)");
}

InputError OptionsError(const std::string& file, const std::string& message,
                        const std::vector<std::pair<std::string, std::string>>& flags) {
  for (const auto& [field, flag] : flags) {
    if (message.find(field) != std::string::npos) return MakeInputError(file, flag, message);
  }
  return MakeInputError(file, "options", message);
}

void RefuseMoreFoldsThanSamples(const SampleSet& set, int folds, const std::string& path) {
  std::map<int, int> per_command;
  for (int i = 0; i < set.size(); ++i) ++per_command[set.command[i]];
  for (const auto& [id, count] : per_command) {
    if (folds <= count) continue;
    const std::string label =
        id < static_cast<int>(set.command_labels.size()) ? " '" + set.command_labels[id] + "'" : "";
    throw MakeInputError(path, "--folds",
                         fmt::format("{} folds, but command {}{} has {} samples ({} in all); at "
                                     "most {} folds expected",
                                     folds, id, label, count, set.size(), count));
  }
}

void Warn(const std::string& text) {
  if (g_quiet) return;
  std::fprintf(stderr, "dgmm: warning: %s\n", text.c_str());
  std::fflush(stderr);
}

}  // namespace dgmm::app
