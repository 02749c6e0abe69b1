#include "sim2real/inputs.h"

#include <algorithm>
#include <map>
#include <set>

#include "sim2real/sentence_format.h"
#include "util/error.h"

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

Recording SimRecording(const SampleSet& sim, std::uint64_t fallback_seed, bool* from_metadata) {
  Recording r;
  r.protocol = "paper";
  r.seed = fallback_seed;
  auto protocol = sim.metadata.find("protocol");
  auto seed = sim.metadata.find("seed");
  *from_metadata = protocol != sim.metadata.end() && seed != sim.metadata.end();
  if (protocol != sim.metadata.end()) r.protocol = protocol->second;
  if (seed != sim.metadata.end()) {
    try {
      r.seed = std::stoull(seed->second);
    } catch (const std::exception&) {
      throw MakeInputError("--sim", "metadata seed", "'" + seed->second + "' is not a non-negative integer");
    }
  }
  return r;
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
  DetectTerrainColumns(in.real_set, &in.pitch_col, &in.roll_col);
  return in;
}

PlacementsPerCommand CountPlacementsPerCommand(const AnalysisInputs& in) {
  auto median = [&](const Samples& s) {
    std::map<int, std::set<int>> placements;  // per command
    for (int i = 0; i < s.size(); ++i) placements[s.command[i]].insert(s.episode[i]);
    std::vector<double> counts;
    for (int c : in.real_commands) counts.push_back(placements.count(c) ? placements[c].size() : 0.0);
    if (counts.empty()) return 0.0;
    std::nth_element(counts.begin(), counts.begin() + counts.size() / 2, counts.end());
    return counts[counts.size() / 2];
  };
  return {median(in.sim), median(in.real)};
}

std::string SmallSimSetNote(const AnalysisInputs& in, const std::string& sim_path) {
  const PlacementsPerCommand n = CountPlacementsPerCommand(in);
  if (n.sim > n.real) return "";
  return sim_path + Fmt(": %g placements per command (median), no more than the real set's %g", n.sim, n.real) +
         ": locate compares the real residuals with the sim set's cross-fitted ones, which hold whole placements "
         "out, and with as few sim placements it finds mismatch between two recordings of the same robot; record "
         "the sim set with more placements (e.g. dgmm simulate --protocol paper --placements 166)";
}

}  // namespace dgmm::sim2real
