#include "sim2real/verdict.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "sim2real/search_span_json.h"
#include "sim2real/sentence_format.h"

namespace dgmm::sim2real {

using json = nlohmann::json;

std::string DescribeExperiment(const VerdictExperiment& e) {
  if (e.commands.empty() || e.terrain.empty()) return "";
  std::string s = "record command " + e.commands[0] + " on " + e.terrain[0] + Fmt(" about %.0f times", e.executions);
  if (!e.checked_by_simulation) {
    s += " (not checked by simulation: " + e.not_checked_because + ")";
  } else if (e.confirmed) {
    s += Fmt(" (checked by simulation, %.0f executions at each fitted value: the proposed experiment separates "
             "them, z %.1f >= %.2f", e.executions_simulated, e.z, e.z_required) + Fmt(", p %.3g)", e.p_value);
  } else if (e.executions_needed < 0) {
    s += Fmt(" (checked by simulation, %.0f executions at each fitted value: the two make no measurable "
             "difference in that cell, p %.3g; the proposed experiment would not separate them)",
             e.executions_simulated, e.p_value);
  } else {
    s += Fmt(" (checked by simulation, %.0f executions at each fitted value: the proposed experiment would not "
             "separate them, z %.1f (needed %.2f)", e.executions_simulated, e.z, e.z_required) +
         Fmt(", p %.3g; more executions needed: %.0f)", e.p_value, e.executions_needed);
  }
  return s;
}

std::string VerdictJson(const Verdict& v) {
  json named = json::array();
  for (const auto& n : v.named) {
    named.push_back({{"family", n.family}, {"knob", n.knob}, {"value", JsonNumber(n.value)}, {"unit", n.unit},
                     {"nominal", JsonNumber(n.nominal)}, {"fitted_value", JsonNumber(n.fitted)},
                     {"range", {JsonNumber(n.lo), JsonNumber(n.hi)}}, {"ci95", {JsonNumber(n.value_lower), JsonNumber(n.value_upper)}},
                     {"fits_as_well", SearchSpanJson(n.as_well)},
                     {"inclusion", n.inclusion < 0 ? json(nullptr) : json(n.inclusion)},
                     {"candidate_inclusion", n.candidate_inclusion < 0 ? json(nullptr) : json(n.candidate_inclusion)},
                     {"scope_inclusion", n.scope_inclusion < 0 ? json(nullptr) : json(n.scope_inclusion)},
                     {"tie_group", n.tie_group < 0 ? json(nullptr) : json(n.tie_group)},
                     {"flags", n.flags}, {"doubts", n.doubts}});
  }
  json ties = json::array();
  for (const auto& t : v.ties) {
    const VerdictExperiment& e = t.experiment;
    json experiment = {{"commands", e.commands},
                       {"terrain", e.terrain},
                       {"executions", e.executions},
                       {"separation_per_execution", e.separation},
                       {"checked_by_simulation", e.checked_by_simulation},
                       {"confirmed", e.checked_by_simulation ? json(e.confirmed) : json(nullptr)},
                       {"not_checked_because", e.checked_by_simulation ? json(nullptr) : json(e.not_checked_because)}};
    if (e.checked_by_simulation) {
      experiment["simulation"] = {{"knobs", e.simulated_knobs},
                                  {"values", e.simulated_values},
                                  {"executions", e.executions_simulated},
                                  {"placements", e.placements},
                                  {"seed", e.seed},
                                  {"heading_deg", e.heading_deg},
                                  {"spread_scale", e.spread_scale},
                                  {"separation_per_execution", e.simulated_separation},
                                  {"z", e.z},
                                  {"z_required", e.z_required},
                                  {"p_value", e.p_value},
                                  {"executions_needed", e.executions_needed < 0 ? json(nullptr) : json(e.executions_needed)},
                                  {"seconds", e.seconds}};
    } else {
      experiment["simulation"] = nullptr;
    }
    ties.push_back({{"families", t.families}, {"why", t.why}, {"experiment", experiment}});
  }
  json drifting = json::array();
  for (const auto& d : v.drifting) {
    json e = {{"family", d.family}, {"knob", d.knob}, {"unit", d.unit}, {"along", d.along},
              {"value", JsonNumber(d.value)}, {"nominal", JsonNumber(d.nominal)},
              {"relative_change", JsonNumber(d.gamma)}, {"p_value", JsonNumber(d.p_value)},
              {"inclusion", d.inclusion < 0 ? json(nullptr) : json(d.inclusion)}};
    if (d.along == "session order") {
      e["first"] = JsonNumber(d.first), e["last"] = JsonNumber(d.last);
    } else {
      e["lowest"] = JsonNumber(d.first), e["lowest_step"] = d.first_step;
      e["highest"] = JsonNumber(d.last), e["highest_step"] = d.last_step;
    }
    drifting.push_back(e);
  }
  json weak = json::array();
  for (const auto& w : v.weak) {
    weak.push_back({{"family", w.family}, {"knob", w.knob}, {"value", JsonNumber(w.value)}, {"inclusion", w.inclusion}});
  }
  json out = {{"status", v.status},
              {"sentence", v.sentence},
              {"named", named},
              {"not_named_low_inclusion", weak},
              {"inclusion_threshold", v.min_inclusion},
              {"doubts", v.doubts},
              {"ties", ties},
              {"drifting", drifting},
              {"unexplained", {{"present", v.unexplained_present}, {"structured_in", v.structured_in}}},
              {"gap_closed", JsonNumber(v.gap_closed)}};
  return out.dump();
}

void AddVerdictDoubt(const std::string& doubt, Verdict* v) {
  v->doubts.push_back(doubt);
  if (v->status == "explained") v->status = "partly_explained";
  if (v->status == "clean") v->status = "unexplained";
}

}  // namespace dgmm::sim2real
