#include "sim2real/samples.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>

#include "util/error.h"

namespace dgmm::sim2real {
namespace {

// "Delta_Yaw (body)" -> "yaw": lower case, letters only, without a leading "delta"/"d".
std::string Canonical(const std::string& name) {
  std::string s;
  for (char ch : name) {
    if (std::isalpha(static_cast<unsigned char>(ch))) s += std::tolower(static_cast<unsigned char>(ch));
  }
  for (const char* suffix : {"body", "world", "rad", "m"}) {
    std::string suf(suffix);
    if (s.size() > suf.size() + 1 && s.ends_with(suf)) s.resize(s.size() - suf.size());
  }
  if (s.starts_with("delta")) return s.substr(5);
  if (s.size() > 1 && s[0] == 'd') return s.substr(1);
  return s;
}

}  // namespace

PoseLayout DetectPoseLayout(const SampleSet& set) {
  PoseLayout layout;
  std::map<std::string, int*> slots = {{"x", &layout.dx},        {"y", &layout.dy},
                                       {"z", &layout.dz},        {"roll", &layout.droll},
                                       {"pitch", &layout.dpitch}, {"yaw", &layout.dyaw}};
  int found = 0;
  for (int j = 0; j < static_cast<int>(set.x_names.size()) && j < set.pose_dim(); ++j) {
    auto it = slots.find(Canonical(set.x_names[j]));
    if (it != slots.end() && *it->second < 0) {
      *it->second = j;
      ++found;
    }
  }
  if (found == 0 && set.pose_dim() == 6) {
    layout = PoseLayout{0, 1, 2, 3, 4, 5};
  }
  return layout;
}

void DetectTerrainColumns(const SampleSet& set, int* pitch, int* roll) {
  *pitch = -1;
  *roll = -1;
  for (int j = 0; j < static_cast<int>(set.z_names.size()) && j < set.terrain_dim(); ++j) {
    std::string c = Canonical(set.z_names[j]);
    if (c == "pitch" && *pitch < 0) *pitch = j;
    if (c == "roll" && *roll < 0) *roll = j;
  }
  if (*pitch < 0 && *roll < 0 && set.terrain_dim() >= 2) {
    *pitch = 0;
    *roll = 1;
  }
}

Samples MakeSamples(const SampleSet& set) {
  std::vector<int> identity(set.num_commands());
  for (int c = 0; c < set.num_commands(); ++c) identity[c] = c;
  return MakeSamples(set, identity);
}

Samples MakeSamples(const SampleSet& set, const std::vector<int>& command_map) {
  std::vector<int> rows;
  for (int i = 0; i < set.size(); ++i) {
    int c = set.command(i);
    if (c >= 0 && c < static_cast<int>(command_map.size()) && command_map[c] >= 0) rows.push_back(i);
  }
  Samples s;
  const int n = static_cast<int>(rows.size());
  s.x.resize(n, set.pose_dim());
  s.z.resize(n, set.terrain_dim());
  s.has_sequence = set.has_sequence();
  for (int k = 0; k < n; ++k) {
    const int i = rows[k];
    s.command.push_back(command_map[set.command(i)]);
    s.x.row(k) = set.x.row(i);
    if (set.terrain_dim() > 0) s.z.row(k) = set.z.row(i);
    if (s.has_sequence) {
      s.episode.push_back(set.episode(i));
      s.first_execution.push_back(set.step(i) == 0 ? 1 : 0);
    } else {
      s.episode.push_back(i);
      s.first_execution.push_back(0);
    }
  }
  // A command that differs from the previous sample's command within the same episode also counts
  // as a change (protocols that vary the command inside a placement).
  if (s.has_sequence) {
    for (int k = 1; k < n; ++k) {
      if (s.episode[k] == s.episode[k - 1] && s.command[k] != s.command[k - 1]) {
        s.first_execution[k] = 1;
      }
    }
  }
  return s;
}

std::vector<int> AlignCommands(const SampleSet& sim, const SampleSet& real) {
  if (sim.pose_dim() != real.pose_dim()) {
    throw MakeInputError("", "x", "the sim set has " + std::to_string(sim.pose_dim()) +
                                      " pose dimensions, the real set " +
                                      std::to_string(real.pose_dim()));
  }
  if (sim.terrain_dim() != real.terrain_dim()) {
    throw MakeInputError("", "z", "the sim set has " + std::to_string(sim.terrain_dim()) +
                                      " terrain dimensions, the real set " +
                                      std::to_string(real.terrain_dim()));
  }
  std::vector<int> map(real.num_commands(), -1);
  for (int r = 0; r < real.num_commands(); ++r) {
    for (int s = 0; s < sim.num_commands(); ++s) {
      bool same_label = r < static_cast<int>(real.command_labels.size()) &&
                        s < static_cast<int>(sim.command_labels.size()) &&
                        !real.command_labels[r].empty() &&
                        real.command_labels[r] == sim.command_labels[s];
      bool same_values = real.commands.cols() == sim.commands.cols() &&
                         real.commands.cols() > 0 &&
                         (real.commands.row(r) - sim.commands.row(s)).cwiseAbs().maxCoeff() < 1e-9;
      if (same_label || same_values) {
        map[r] = s;
        break;
      }
    }
    if (map[r] < 0 && real.num_commands() == 1 && sim.num_commands() == 1) map[r] = 0;
  }
  return map;
}

Samples SubsetSamples(const Samples& s, const std::vector<int>& rows) {
  Samples out;
  const int n = static_cast<int>(rows.size());
  out.x.resize(n, s.pose_dim());
  out.z.resize(n, s.terrain_dim());
  out.has_sequence = s.has_sequence;
  for (int k = 0; k < n; ++k) {
    const int i = rows[k];
    out.command.push_back(s.command[i]);
    out.x.row(k) = s.x.row(i);
    if (s.terrain_dim() > 0) out.z.row(k) = s.z.row(i);
    out.episode.push_back(s.episode[i]);
    out.first_execution.push_back(s.first_execution[i]);
  }
  return out;
}

SampleSet ToRawUnits(const SampleSet& set, const std::string& which) {
  if (set.transform.empty()) return set;
  const int dx = set.pose_dim(), dz = set.terrain_dim();
  const auto& t = set.transform;
  if (t.offset.size() != dx + dz || t.scale.size() != dx + dz) {
    throw MakeInputError(which, "transform", "standardisation has " + std::to_string(t.offset.size()) +
                                                 " offsets and " + std::to_string(t.scale.size()) +
                                                 " scales, expected x + z = " + std::to_string(dx + dz) +
                                                 ": cannot reconcile it with the other set");
  }
  if (!t.offset.allFinite() || !t.scale.allFinite() || (t.scale.array() <= 0).any()) {
    throw MakeInputError(which, "transform", "standardisation scales must be finite and positive");
  }
  SampleSet out = set;
  for (int j = 0; j < dx; ++j) out.x.col(j) = (set.x.col(j).array() * t.scale(j) + t.offset(j)).matrix();
  for (int j = 0; j < dz; ++j) out.z.col(j) = (set.z.col(j).array() * t.scale(dx + j) + t.offset(dx + j)).matrix();
  out.transform = Standardization{};
  return out;
}

}  // namespace dgmm::sim2real
