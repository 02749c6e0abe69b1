#pragma once
// The sim-vs-real analysis's simulator (lib/sim2real/knob_simulator.h) wired to the MuJoCo
// simulator of lib/sim: knobs from sim::EnumerateKnobs, recordings from the protocols of
// lib/sim/protocol.h at the knob values (sim::ApplyKnobs).
#include <memory>
#include <string>
#include <vector>

#include "sim/knobs.h"
#include "sim/sim_config.h"
#include "sim2real/knob_simulator.h"

namespace dgmm::app {

class MujocoKnobSimulator : public sim2real::KnobSimulator {
 public:
  // Loads the robot of `config` and enumerates its knobs. Throws InputError naming the part of
  // the config or model that is wrong.
  explicit MujocoKnobSimulator(const sim::SimConfig& config);

  const std::vector<sim2real::Knob>& knobs() const override { return knobs_; }
  std::string Fingerprint() const override { return fingerprint_; }
  SampleSet Record(const sim2real::Recording& recording, const std::vector<sim2real::KnobValue>& values,
                   int threads) const override;
  sim2real::CellRecording RecordCell(const sim2real::Cell& cell,
                                     const std::vector<sim2real::KnobValue>& values) const override;
  std::string ConfigJson(const std::vector<sim2real::KnobValue>& values) const override;
  double total_mass_kg() const override { return total_mass_kg_; }
  double leg_reach_m() const override { return leg_reach_m_; }
  bool level_ground() const override { return level_ground_; }
  bool plane_ground() const override { return plane_ground_; }
  bool sloped_ground() const override { return sloped_ground_; }

  const sim::SimConfig& config() const { return config_; }

 private:
  std::vector<sim::KnobValue> ToSim(const std::vector<sim2real::KnobValue>& values) const;

  sim::SimConfig config_;
  std::vector<sim::Knob> sim_knobs_;
  std::vector<sim2real::Knob> knobs_;
  std::string fingerprint_;
  double total_mass_kg_ = 0, leg_reach_m_ = 0;
  bool level_ground_ = false;
  bool plane_ground_ = false;
  bool sloped_ground_ = false;
};

}  // namespace dgmm::app
