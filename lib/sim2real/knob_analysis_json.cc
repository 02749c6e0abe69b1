#include <nlohmann/json.hpp>

#include <cmath>
#include <vector>

#include "sim2real/knob_analysis.h"

namespace dgmm::sim2real {

std::string KnobAnalysisJson(const KnobAnalysis& a) {
  using json = nlohmann::json;
  json cands = json::array();
  for (const auto& c : a.candidates) {
    cands.push_back({{"key", c.key}, {"family", c.family}, {"knob", c.knob}, {"nominal", c.nominal},
                     {"probe", c.probe}, {"range", {c.lo, c.hi}}, {"simulated", c.physical}});
  }
  json steps = json::array();
  for (const auto& s : a.steps) {
    json cs = json::array();
    for (const auto& c : s.candidates) {
      cs.push_back({{"key", a.candidates[c.effect].key}, {"gain", c.gain}, {"se", c.se}, {"z", c.z}});
    }
    steps.push_back({{"chosen", s.chosen >= 0 ? json(a.candidates[s.chosen].key) : json(nullptr)},
                     {"threshold_z", s.threshold_z}, {"candidates", cs}});
  }
  json tests = json::array();
  for (const auto& t : a.residual.tests) {
    tests.push_back({{"where", t.where}, {"statistic", t.statistic}, {"p_value", t.p_value}, {"significant", t.significant}});
  }
  json drift = json::array();
  for (const auto& d : a.drift_tests) {
    const EffectDrift& v = d.step_variation;
    drift.push_back({{"key", a.candidates[d.candidate].key}, {"relative_change", d.drift.gamma},
                     {"p_value", d.drift.p_value}, {"z", d.drift.z}, {"episodes", d.drift.episodes}, {"drifting", d.drift.drifting},
                     {"step_variation", {{"relative_rms", v.gamma}, {"p_value", v.p_value}, {"z", v.z}, {"varies", v.drifting}}}});
  }
  json trace = json::array();
  for (const auto& r : a.refine_trace) trace.push_back({{"knob", r.knob}, {"value", r.value}, {"coefficient", r.coefficient}});
  json spread = nullptr;
  if (a.spread.tested) {
    std::vector<double> log_k(a.spread.knob_log_ratio.data(), a.spread.knob_log_ratio.data() + a.spread.knob_log_ratio.size());
    spread = {{"knob_log_variance_ratio", log_k}, {"tracker_coefficient", a.spread.a}, {"gain", a.spread.gain},
              {"se", a.spread.se}, {"z", a.spread.z}, {"tracker_needed", a.spread.tracker_needed},
              {"tracker_scale", std::isfinite(a.tracker_scale) ? json(a.tracker_scale) : json(nullptr)}};
  }
  json removed = json::array();
  for (int k : a.removed) removed.push_back(a.candidates[k].key);
  json out = {{"candidates", cands},
              {"selection_steps", steps},
              {"refinement", trace},
              {"removed_by_backward_pass", removed},
              {"inert_knobs", a.inert_knobs},
              {"residual_tests", tests},
              {"drift_tests", drift},
              {"spread", spread},
              {"total_drift", {{"relative_change", a.total_drift.gamma}, {"p_value", a.total_drift.p_value},
                               {"z", a.total_drift.z}, {"drifting", a.total_drift.drifting}}},
              {"total_step_variation", {{"relative_rms", a.total_step_variation.gamma},
                                        {"p_value", a.total_step_variation.p_value},
                                        {"z", a.total_step_variation.z}, {"varies", a.total_step_variation.drifting}}},
              {"simulations", a.simulations},
              {"from_cache", a.from_cache},
              {"signature_simulations", a.signature_simulations},
              {"signature_requests", a.signature_requests},
              {"placements_per_simulation", a.placements},
              {"cache_dir", a.cache_dir},
              {"signature_seconds", a.signature_seconds},
              {"refine_seconds", a.refine_seconds},
              {"experiment_checks", a.experiment_checks},
              {"experiment_check_seconds", a.experiment_seconds},
              {"seconds", a.seconds},
              {"heldout_ll", {{"sim", a.ll_sim}, {"corrected", a.ll_corrected}, {"ceiling", a.ll_ceiling}}},
              {"note", a.note}};
  return out.dump();
}

}  // namespace dgmm::sim2real
