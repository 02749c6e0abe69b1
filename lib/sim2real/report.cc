#include "sim2real/report.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace dgmm::sim2real {
namespace {

using nlohmann::json;

json Vec(const Eigen::VectorXd& v) { return std::vector<double>(v.data(), v.data() + v.size()); }

// NaN/Inf are not JSON: null.
json Num(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json Regions(const std::vector<Region>& regions) {
  json out = json::array();
  for (const auto& r : regions) {
    out.push_back({{"family", r.family}, {"label", r.label}, {"command", r.command},
                   {"terrain", r.terrain}, {"sequence", r.sequence}, {"n_real", r.n_real},
                   {"n_sim", r.n_sim}, {"deficit_nats_per_sample", Num(r.deficit)},
                   {"mmd2", Num(r.mmd2)}, {"p_value", r.p_value}, {"q_value", r.q_value},
                   {"significant", r.significant}});
  }
  return out;
}

std::string Escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '&': o += "&amp;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string F(const char* fmt, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

std::string Base64(const std::string& in) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8 | (unsigned char)in[i + 2];
    out += k[v >> 18 & 63];
    out += k[v >> 12 & 63];
    out += k[v >> 6 & 63];
    out += k[v & 63];
  }
  if (i < in.size()) {
    unsigned v = (unsigned char)in[i] << 16 | (i + 1 < in.size() ? (unsigned char)in[i + 1] << 8 : 0);
    out += k[v >> 18 & 63];
    out += k[v >> 12 & 63];
    out += i + 1 < in.size() ? k[v >> 6 & 63] : '=';
    out += '=';
  }
  return out;
}

// Background colour for a deficit: white at <= 0, red growing to `scale`.
std::string HeatColour(double v, double scale) {
  if (!std::isfinite(v)) return "#eeeeee";
  const double t = std::clamp(v / scale, -1.0, 1.0);
  int r = 255, g = 255, b = 255;
  if (t > 0) {
    g = b = static_cast<int>(255 * (1 - t));
  } else {
    r = g = static_cast<int>(255 * (1 + 0.5 * t));
  }
  char buf[16];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", r, g, b);
  return buf;
}

// The re-simulation summary: one row per scan, the direct check, the raw JSON folded away.
std::string RecalibrationHtml(const std::string& text) {
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  std::ostringstream o;
  if (j.is_discarded() || !j.is_object()) return "<pre>" + Escape(text) + "</pre>";
  if (j.contains("skipped")) {
    return "<p>Skipped: " + Escape(j["skipped"].is_string() ? j["skipped"].get<std::string>() : j["skipped"].dump()) + "</p>";
  }
  if (j.contains("scans") && j["scans"].is_array()) {
    o << "<table><tr><th>effect</th><th>simulator parameter</th><th>nominal</th><th>best</th>"
         "<th>gain over nominal (nats per real sample)</th></tr>";
    for (const auto& s : j["scans"]) {
      const auto field = [&](const char* k) {
        if (!s.contains(k)) return std::string("-");
        return Escape(s[k].is_string() ? s[k].get<std::string>() : s[k].dump());
      };
      o << "<tr><td>" << field("effect") << "</td><td>" << field("parameter") << "</td><td>"
        << field("nominal") << "</td><td>" << field("best") << "</td><td>"
        << (s.contains("improvement_nats_per_sample") && s["improvement_nats_per_sample"].is_number()
                ? F("%+.3f", s["improvement_nats_per_sample"].get<double>()) : std::string("-"))
        << "</td></tr>";
    }
    o << "</table>";
  }
  if (j.contains("verification") && j["verification"].contains("nominal_mean_log_likelihood")) {
    const auto& v = j["verification"];
    o << "<p>Check: sets re-simulated with " << Escape(v.value("placements", json(0)).dump())
      << " new placements; a model trained on each scores the real set "
      << F("%.3f", v["nominal_mean_log_likelihood"].get<double>()) << " (nominal config) and "
      << F("%.3f", v["recalibrated_mean_log_likelihood"].get<double>())
      << " (recalibrated config) nats per sample. The recalibrated config is written as "
         "<code>recalibrated_config.json</code>.</p>";
  }
  o << "<details><summary>All candidates (JSON)</summary><pre>" << Escape(j.dump(2)) << "</pre></details>";
  return o.str();
}

