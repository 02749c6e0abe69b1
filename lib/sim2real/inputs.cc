#include "sim2real/inputs.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/set_warnings.h"
#include "sim2real/sentence_format.h"
#include "util/error.h"
#include "util/median.h"

namespace dgmm::sim2real {
namespace {

// The real samples whose command the sim set has; their source rows; what was dropped.
void KeepSharedCommands(AnalysisInputs* in, const std::vector<int>& real_map) {
  const std::set<int> sim_commands(in->sim.command.begin(), in->sim.command.end());
  std::vector<int> keep, rows;
  int k = 0;
  std::set<int> dropped;
  for (int i = 0; i < in->real_set.size(); ++i) {
    const int c = in->real_set.command(i);
    const bool mapped = real_map[c] >= 0;
    if (mapped && sim_commands.count(real_map[c])) {
      keep.push_back(k);
      rows.push_back(i);
    } else {
      dropped.insert(c);
      ++in->dropped_samples;
    }
    if (mapped) ++k;  // MakeSamples keeps the set's order for mapped commands
  }
  in->real = SubsetSamples(in->real, keep);
  in->real_source_row = rows;
  for (int c : dropped) {
    in->dropped_commands.push_back(c < static_cast<int>(in->real_set.command_labels.size())
                                       ? in->real_set.command_labels[c] : std::to_string(c));
  }
}

// A seed as metadata holds it: digits only ("12abc" and "-5", which std::stoull reads as 12 and as
// 2^64 - 5, are not seeds).
std::optional<std::uint64_t> ParseSeed(const std::string& text) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  try {
    return std::stoull(text);
  } catch (const std::out_of_range&) {
    return std::nullopt;
  }
}

Recording SimRecording(const SampleSet& sim, std::uint64_t fallback_seed, bool* from_metadata) {
  Recording r;
  r.protocol = "paper";
  r.seed = fallback_seed;
  auto protocol = sim.metadata.find("protocol");
  auto seed = sim.metadata.find("seed");
  *from_metadata = protocol != sim.metadata.end() && seed != sim.metadata.end();
  if (protocol != sim.metadata.end()) r.protocol = protocol->second;
  if (seed != sim.metadata.end()) {
    const auto parsed = ParseSeed(seed->second);
    if (!parsed) throw MakeInputError("--sim", "metadata seed", "'" + seed->second + "' is not a non-negative integer");
    r.seed = *parsed;
  }
  return r;
}

// The real set's recording seed when its metadata has one (a simulated "real" set); a recorded log's
// metadata may hold anything under that name, so what does not read as a seed is ignored.
std::optional<std::uint64_t> RealSeed(const SampleSet& real) {
  const auto seed = real.metadata.find("seed");
  return seed == real.metadata.end() ? std::nullopt : ParseSeed(seed->second);
}

}  // namespace

AnalysisInputs PrepareInputs(const SampleSet& sim_in, const SampleSet& real_in, std::uint64_t fallback_seed) {
  for (const auto* set : {&sim_in, &real_in}) {
    const std::string problem = set->Validate();
    if (!problem.empty()) throw MakeInputError(set == &sim_in ? "--sim" : "--real", "", problem);
  }
  AnalysisInputs in;
  in.sim_set = ToRawUnits(sim_in, "--sim");
  in.real_set = ToRawUnits(real_in, "--real");
  const std::vector<int> real_map = AlignCommands(in.sim_set, in.real_set);
  in.sim = MakeSamples(in.sim_set);
  in.real = MakeSamples(in.real_set, real_map);
  KeepSharedCommands(&in, real_map);
  if (in.real.size() < 10) {
    throw MakeInputError("--real", "", "fewer than 10 real samples share a command with the sim set");
  }
  in.layout = DetectPoseLayout(in.sim_set);
  for (int c = 0; c < in.sim_set.num_commands(); ++c) {
    in.command_labels.push_back(c < static_cast<int>(in.sim_set.command_labels.size())
                                    ? in.sim_set.command_labels[c] : std::to_string(c));
  }
  const std::set<int> rc(in.real.command.begin(), in.real.command.end());
  in.real_commands.assign(rc.begin(), rc.end());
  double first = 0;
  for (int f : in.real.first_execution) first += f;
  in.first_execution_share = first / in.real.size();
  in.recording = SimRecording(in.sim_set, fallback_seed, &in.recording_from_metadata);
  in.real_seed = RealSeed(in.real_set);
  DetectTerrainColumns(in.real_set, &in.pitch_col, &in.roll_col);
  return in;
}

