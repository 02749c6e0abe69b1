// report.json (report.h).
#include <nlohmann/json.hpp>

#include <cmath>

#include "sim2real/json_number.h"
#include "sim2real/report.h"
#include "sim2real/search_span_json.h"

namespace dgmm::sim2real {
namespace {

using nlohmann::json;

// NaN/Inf are not JSON: null (JsonNumber).
json Vec(const Eigen::VectorXd& v) {
  json out = json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(JsonNumber(v(i)));
  return out;
}

json Regions(const std::vector<Region>& regions) {
  json out = json::array();
  for (const auto& r : regions) {
    out.push_back({{"family", r.family}, {"label", r.label}, {"command", r.command}, {"terrain", r.terrain},
                   {"sequence", r.sequence}, {"n_real", r.n_real}, {"n_sim", r.n_sim},
                   {"deficit_nats_per_sample", JsonNumber(r.deficit)}, {"mmd2", JsonNumber(r.mmd2)}, {"p_value", r.p_value},
                   {"q_value", r.q_value}, {"significant", r.significant}});
  }
  return out;
}

json HeatMap(const Analysis& a, const Eigen::MatrixXd& h) {
  json rows = json::array();
  for (int i = 0; i < h.rows(); ++i) {
    json row = json::array();
    for (int j = 0; j < h.cols(); ++j) row.push_back(JsonNumber(h(i, j)));
    rows.push_back({{"command", a.inputs.command_labels[a.inputs.real_commands[i]]}, {"deficit", row}});
  }
  return {{"terrain", a.baseline.terrain_labels}, {"rows", rows}};
}

json LocateJson(const Analysis& a) {
  const LocateSummary& s = a.baseline.before;
  return {{"terrain_regions", a.baseline.terrain_labels},
          {"significant_mismatch", a.baseline.significant_mismatch},
          {"placement_dependence", {{"statistic", a.baseline.placement.statistic},
                                    {"p_value", a.baseline.placement.p_value},
                                    {"tests_permute", a.baseline.permute_placements ? "placements" : "samples"},
                                    {"why", a.baseline.permute_why}}},
          {"pooled_x_flagged_commands", s.pooled_x_flagged},
          {"conditional_flagged_regions", s.conditional_flagged},
          {"regions", Regions(s.regions)},
          {"heat_map", HeatMap(a, s.heat)}};
}

json StepsJson(const Analysis& a) {
  json steps = json::array();
  for (const auto& s : a.refinement.selection.steps) {
    json cs = json::array();
    for (const auto& c : s.candidates) {
      cs.push_back({{"key", a.candidates.candidates[c.effect].key}, {"gain", c.gain}, {"se", JsonNumber(c.se)}, {"z", c.z}});
    }
    steps.push_back({{"chosen", s.chosen >= 0 ? json(a.candidates.candidates[s.chosen].key) : json(nullptr)},
                     {"threshold_z", s.threshold_z}, {"candidates", cs}});
  }
  return steps;
}

// The walk's own chance (walk_chance.h): the replica's paired ratio per axis, each candidate's share.
json WalkChanceJson(const Analysis& a) {
  const WalkChance& w = a.candidates.chance;
  if (!w.measured) return {{"measured", false}, {"why_not", w.why_not}};
  json ratio = json::object(), share = json::object();
  const auto& names = a.inputs.sim_set.x_names;
  for (int j = 0; j < w.paired_ratio.size(); ++j) {
    ratio[j < static_cast<int>(names.size()) ? names[j] : std::to_string(j)] = JsonNumber(w.paired_ratio(j));
  }
  for (size_t k = 0; k < a.candidates.chance_share.size(); ++k) {
    const double v = a.candidates.chance_share[k];
    if (!std::isnan(v)) share[a.candidates.candidates[k].key] = JsonNumber(v);
  }
  return {{"measured", true}, {"added_payload_kg", w.added_kg}, {"paired_ratio", ratio},
          {"largest_ratio", JsonNumber(w.largest_ratio)}, {"chance_share", share}};
}

json KnobsJson(const Analysis& a) {
  const CandidateSet& set = a.candidates;
  const Refinement& r = a.refinement;
  json cands = json::array();
  for (size_t k = 0; k < set.candidates.size(); ++k) {
    const auto& c = set.candidates[k];
    cands.push_back({{"key", c.key}, {"family", c.family}, {"knob", c.knob}, {"nominal", c.nominal}, {"probe", c.probe},
                     {"range", {c.lo, c.hi}}, {"simulated", c.simulated},
                     {"inclusion", a.confidence.computed ? JsonNumber(a.confidence.inclusion[k]) : json(nullptr)}});
  }
  json trace = json::array();
  for (const auto& s : r.trace) {
    trace.push_back({{"knob", s.knob}, {"value", s.value}, {"coefficient", JsonNumber(s.coefficient)}, {"score", JsonNumber(s.score)}});
  }
  json refined = json::array();
  for (const auto& f : r.refined) {
    refined.push_back({{"knob", f.knob}, {"value", f.value}, {"coefficient", JsonNumber(f.coefficient)}, {"converged", f.converged},
                       {"fits_as_well", SearchSpanJson(f.as_well)}, {"single_peaked", f.rugged.empty()}});
  }
  json removed = json::array();
  for (int k : r.selection.removed) removed.push_back(set.candidates[k].key);
  json family = json::object();
  for (const auto& [f, v] : a.confidence.family_inclusion) family[f] = v;
  json spread = nullptr;
  if (r.spread.tested) {
    spread = {{"knob_log_variance_ratio", Vec(r.spread.knob_log_ratio)}, {"tracker_coefficient", r.spread.a},
              {"gain", r.spread.gain}, {"se", r.spread.se}, {"z", r.spread.z}, {"tracker_needed", r.spread.tracker_needed},
              {"tracker_scale", JsonNumber(r.tracker_scale)}};
  }
  json out = {{"candidates", cands}, {"selection_steps", StepsJson(a)}, {"removed_by_backward_pass", removed},
          {"refinement", trace}, {"refined", refined}, {"family_inclusion", family},
          {"bootstrap_resamples", a.confidence.resamples}, {"inert_knobs", set.inert_knobs},
          {"unwalkable_probes", set.unwalkable_probes}, {"walk_chance", WalkChanceJson(a)},
          {"per_leg_probes", {{"recorded", set.legs_probed}, {"why", set.legs_note}}}, {"spread", spread},
          {"recordings", {{"signatures", set.recorded}, {"signatures_from_cache", set.from_cache},
                          {"signature_requests", set.requests}, {"refinement", r.recorded},
                          {"refinement_from_cache", r.from_cache}}},
          {"placements_per_recording", set.recording.placements},
          {"executions_per_placement", set.recording.executions_per_placement},
          {"every_execution_because", a.every_execution_because.empty() ? json(nullptr) : json(a.every_execution_because)}};
  if (set.spread_signatures) {  // --spread-signatures (experimental): the fitted per-axis log variance ratio
    out["spread_signatures"] = {{"on", true}, {"fitted_log_variance_ratio", Vec(r.selection.fit.log_var)}};
  }
  return out;
}

json DriftJson(const EffectDrift& d, const char* change, const char* flag) {
  return {{change, JsonNumber(d.gamma)}, {"p_value", JsonNumber(d.p_value)}, {"z", JsonNumber(d.z)}, {flag, d.drifting}};
}

json AdequacyJson(const Analysis& a) {
  const Adequacy& q = a.adequacy;
  json tests = json::array();
  for (const auto& t : q.residual.tests) {
    tests.push_back({{"where", t.where}, {"statistic", t.statistic}, {"p_value", t.p_value}, {"significant", t.significant}});
  }
  json drift = json::array();
  for (const auto& d : q.drift_tests) {
    json e = DriftJson(d.drift, "relative_change", "drifting");
    e["key"] = a.candidates.candidates[d.candidate].key;
    e["step_variation"] = DriftJson(d.step_variation, "relative_rms", "varies");
    drift.push_back(e);
  }
  json checks = json::array();
  for (const auto& c : q.checks) {
    checks.push_back({{"key", a.candidates.candidates[c.candidate].key}, {"fitted_value", JsonNumber(c.fitted)},
                      {"value", JsonNumber(c.value)}, {"outside_range", c.outside_range}, {"pinned_low", c.pinned_low},
                      {"pinned_high", c.pinned_high}, {"impossible", c.impossible}, {"unconverged", c.unconverged},
                      {"not_single_peaked", c.rugged}, {"chaotic_walk", c.chaotic},
                      {"chance_share", JsonNumber(c.chance_share)}, {"doubts", c.doubts}});
  }
  return {{"regions_after", Regions(q.after.regions)}, {"conditional_flagged_regions_after", q.after.conditional_flagged},
          {"heat_map_after", HeatMap(a, q.after.heat)},
          {"shortfall_nats_per_sample", JsonNumber(q.shortfall)}, {"shortfall_se", JsonNumber(q.shortfall_se)},
          {"null_shortfall_nats_per_sample", JsonNumber(a.null_shortfall.mean)},
          {"null_shortfall_sd", JsonNumber(a.null_shortfall.sd)},
          {"null_shortfall_se", JsonNumber(a.null_shortfall.mean_se)},
          {"null_shortfall_source", a.null_shortfall.recorded ? "recorded" : "drawn"},
          {"null_shortfall_draws", a.null_shortfall.draws},
          {"null_shortfall_recorded", a.null_shortfall.recordings},
          {"excess_shortfall_nats_per_sample", JsonNumber(q.excess_shortfall)},
          {"excess_shortfall_se", JsonNumber(q.excess_shortfall_se)},
          {"below_ceiling", q.below_ceiling}, {"knob_checks", checks}, {"residual_tests", tests},
          {"drift_tests", drift}, {"total_drift", DriftJson(q.total_drift, "relative_change", "drifting")},
          {"total_step_variation", DriftJson(q.total_step_variation, "relative_rms", "varies")},
          {"doubts", q.doubts}};
}

// The fit of what the verdict names: the runoff's or the leg search's correction when it named a
// knob (its recordings' own models score real samples they never saw, so there is no SE of
// folds), else the knob correction's held-out fit.
json FitJson(const Analysis& a) {
  const Baseline& b = a.baseline;
  const LegSearch* own = NamedByOwnModels(a);
  const LegSearch& l = own ? *own : a.leg_search;
  const bool leg = own != nullptr;
  const json corrected = leg ? JsonNumber(BestScore(l))
                             : a.knobs_analysed ? JsonNumber(a.adequacy.ll_corrected) : json(nullptr);
  return {{"heldout_log_likelihood_per_sample",
           {{"sim", b.ll_sim}, {"corrected", corrected},
            {"real_trained_ceiling", b.ll_ceiling}, {"real_only", b.ll_real_only},
            {"ceiling_sim_prior_count", b.ceiling_prior_count}}},
          {"corrected_by", !a.knobs_analysed ? json(nullptr) : json(leg ? own->by : "knobs")},
          {"gap_closed", leg ? JsonNumber(l.gap_closed) : a.knobs_analysed ? JsonNumber(a.adequacy.gap_closed) : json(nullptr)},
          {"gap_closed_se", !leg && a.knobs_analysed ? JsonNumber(a.adequacy.gap_closed_se) : json(nullptr)}};
}

// The nominal's two draws (null when recorded once): scores per real sample, the second's gain in
// SEs, which is the search's nominal.
json NominalDrawsJson(const NominalDraws& d) {
  if (!d.recorded) return nullptr;
  return {{"first_score", JsonNumber(d.first)}, {"second_score", JsonNumber(d.second)},
          {"second_added_kg", JsonNumber(d.added_kg)}, {"z_second_vs_first", JsonNumber(d.z_second)},
          {"chance", JsonNumber(d.chance)},
          {"nominal", d.second_is_nominal ? "second" : "first"}};
}

json LegSearchJson(const LegSearch& l) {
  if (!l.ran) return nullptr;
  json points = json::array();
  for (const LegSearchPoint& p : l.points) {
    points.push_back({{"leg", p.leg}, {"knob", p.knob}, {"value", p.value}, {"score", JsonNumber(p.score)},
                      {"fits_as_well", p.fits_as_well}});
  }
  return {{"named", l.named}, {"score", l.score}, {"why", l.why}, {"leg", l.best >= 0 ? json(l.leg) : json(nullptr)},
          {"knob", l.best >= 0 ? json(l.knob) : json(nullptr)}, {"value", JsonNumber(l.value)},
          {"nominal_score", JsonNumber(l.nominal_score)}, {"nominal_draws", NominalDrawsJson(l.draws)},
          {"nominal_misfit", JsonNumber(l.nominal_misfit)}, {"best_misfit", JsonNumber(l.best_misfit)},
          {"best_misfit_se", JsonNumber(l.best_misfit_se)},
          {"misfit_against", l.misfit_elsewhere ? "other_places" : "own_executions"},
          {"real_gain", JsonNumber(l.real_gain)}, {"null_gain", JsonNumber(l.null_gain)},
          {"z_null_corrected", JsonNumber(l.z_null_corrected)}, {"null_corrected_gate", l.null_corrected_gate},
          {"best_plain_score", JsonNumber(l.best_plain)}, {"z_vs_nominal", JsonNumber(l.z_vs_nominal)},
          {"gap_closed", JsonNumber(l.gap_closed)}, {"challenged", l.challenged},
          {"z_vs_named", JsonNumber(l.z_vs_named)}, {"rivals_named", l.rivals_named}, {"legs_as_well", l.legs_as_well},
          {"sides_searched", l.sides_searched}, {"side", l.side},
          {"fits_as_well", SearchSpanJson(l.as_well)}, {"points", points},
          {"recorded", l.recorded}, {"from_cache", l.from_cache}, {"seconds", l.seconds}};
}

// The leg search's fields that only a search of legs has: the legs that fit as well, and its
// challenge of named knobs unless the search also challenges them (the payload search does).
void EraseLegOnlyFields(json* out, bool challenges = false) {
  out->erase("legs_as_well");
  if (challenges) return;
  for (const char* leg_only : {"challenged", "z_vs_named", "rivals_named"}) out->erase(leg_only);
}

// The runoff's rows are knobs: a point's `leg` is null unless its knob is a leg's, the knobs whose
// points fit as well as the best are `knobs_as_well`, and the leg search's challenge fields go.
json RunoffJson(const Runoff& r) {
  if (!r.ran && r.why_not.empty()) return nullptr;
  if (!r.ran) return {{"ran", false}, {"why_not", r.why_not}};
  const LegSearch& s = r.search;
  json out = LegSearchJson(s);
  EraseLegOnlyFields(&out);
  const auto leg_of = [](const LegSearchPoint& p) { return p.leg == p.knob ? json(nullptr) : json(p.leg); };
  json knobs_as_well = json::array();
  for (size_t j = 0; j < s.points.size(); ++j) {
    const LegSearchPoint& p = s.points[j];
    out["points"][j]["leg"] = leg_of(p);
    if (p.fits_as_well && p.knob != s.knob && !knobs_as_well.contains(p.knob)) knobs_as_well.push_back(p.knob);
  }
  if (s.best >= 0) out["leg"] = leg_of(s.points[s.best]);
  out["knobs_as_well"] = knobs_as_well;
  out["ran"] = true;
  out["contenders"] = r.contenders;
  out["named_before"] = r.named_before.empty() ? json(nullptr) : json(r.named_before);
  return out;
}

// The ground's standing tilt compared, every ground knob's curve, and the search of the values that
// met the real spread (its points are knobs: `leg` goes); null where it could not run.
json GroundJson(const GroundSearch& g) {
  if (!g.ran) return g.why.empty() ? json(nullptr) : json({{"ran", false}, {"why_not", g.why}});
  json curves = json::array();
  for (const GroundCurve& c : g.curves) {
    curves.push_back({{"knob", c.knob}, {"values", c.values}, {"ratios", c.ratios}, {"matched", JsonNumber(c.matched)},
                      {"matched_ratio", JsonNumber(c.matched_ratio)}, {"matched_ratio_se", JsonNumber(c.matched_se)},
                      {"match_z", JsonNumber(c.match_z)}, {"meets", c.meets},
                      {"tilt_log_density", JsonNumber(c.tilt_score)}, {"tilt_z_below_best", JsonNumber(c.tilt_z)},
                      {"tilt_shaped_as_well", c.tilt_as_well}});
  }
  json search = LegSearchJson(g.search);
  if (!search.is_null()) {
    EraseLegOnlyFields(&search);
    search.erase("leg");
    for (json& p : search["points"]) p.erase("leg");
  }
  return {{"ran", true}, {"why", g.why}, {"on_slope", g.on_slope},
          {"standing_spread_rad", {{"real", g.real.value}, {"real_se", g.real.se}, {"sim", g.sim.value},
                                   {"sim_se", g.sim.se}, {"real_placements", g.real.placements},
                                   {"sim_placements", g.sim.placements}}},
          {"ratio", g.ratio}, {"ratio_se", g.ratio_se}, {"z_moved", g.z_moved}, {"moved", g.moved},
          {"curves", curves}, {"search", search}, {"named", g.search.named},
          {"recorded", g.recorded}, {"from_cache", g.from_cache}, {"seconds", g.seconds}};
}

// The payload search's best column as a search (its points: masses at that position) with every
// position searched; null when it did not run.
json PayloadSearchJson(const PayloadSearch& p) {
  if (!p.ran) return p.why.empty() ? json(nullptr) : json({{"ran", false}, {"why_not", p.why}});
  json out = LegSearchJson(p.search);
  EraseLegOnlyFields(&out, true);
  out.erase("leg");
  json columns = json::array();
  for (const PayloadColumn& c : p.columns) {
    columns.push_back({{"forward_m", c.x}, {"left_m", c.y}, {"best_mass_kg", JsonNumber(c.mass)},
                       {"best_forward_m", c.best_x}, {"best_left_m", c.best_y},
                       {"score", JsonNumber(c.score)}, {"fits_as_well", c.fits_as_well},
                       {"posture_z", JsonNumber(c.posture_z)}});
  }
  out["ran"] = true;
  out["why"] = p.why;
  out["forward_m"] = JsonNumber(p.x);
  out["left_m"] = JsonNumber(p.y);
  const auto [forward, left] = PayloadMoment(p);
  out["moment_kg_m"] = {JsonNumber(forward), JsonNumber(left)};
  out["positions"] = columns;
  out["likelihood_best_position"] = p.likelihood_best;  // index into positions: the best by likelihood alone
  out["named_position"] = p.best_column;  // the position named (the posture's choice where it differs)
  out["leg_challenged"] = p.leg_challenged.empty() ? json(nullptr) : json(p.leg_challenged);
  out["refused_fits_better_than_leg"] = p.refused_fits_better;
  out["seconds"] = p.seconds;
  return out;
}

// The advice where the evidence stopped short of a name (more_data.h); null when not advised.
json MoreDataJson(const MoreData& m) {
  if (!m.advised) return nullptr;
  return {{"knob", m.knob}, {"family", m.family}, {"reason", m.reason}, {"z", JsonNumber(m.z)},
          {"z_required", JsonNumber(m.z_required)}, {"inclusion", JsonNumber(m.inclusion)},
          {"z_effective", JsonNumber(m.z_effective)}, {"placements", m.placements},
          {"executions_per_placement", m.executions_per_placement}, {"placements_are_samples", !m.sequence},
          {"placements_needed", m.placements_needed < 0 ? json(nullptr) : json(m.placements_needed)},
          {"max_factor", JsonNumber(m.max_factor)}, {"said", m.said.empty() ? json(nullptr) : json(m.said)},
          {"chance", JsonNumber(m.chance)}};
}

json Pair(const Eigen::Vector2d& v) { return json::array({JsonNumber(v(0)), JsonNumber(v(1))}); }

// The posture check (rad, pitch and roll); null when it was not tried.
json PostureJson(const PostureCheck& c) {
  if (!c.ran) return c.why.empty() ? json(nullptr) : json({{"ran", false}, {"why_not", c.why}});
  return {{"ran", true}, {"on_slope", c.on_slope},
          {"walking", {{"shift", Pair(c.walking.shift)}, {"se", Pair(c.walking.se)}}},
          {"standing", {{"shift", Pair(c.standing.shift)}, {"se", Pair(c.standing.se)}}},
          {"correction", c.correction}, {"recorded", c.recorded}, {"compared_only", c.compared_only},
          {"predicted", Pair(c.predicted)}, {"predicted_se", Pair(c.predicted_se)},
          {"predicted_standing", Pair(c.predicted_standing)},
          {"imu_offset", Pair(c.imu)}, {"left", Pair(c.left)}, {"z_left", JsonNumber(c.z_left)},
          {"z_left_without_imu", JsonNumber(c.z_left_without_imu)}, {"z_moved", JsonNumber(c.z_moved)},
          {"left_out", c.left_out}};
}

// A named IMU offset the posture contradicted (null: none, the analysis ran once).
json ContradictedImuJson(const ContradictedImu& c) {
  if (!c.refitted) return nullptr;
  return {{"first_named", c.named}, {"imu_offset", Pair(c.check.imu)}, {"z_left", JsonNumber(c.check.z_left)},
          {"z_left_without_imu", JsonNumber(c.check.z_left_without_imu)}};
}

}  // namespace

std::string ReportJson(const Analysis& a, const ReportContext& ctx) {
  const AnalysisInputs& in = a.inputs;
  json out = {{"sim", ctx.sim_path}, {"real", ctx.real_path},
              {"samples", {{"real", in.real.size()}, {"sim", in.sim.size()}}},
              {"pose_dim", in.real.pose_dim()}, {"terrain_dim", in.real.terrain_dim()},
              {"has_sequence", in.real.has_sequence},
              {"verdict", json::parse(VerdictJson(a.verdict))},
              {"locate", LocateJson(a)},
              {"knobs", a.knobs_analysed ? KnobsJson(a) : json(nullptr)},
              {"adequacy", a.knobs_analysed ? AdequacyJson(a) : json(nullptr)},
              {"ground", GroundJson(a.ground)},
              {"runoff", RunoffJson(a.runoff)},
              {"leg_search", LegSearchJson(a.leg_search)},
              {"payload_search", PayloadSearchJson(a.payload_search)},
              {"posture", PostureJson(a.posture)},
              {"imu_contradicted", ContradictedImuJson(a.imu_contradicted)},
              {"more_data", MoreDataJson(a.more_data)},
              {"fit", FitJson(a)},
              {"simulator", {{"analysed", a.knobs_analysed}, {"config_source", ctx.simulator_config_source},
                             {"fingerprint", ctx.simulator_fingerprint},
                             {"locate_only_because", a.locate_only_because},
                             {"recording", {{"protocol", in.recording.protocol}, {"seed", in.recording.seed},
                                            {"from_sim_metadata", in.recording_from_metadata}}}}},
              {"models", {{"corrected", ctx.corrected_model_file.empty() ? json(nullptr) : json(ctx.corrected_model_file)},
                          {"sim", ctx.sim_model_file}}},
              {"recalibrated_config", ctx.recalibrated_config_file.empty() ? json(nullptr) : json(ctx.recalibrated_config_file)},
              {"figures", json::array()}, {"notes", ctx.notes},
              {"dropped_real_commands", in.dropped_commands}, {"dropped_real_samples", in.dropped_samples},
              {"seconds", {{"locate", a.seconds.locate}, {"candidates", a.seconds.candidates},
                           {"refine", a.seconds.refine}, {"confidence", a.seconds.confidence},
                           {"adequacy", a.seconds.adequacy}, {"ties", a.seconds.ties}, {"ground", a.seconds.ground},
                           {"runoff", a.seconds.runoff},
                           {"leg_search", a.seconds.legs}, {"payload_search", a.seconds.payload},
                           {"posture", a.seconds.posture}, {"total", a.seconds.total}}}};
  for (const auto& f : ctx.figures) out["figures"].push_back({{"file", f.file}, {"caption", f.caption}});
  return out.dump(2) + "\n";
}

}  // namespace dgmm::sim2real