std::string HeatTable(const Sim2RealResult& r, const Eigen::MatrixXd& h) {
  double scale = 0.5;
  for (int i = 0; i < h.rows(); ++i)
    for (int j = 0; j < h.cols(); ++j)
      if (std::isfinite(h(i, j))) scale = std::max(scale, std::abs(h(i, j)));
  std::ostringstream o;
  o << "<table class=heat><tr><th>command</th>";
  for (const auto& t : r.terrain_labels) o << "<th>" << Escape(t) << "</th>";
  o << "</tr>\n";
  for (int i = 0; i < h.rows(); ++i) {
    const int c = r.real_commands[i];
    o << "<tr><td>" << Escape(r.command_labels[c]) << "</td>";
    for (int j = 0; j < h.cols(); ++j) {
      o << "<td style='background:" << HeatColour(h(i, j), scale) << "'>"
        << (std::isfinite(h(i, j)) ? F("%.2f", h(i, j)) : "-") << "</td>";
    }
    o << "</tr>\n";
  }
  o << "</table>\n";
  return o.str();
}

std::string RegionTable(const std::vector<Region>& regions, const std::vector<std::string>& families,
                        int limit) {
  std::ostringstream o;
  o << "<table><tr><th>region</th><th>family</th><th>real</th><th>sim</th>"
       "<th>deficit (nats/sample)</th><th>MMD p</th><th>BH q</th></tr>\n";
  int shown = 0;
  for (const auto& g : regions) {
    if (std::find(families.begin(), families.end(), g.family) == families.end()) continue;
    if (shown++ >= limit) break;
    o << "<tr" << (g.significant ? " class=sig" : "") << "><td>" << Escape(g.label) << "</td><td>"
      << g.family << "</td><td>" << g.n_real << "</td><td>" << g.n_sim << "</td><td>"
      << F("%.3f", g.deficit) << "</td><td>" << F("%.4f", g.p_value) << "</td><td>"
      << F("%.4f", g.q_value) << (g.significant ? " *" : "") << "</td></tr>\n";
  }
  o << "</table>\n";
  return o.str();
}

}  // namespace

std::string ReportJson(const Sim2RealResult& r, const ReportContext& ctx) {
  json effects = json::array();
  for (size_t k = 0; k < r.effects.size(); ++k) {
    const auto& e = r.effects[k];
    json params = json::array();
    for (int q = 0; q < e.theta.size(); ++q) {
      params.push_back({{"name", e.spec.parameters[q].name}, {"unit", e.spec.parameters[q].unit},
                        {"value", e.theta(q)}, {"ci95", {Num(e.lower(q)), Num(e.upper(q))}}});
    }
    effects.push_back({{"rank", k + 1}, {"effect", e.spec.key}, {"title", e.spec.title},
                       {"physics", e.spec.physics}, {"sentence", e.sentence},
                       {"parameters", params},
                       {"inclusion_probability", r.bootstrap_resamples > 0 ? json(e.inclusion) : json(nullptr)},
                       {"heldout_gain_nats_per_sample", e.gain}, {"gain_se", e.gain_se},
                       {"importance_nats_per_sample", e.importance}, {"selection_step", e.selection_step},
                       {"cannot_be_told_apart_from", e.confusable_with}});
  }
  json steps = json::array();
  for (const auto& s : r.steps) {
    json cands = json::array();
    for (const auto& c : s.candidates) {
      cands.push_back({{"effect", r.library[c.effect].key}, {"gain", c.gain}, {"se", Num(c.se)}, {"z", c.z}});
    }
    steps.push_back({{"chosen", s.chosen >= 0 ? json(r.library[s.chosen].key) : json(nullptr)},
                     {"threshold_z", s.threshold_z}, {"candidates", cands}});
  }
  json inclusion = json::object();
  for (size_t k = 0; k < r.library.size(); ++k) {
    inclusion[r.library[k].key] = r.bootstrap_resamples > 0 ? json(r.inclusion[k]) : json(nullptr);
  }
  json heat = json::array();
  for (int i = 0; i < r.heat_before.rows(); ++i) {
    json row = json::array();
    for (int j = 0; j < r.heat_before.cols(); ++j) row.push_back(Num(r.heat_before(i, j)));
    heat.push_back({{"command", r.command_labels[r.real_commands[i]]}, {"deficit", row}});
  }
  json out = {
      {"sim", ctx.sim_path}, {"real", ctx.real_path},
      {"samples", {{"real", r.n_real}, {"sim", r.n_sim}}},
      {"pose_dim", r.pose_dim}, {"terrain_dim", r.terrain_dim}, {"has_sequence", r.has_sequence},
      {"terrain_regions", r.terrain_labels},
      {"significant_mismatch", r.significant_mismatch},
      {"pooled_x_flagged_commands", r.pooled_x_flagged},
      {"conditional_flagged_regions", r.conditional_flagged},
      {"regions_before", Regions(r.before)}, {"regions_after", Regions(r.after)},
      {"heat_map", {{"terrain", r.terrain_labels}, {"rows", heat}}},
      {"effects", effects}, {"selection_steps", steps}, {"inclusion_probability", inclusion},
      {"unexplained", Regions(r.unexplained)},
      {"heldout_log_likelihood_per_sample",
       {{"sim", r.ll_sim}, {"corrected", r.ll_corrected}, {"real_trained_ceiling", r.ll_ceiling},
        {"real_only", r.ll_real_only}, {"ceiling_sim_prior_count", r.ceiling_prior_count}}},
      {"gap_closed", Num(r.gap_closed)},
      {"conclusion", r.conclusion},
      {"figures", json::array()}, {"notes", ctx.notes},
      {"models", {{"corrected", ctx.corrected_model_file}, {"sim", ctx.sim_model_file}}},
      {"seconds", r.seconds}};
  for (const auto& f : ctx.figures) out["figures"].push_back({{"file", f.file}, {"caption", f.caption}});
  if (!ctx.recalibration_json.empty()) out["recalibration"] = json::parse(ctx.recalibration_json);
  if (!ctx.verdict_json.empty()) out["verdict"] = json::parse(ctx.verdict_json);
  if (!ctx.knob_analysis_json.empty()) out["knob_analysis"] = json::parse(ctx.knob_analysis_json);
  out["dropped_real_commands"] = r.dropped_commands;
  out["dropped_real_samples"] = r.dropped_samples;
  return out.dump(2) + "\n";
}