namespace {

// Per command: the mean z of each placement (episode) of s.
std::map<int, std::vector<Eigen::VectorXd>> PlacementSettings(const Samples& s) {
  std::map<int, std::map<int, std::pair<Eigen::VectorXd, int>>> sums;  // command -> episode -> (sum, n)
  for (int i = 0; i < s.size(); ++i) {
    auto& [sum, n] = sums[s.command[i]][s.episode[i]];
    if (n++ == 0) sum = Eigen::VectorXd::Zero(s.z.cols());
    sum += s.z.row(i).transpose();
  }
  std::map<int, std::vector<Eigen::VectorXd>> out;
  for (const auto& [c, episodes] : sums) {
    for (const auto& [e, sn] : episodes) out[c].push_back(sn.first / sn.second);
  }
  return out;
}

// Distance from z to the nearest of `points`, skipping index `skip`; infinite when none is left.
double Nearest(const Eigen::VectorXd& z, const std::vector<Eigen::VectorXd>& points, int skip = -1) {
  double best = INFINITY;
  for (int j = 0; j < static_cast<int>(points.size()); ++j) {
    if (j != skip) best = std::min(best, (points[j] - z).norm());
  }
  return best;
}

}  // namespace

SettingCoverage MeasureSettingCoverage(const AnalysisInputs& in) {
  const auto sim = PlacementSettings(in.sim), real = PlacementSettings(in.real);
  std::vector<double> sim_to_sim, real_to_sim;
  for (int c : in.real_commands) {
    const auto s = sim.find(c), r = real.find(c);
    if (s == sim.end() || r == real.end()) continue;
    for (int p = 0; p < static_cast<int>(s->second.size()); ++p) sim_to_sim.push_back(Nearest(s->second[p], s->second, p));
    for (const Eigen::VectorXd& z : r->second) real_to_sim.push_back(Nearest(z, s->second));
  }
  return {Median(sim_to_sim), Median(real_to_sim)};
}

std::string SmallSimSetNote(const AnalysisInputs& in, const std::string& sim_path, double ratio) {
  if (in.sim.z.cols() == 0) return "";  // no terrain: settings cannot be told apart
  const SettingCoverage c = MeasureSettingCoverage(in);
  if (!(c.sim_to_sim > ratio * c.real_to_sim)) return "";
  const std::string sim_gap = std::isfinite(c.sim_to_sim)
                                  ? Fmt("lies %.3g from its command's nearest other sim placement", c.sim_to_sim)
                                  : "has no other sim placement of its command";
  return sim_path + ": a sim placement's terrain z " + sim_gap +
         Fmt(", a real placement's %.3g from the nearest sim one (medians)", c.real_to_sim) +
         ": locate compares the real residuals with the sim set's cross-fitted ones, which hold whole placements "
         "out, and then finds mismatch between two recordings of the same robot; record the sim set with more "
         "placements (e.g. dgmm simulate --protocol paper --placements 166)";
}

std::vector<std::string> RecordingNotes(const SampleSet& set, const std::string& path) {
  std::vector<std::string> notes;
  for (const std::string& w : KeptWarnings(set)) notes.push_back(path + ": dgmm warned when it made this set: " + w);
  return notes;
}

PlacementCount RealPlacements(const AnalysisInputs& in) {
  if (!in.real_set.has_sequence()) return {in.real_set.size(), 1};
  const std::set<int> placements(in.real_set.episode.data(), in.real_set.episode.data() + in.real_set.size());
  int executions = 0;
  for (int i = 0; i < in.real_set.size(); ++i) executions = std::max(executions, in.real_set.step(i) + 1);
  return {static_cast<int>(placements.size()), executions};
}

std::vector<int> RealSteps(const AnalysisInputs& in) {
  std::vector<int> step(in.real.size(), -1);
  if (in.real.has_sequence && in.real_set.has_sequence()) {
    for (int i = 0; i < in.real.size(); ++i) step[i] = in.real_set.step(in.real_source_row[i]);
  }
  return step;
}

std::vector<int> SimSteps(const AnalysisInputs& in) {
  std::vector<int> step(in.sim.size(), -1);
  if (in.sim.has_sequence && in.sim_set.has_sequence() && in.sim_set.size() == in.sim.size()) {
    for (int i = 0; i < in.sim.size(); ++i) step[i] = in.sim_set.step(i);
  }
  return step;
}

}  // namespace dgmm::sim2real