std::string ReportHtml(const Sim2RealResult& r, const ReportContext& ctx, const std::filesystem::path& dir) {
  std::ostringstream o;
  o << "<!DOCTYPE html><html><head><meta charset='utf-8'><title>dgmm sim2real report</title>"
       "<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;line-height:1.4}"
       "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:3px 7px;"
       "font-size:13px}tr.sig{font-weight:bold}table.heat td{text-align:center}"
       "img{max-width:100%}.note{color:#777}</style></head><body>\n";
  o << "<h1>Sim vs real: " << Escape(ctx.sim_path) << " vs " << Escape(ctx.real_path) << "</h1>\n";
  o << "<h2>Conclusion</h2><p>" << Escape(r.conclusion) << "</p>\n";
  if (!ctx.verdict_sentence.empty()) o << "<p><b>Verdict:</b> " << Escape(ctx.verdict_sentence) << "</p>\n";
  for (const auto& n : ctx.notes) o << "<p class=note>" << Escape(n) << "</p>\n";
  o << "<h2>1. Where the simulation fails</h2><p>" << r.n_real << " real and " << r.n_sim
    << " simulated samples. Deficit = held-out real log-likelihood per sample of the best "
       "real-trained model minus that of the sim-trained model (positive: the sim model explains "
       "the real data worse). Tests: MMD between whitened residuals of real and (cross-fitted) "
       "simulated samples, Benjamini-Hochberg within each family; bold = q &lt; 0.05.</p>\n";
  o << "<h3>Terrain, sequence and command regions</h3>"
    << RegionTable(r.before, {"terrain", "sequence", "command"}, 12);
  o << "<h3>Command &times; terrain deficit (nats per real sample)</h3>" << HeatTable(r, r.heat_before);
  o << "<h3>The naive test: x alone per command, pooled over terrain and sequence</h3><p>"
    << r.pooled_x_flagged << " of " << r.real_commands.size()
    << " commands flagged (the conditional tests flag " << r.conditional_flagged << " regions).</p>"
    << RegionTable(r.before, {"pooled_x"}, 5);
  o << "<h2>2. What physics was left out</h2>\n";
  if (r.effects.empty()) o << "<p>No effect of the library improves the held-out real likelihood significantly.</p>";
  o << "<table><tr><th>rank</th><th>effect</th><th>in plain words</th><th>parameters (95% CI)</th>"
       "<th>importance (nats/sample lost without it)</th><th>inclusion</th><th>cannot be told apart from</th></tr>\n";
  for (size_t k = 0; k < r.effects.size(); ++k) {
    const auto& e = r.effects[k];
    o << "<tr><td>" << k + 1 << "</td><td>" << Escape(e.spec.title) << "</td><td>" << Escape(e.sentence)
      << "</td><td>";
    for (int q = 0; q < e.theta.size(); ++q) {
      o << Escape(e.spec.parameters[q].name) << " = " << F("%.4g", e.theta(q)) << " ["
        << F("%.4g", e.lower(q)) << ", " << F("%.4g", e.upper(q)) << "] "
        << Escape(e.spec.parameters[q].unit) << "<br>";
    }
    o << "</td><td>" << F("%.3f", e.importance) << " (step " << e.selection_step << ": gain " << F("%.3f", e.gain) << " &plusmn; " << F("%.3f", e.gain_se) << ")</td><td>"
      << (r.bootstrap_resamples > 0 ? F("%.0f%%", 100 * e.inclusion) : std::string("not computed")) << "</td><td>";
    for (const auto& c : e.confusable_with) o << Escape(c) << " ";
    o << "</td></tr>\n";
  }
  o << "</table>\n<h3>Forward selection (held-out gain per real sample over the model of the previous step)</h3>";
  for (size_t s = 0; s < r.steps.size(); ++s) {
    o << "<p>Step " << s + 1 << " (threshold z &gt; " << F("%.2f", r.steps[s].threshold_z) << "): ";
    for (const auto& c : r.steps[s].candidates) {
      o << Escape(r.library[c.effect].key) << " " << F("%+.3f", c.gain) << " (z " << F("%.1f", c.z) << "); ";
    }
    o << (r.steps[s].chosen >= 0 ? "chose " + Escape(r.library[r.steps[s].chosen].key) : "stopped") << ".</p>\n";
  }
  o << "<h3>Unexplained mismatch after the correction</h3>";
  if (r.unexplained.empty()) o << "<p>None: no terrain, sequence or command region differs significantly after the correction.</p>";
  else o << RegionTable(r.unexplained, {"terrain", "sequence", "command"}, 10);
  o << "<h2>3. The corrected model</h2><p>Written as <code>" << Escape(ctx.corrected_model_file)
    << "</code> (kind \"corrected\", readable by <code>dgmm score</code> and <code>dgmm render</code>); "
       "the sim-trained model of the analysis as <code>" << Escape(ctx.sim_model_file) << "</code>.</p>\n";
  if (!ctx.recalibration_json.empty()) {
    o << "<h3>Re-simulation with the fitted physical parameters</h3>" << RecalibrationHtml(ctx.recalibration_json);
  }
  o << "<h2>4. The fit</h2><table><tr><th>model</th><th>held-out real log-likelihood per sample</th></tr>"
    << "<tr><td>(a) sim-trained</td><td>" << F("%.3f", r.ll_sim) << "</td></tr>"
    << "<tr><td>(b) corrected (sim + fitted effects)</td><td>" << F("%.3f", r.ll_corrected) << "</td></tr>"
    << "<tr><td>(c) real-trained ceiling (sim prior strength " << F("%.0f", r.ceiling_prior_count)
    << ")</td><td>" << F("%.3f", r.ll_ceiling) << "</td></tr>"
    << "<tr><td>real-trained from real data alone</td><td>" << F("%.3f", r.ll_real_only) << "</td></tr></table>"
    << "<p>Share of the gap closed: "
    << (std::isfinite(r.gap_closed) ? F("%.0f%%", 100 * r.gap_closed) : std::string("no gap (the sim model is at or above the ceiling)"))
    << ". Above 100% means the corrected model generalises better than the real-trained ceiling, "
       "which has only the real samples to learn from.</p>\n";
  o << "<h3>Command &times; terrain deficit after the correction</h3>" << HeatTable(r, r.heat_after);
  if (!ctx.figures.empty()) o << "<h2>Figures</h2>\n";
  for (const auto& f : ctx.figures) {
    std::ifstream in(dir / f.file, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    o << "<figure><img alt='" << Escape(f.file) << "' src='data:image/png;base64," << Base64(ss.str())
      << "'><figcaption>" << Escape(f.caption) << "</figcaption></figure>\n";
  }
  o << "<p class=note>Method, assumptions and limits: docs/sim2real.md. Analysis took "
    << F("%.1f", r.seconds) << " s.</p></body></html>\n";
  return o.str();
}

}  // namespace dgmm::sim2real
