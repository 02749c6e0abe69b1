// report.html and the stdout summary (report.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "sim2real/report.h"

namespace dgmm::sim2real {
namespace {

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

// Where the null shortfall comes from, in words (ceiling.h, recorded_null.h).
std::string NullWhere(const NullShortfall& n) {
  return n.recorded ? "the nominal re-recorded with the real set's design" : "the sim set's own size";
}
std::string NullHow(const NullShortfall& n) {
  return n.recorded ? F("%.0f re-recordings", n.draws) + ", SE of their mean " + F("%.3f", n.mean_se)
                    : std::string("sets drawn from the sim model");
}

// The share of the nominal's misfit a named point removes. Above 1 the real samples fit the point's
// model better than its recording's own unseen samples do: all of the misfit, not more than all.
std::string MisfitRemoved(double share) { return share > 1 ? "all" : F("%.0f%%", 100 * share); }

// "it removes 41% of the nominal's misfit", or on uneven ground "the real samples fit its model as
// well as its own recording at other places (misfit 0.041, 0.6 SE)".
std::string MisfitSaid(const LegSearch& own) {
  if (!own.misfit_elsewhere) return "it removes " + MisfitRemoved(own.gap_closed) + " of the nominal's misfit";
  return "the real samples fit its model as well as its own recording at other places does (misfit " +
         F("%.3f", own.best_misfit) + " nats per sample, " + F("%.1f SE", own.best_misfit / own.best_misfit_se) + ")";
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

std::string HeatTable(const Analysis& a, const Eigen::MatrixXd& h) {
  double scale = 0.5;
  for (Eigen::Index k = 0; k < h.size(); ++k) {
    if (std::isfinite(h.data()[k])) scale = std::max(scale, std::abs(h.data()[k]));
  }
  std::ostringstream o;
  o << "<table class=heat><tr><th>command</th>";
  for (const auto& t : a.baseline.terrain_labels) o << "<th>" << Escape(t) << "</th>";
  o << "</tr>\n";
  for (int i = 0; i < h.rows(); ++i) {
    o << "<tr><td>" << Escape(a.inputs.command_labels[a.inputs.real_commands[i]]) << "</td>";
    for (int j = 0; j < h.cols(); ++j) {
      o << "<td style='background:" << HeatColour(h(i, j), scale) << "'>"
        << (std::isfinite(h(i, j)) ? F("%.2f", h(i, j)) : "-") << "</td>";
    }
    o << "</tr>\n";
  }
  o << "</table>\n";
  return o.str();
}

std::string RegionTable(const std::vector<Region>& regions, const std::vector<std::string>& families, int limit) {
  std::ostringstream o;
  o << "<table><tr><th>region</th><th>family</th><th>real</th><th>sim</th>"
       "<th>deficit (nats/sample)</th><th>MMD p</th><th>BH q</th></tr>\n";
  int shown = 0;
  for (const auto& g : regions) {
    if (std::find(families.begin(), families.end(), g.family) == families.end()) continue;
    if (shown++ >= limit) break;
    o << "<tr" << (g.significant ? " class=sig" : "") << "><td>" << Escape(g.label) << "</td><td>" << g.family
      << "</td><td>" << g.n_real << "</td><td>" << g.n_sim << "</td><td>" << F("%.3f", g.deficit) << "</td><td>"
      << F("%.4f", g.p_value) << "</td><td>" << F("%.4f", g.q_value) << (g.significant ? " *" : "") << "</td></tr>\n";
  }
  o << "</table>\n";
  return o.str();
}

std::string LocateSection(const Analysis& a) {
  const LocateSummary& s = a.baseline.before;
  std::ostringstream o;
  o << "<h2>1. Where the simulation fails (locate)</h2><p>" << a.inputs.real.size() << " real and " << a.inputs.sim.size()
    << " simulated samples. Deficit = held-out real log-likelihood per sample of the best real-trained model minus "
       "that of the sim-trained model (positive: the sim model explains the real data worse). Tests: MMD between "
       "whitened residuals of real and (cross-fitted) simulated samples, Benjamini-Hochberg within each family; bold "
       "= q &lt; 0.05.</p>\n<h3>Terrain, sequence and command regions</h3>"
    << RegionTable(s.regions, {"terrain", "sequence", "command"}, 12)
    << "<h3>Command &times; terrain deficit (nats per real sample)</h3>" << HeatTable(a, s.heat)
    << "<h3>The naive test: x alone per command, pooled over terrain and sequence</h3><p>" << s.pooled_x_flagged << " of "
    << a.inputs.real_commands.size() << " commands flagged (the conditional tests flag " << s.conditional_flagged
    << " regions).</p>" << RegionTable(s.regions, {"pooled_x"}, 5);
  return o.str();
}

std::string NamedTable(const Verdict& v) {
  std::ostringstream o;
  o << "<table><tr><th>#</th><th>family</th><th>knob</th><th>value (95% interval)</th><th>range</th><th>nominal</th>"
       "<th>inclusion (family)</th><th>flags and doubts</th></tr>\n";
  for (size_t k = 0; k < v.named.size(); ++k) {
    const auto& n = v.named[k];
    o << "<tr><td>" << k + 1 << "</td><td>" << Escape(n.family) << "</td><td>" << Escape(n.knob) << "</td><td>"
      << F("%.4g", n.value) << " " << Escape(n.unit)
      << (std::isfinite(n.value_lower) ? " [" + F("%.4g", n.value_lower) + ", " + F("%.4g", n.value_upper) + "]" : "")
      << (n.as_well.Beyond(n.value_lower, n.value_upper)
              ? "<br>fit as well: " + F("%.4g", n.as_well.lower) + " to " + F("%.4g", n.as_well.upper)
              : "")
      << "</td><td>" << (std::isfinite(n.lo) ? F("%.4g", n.lo) + " to " + F("%.4g", n.hi) : "-") << "</td><td>"
      << F("%.4g", n.nominal) << "</td><td>" << (n.inclusion < 0 ? "not computed" : F("%.0f%%", 100 * n.inclusion))
      << "</td><td>";
    for (const auto& d : n.doubts) o << Escape(d) << "<br>";
    o << "</td></tr>\n";
  }
  o << "</table>\n";
  return o.str();
}

// How the search that named the verdict's knob came to run, for section 2 ("... named ").
std::string SearchIntro(const std::string& by) {
  if (by == "ground_search") {
    return "<p>On this uneven ground the real robot stands tilted otherwise than the simulated one; the search of "
           "the ground's knobs (section 5), each recorded until it gives the real standing tilt's spread and scored "
           "by a model of its own, named ";
  }
  if (by == "runoff") {
    return "<p>On this uneven ground the forward selection below left a mismatch; a runoff of its contenders, each "
           "recorded again and scored by a model of its own (section 5), named ";
  }
  if (by == "payload_search") {
    return "<p>The forward selection below and the search of every leg's gain named nothing; the search of a "
           "payload's mass and position (section 5) named ";
  }
  return "<p>The forward selection below named nothing; the search of every leg's gain (section 5) named ";
}

std::string PhysicsSection(const Analysis& a) {
  std::ostringstream o;
  o << "<h2>2. What physics explains it (simulator knobs and measurement effects)</h2>\n";
  if (!a.knobs_analysed) {
    o << "<p>Not analysed: " << Escape(a.locate_only_because) << "</p>\n";
    return o.str();
  }
  o << "<p>" << a.candidates.candidates.size() << " candidates (every knob probe recorded with the sim set's own "
    << "recording, the payload, tracker bias and noise, IMU bias, heading drift). "
    << Escape(a.candidates.legs_note) << ". A candidate is named when selected by held-out real likelihood, constant "
    << "over the session, and its family's bootstrap inclusion is at least "
    << F("%.0f%%", 100 * a.verdict.min_inclusion) << ".</p>\n";
  if (a.candidates.chance.measured) {
    const WalkChance& w = a.candidates.chance;
    o << "<p>The walk's own chance: the nominal recorded again with a payload " << F("%.3g kg", w.added_kg)
      << F(" heavier moves paired executions by up to %.2f of their spread", w.largest_ratio)
      << " (0: they pair; 1.41: as unrelated as two draws).</p>\n";
  }
  if (const LegSearch* own = NamedByOwnModels(a)) {
    const bool payload = own->by == "payload_search", leg = own->by == "leg_search";
    o << SearchIntro(own->by)
      << Escape(own->knob) << F(" = %.4g", own->value) << ": its recording fits the real samples "
      << F("%.1f", own->z_vs_nominal) << " standard errors better than the nominal's, "
      << (payload ? "" : leg ? "no other leg's as well, " : "no other contender's as well, ") << "and "
      << MisfitSaid(*own) << ". It has no bootstrap: inclusion is not computed.</p>\n";
  }
  if (a.verdict.named.empty()) o << "<p>Nothing named.</p>\n";
  else o << NamedTable(a.verdict);
  o << "<h3>Forward selection of the knob path (held-out gain per real sample over the model of the previous step)</h3>";
  for (size_t s = 0; s < a.refinement.selection.steps.size(); ++s) {
    const auto& step = a.refinement.selection.steps[s];
    o << "<p>Step " << s + 1 << " (threshold z &gt; " << F("%.2f", step.threshold_z) << "): ";
    for (size_t c = 0; c < step.candidates.size() && c < 8; ++c) {
      o << Escape(a.candidates.candidates[step.candidates[c].effect].key) << " " << F("%+.3f", step.candidates[c].gain)
        << " (z " << F("%.1f", step.candidates[c].z) << "); ";
    }
    o << (step.chosen >= 0 ? "chose " + Escape(a.candidates.candidates[step.chosen].key) : "stopped") << ".</p>\n";
  }
  return o.str();
}

std::string SureSection(const Analysis& a) {
  std::ostringstream o;
  o << "<h2>3. How sure (ties, discriminating experiments, doubts)</h2>\n";
  if (a.verdict.ties.empty()) o << "<p>No ties: no other family fits the named knobs' signatures as well.</p>\n";
  for (const auto& t : a.verdict.ties) {
    o << "<p><b>";
    for (size_t f = 0; f < t.families.size(); ++f) o << (f ? " / " : "") << Escape(t.families[f]);
    o << "</b>: " << Escape(t.why) << ". " << Escape(DescribeExperiment(t.experiment)) << "</p>\n";
  }
  if (a.verdict.doubts.empty()) o << "<p>No doubts.</p>\n";
  else o << "<ul>";
  for (const auto& d : a.verdict.doubts) o << "<li>" << Escape(d) << "</li>";
  if (!a.verdict.doubts.empty()) o << "</ul>\n";
  return o.str();
}

std::string FitSection(const Analysis& a, const ReportContext& ctx) {
  const Baseline& b = a.baseline;
  std::ostringstream o;
  o << "<h2>4. The fit (adequacy of the correction)</h2><table><tr><th>model</th><th>held-out real log-likelihood per "
       "sample</th></tr><tr><td>(a) sim-trained</td><td>" << F("%.3f", b.ll_sim) << "</td></tr>";
  const LegSearch* own = NamedByOwnModels(a);
  if (own) {
    o << "<tr><td>(b) corrected ("
      << (own->by == "ground_search"    ? "the ground knob of the ground search"
          : own->by == "runoff"         ? "the runoff's named knob"
          : own->by == "payload_search" ? "the payload of the payload search"
                                        : "the weak leg of the leg search")
      << ", its recording's own model under the search's score: sags and a broad floor included)</td><td>"
      << F("%.3f", BestScore(*own)) << "</td></tr>";
  } else if (a.knobs_analysed) {
    o << "<tr><td>(b) corrected (the knob correction)</td><td>" << F("%.3f", a.adequacy.ll_corrected) << "</td></tr>";
  }
  o << "<tr><td>(c) real-trained ceiling (sim prior strength " << F("%.0f", b.ceiling_prior_count) << ")</td><td>"
    << F("%.3f", b.ll_ceiling) << "</td></tr><tr><td>real-trained from real data alone</td><td>" << F("%.3f", b.ll_real_only)
    << "</td></tr></table>\n";
  if (!a.knobs_analysed) return o.str();
  if (own && own->misfit_elsewhere) {
    o << "<p>Misfit of " << Escape(own->knob) << " (the real samples against its own recording at other places): "
      << F("%.3f", own->best_misfit) << " nats per sample, SE " << F("%.3f", own->best_misfit_se) << "; the nominal's "
      << F("%.3f", own->nominal_misfit) << ". The corrected model is written as <code>" << Escape(ctx.corrected_model_file)
      << "</code>.</p>\n";
    return o.str();
  }
  if (own) {
    o << "<p>Share of the nominal recording's misfit (" << F("%.3f", own->nominal_misfit)
      << " nats per sample: the real samples against the recording's own unseen samples) removed by "
      << Escape(own->knob) << ": " << MisfitRemoved(own->gap_closed)
      << (own->gap_closed > 1 ? " (the real samples fit its model better than its recording's own unseen samples)" : "")
      << ". The corrected model is written as <code>"
      << Escape(ctx.corrected_model_file) << "</code>.</p>\n";
    return o.str();
  }
  const Adequacy& q = a.adequacy;
  o << "<p>Share of the gap closed: "
    << (std::isfinite(q.gap_closed) ? F("%.0f%%", 100 * q.gap_closed) + " (SE " + F("%.0f%%", 100 * q.gap_closed_se) + ")"
                                    : std::string("no gap (the sim model is at or above the ceiling)"))
    << "; the corrected model is " << F("%.3f", q.shortfall) << " nats per sample (SE " << F("%.3f", q.shortfall_se)
    << ") below the ceiling; where the physics agree, " << NullWhere(a.null_shortfall) << " puts the sim model "
    << F("%.3f", a.null_shortfall.mean) << " below it (SD " << F("%.3f", a.null_shortfall.sd) << ", "
    << NullHow(a.null_shortfall) << "). The corrected model is written as <code>" << Escape(ctx.corrected_model_file)
    << "</code> (readable by <code>dgmm score</code> and <code>dgmm render</code>).</p>\n"
    << "<h3>Locate again, on the corrected model</h3>"
    << RegionTable(q.after.regions, {"terrain", "sequence", "command"}, 12)
    << "<h3>Command &times; terrain deficit after the correction</h3>" << HeatTable(a, q.after.heat)
    << "<h3>Residual tests</h3><table><tr><th>where</th><th>p</th><th>significant</th></tr>";
  for (const auto& t : q.residual.tests) {
    o << "<tr><td>" << Escape(t.where) << "</td><td>" << F("%.4f", t.p_value) << "</td><td>" << (t.significant ? "yes" : "no")
      << "</td></tr>";
  }
  o << "</table>\n";
  return o.str();
}

// ", the better of two draws, here the second (a payload 0.00093 kg heavier: 11.0017 against the
// first's 9.8824, z 7.78; the walk's own chance 1.11 nats per real sample, counted in the z against
// the nominal)".
std::string DrawsPart(const NominalDraws& d) {
  if (!d.recorded) return "";
  return std::string(", the better of two draws, here the ") + (d.second_is_nominal ? "second" : "first") +
         F(" (the second a payload %.2g kg heavier: ", d.added_kg) + F("%.4f against the first's ", d.second) +
         F("%.4f, ", d.first) + F("z %.2f; ", d.z_second) + F("the walk's own chance %.3g", d.chance) +
         " nats per real sample, counted in the z against the nominal)";
}

// The leg search's or the runoff's points (`title`; the runoff's rows are knobs, not legs).
std::string LegSearchTable(const LegSearch& l, const std::string& title, bool legs) {
  std::ostringstream o;
  o << "<h3>" << Escape(title) << "</h3><p>"
    << (l.named ? "Named " + Escape(l.knob) + F(" = %.4g", l.value) + "."
                : std::string(legs ? "Names no leg: " : "Names no knob: ") + Escape(l.why) + ".")
    << " Nominal recording's own model: " << F("%.4f", l.nominal_score) << " nats per real sample (misfit "
    << F("%.4f", l.nominal_misfit) << "; the best point's " << F("%.4f", l.best_misfit) << ")" << DrawsPart(l.draws)
    << "; " << l.recorded << " recordings (" << l.from_cache << " from the cache), "
    << F("%.0f s", l.seconds) << ".</p><table><tr><th>" << (legs ? "leg</th><th>gain" : "knob</th><th>value")
    << "</th><th>log-likelihood per real sample (own model)</th>"
    << "<th>fits as well as the best</th></tr>";
  for (const LegSearchPoint& p : l.points) {
    o << "<tr><td>" << Escape(legs ? p.leg : p.knob) << "</td><td>" << F("%.4g", p.value) << "</td><td>"
      << (std::isfinite(p.score) ? F("%.4f", p.score) : std::string("fell")) << "</td><td>" << (p.fits_as_well ? "yes" : "")
      << "</td></tr>";
  }
  o << "</table>\n";
  return o.str();
}

// The payload search: every position's best mass and score, then the best position's masses.
std::string PayloadSearchTables(const PayloadSearch& p) {
  std::ostringstream o;
  o << "<h3>Search of a payload's mass and position</h3><p>Each column keeps a moment: a payload of mass m sits at "
       "its position at the mass probe times probe / m.</p><table><tr><th>column: forward, left at the mass probe (m)"
    << "</th><th>best mass (kg)</th><th>where it sits: forward, left (m)</th>"
    << "<th>log-likelihood per real sample (own model)</th><th>fits as well as the best</th>"
    << "<th>posture left (SE)</th></tr>";
  for (const PayloadColumn& c : p.columns) {
    o << "<tr><td>" << F("%.4g", c.x) << ", " << F("%.4g", c.y) << "</td><td>" << F("%.4g", c.mass) << "</td><td>"
      << F("%.4g", c.best_x) << ", " << F("%.4g", c.best_y) << "</td><td>"
      << (std::isfinite(c.score) ? F("%.4f", c.score) : std::string("fell")) << "</td><td>" << (c.fits_as_well ? "yes" : "")
      << "</td><td>" << (std::isfinite(c.posture_z) ? F("%.1f", c.posture_z) : std::string("-")) << "</td></tr>";
  }
  o << "</table>\n";
  if (!p.leg_challenged.empty()) {
    o << "<p>Against the weak " << Escape(p.leg_challenged) << " the leg search named: its best point "
      << (p.search.named           ? "fits the real samples better"
          : p.refused_fits_better ? "fits the real samples better, but its own gates refused it"
                                  : "does not fit the real samples better by the bar")
      << F(" (z %.2f, the bar ", p.search.z_vs_named) << F("%.3g).</p>\n", p.search.bar_z);
  }
  o << LegSearchTable(p.search, "The payload's mass at the best position", false);
  return o.str();
}

// "The torso's posture (mrad, pitch and roll): real minus sim while walking ..., standing ...; the
// named correction gives ..., leaving ... (z)" or why it was not checked.
std::string PostureParagraph(const PostureCheck& c) {
  if (!c.ran) return c.why.empty() ? "" : "<p>The torso's posture was not checked: " + Escape(c.why) + ".</p>\n";
  const auto mrad = [](const Eigen::Vector2d& v) { return F("%+.1f", 1e3 * v(0)) + ", " + F("%+.1f", 1e3 * v(1)); };
  return "<p>The torso's posture (mrad, pitch, roll" + std::string(c.on_slope ? "; on the slope from z's radial part" : "") +
         "): real minus sim " + mrad(c.walking.shift) + " while walking (SE " +
         mrad(c.walking.se) + "), " + mrad(c.standing.shift) + " standing after a placement (SE " +
         mrad(c.standing.se) + "); " +
         (c.compared_only ? "nothing named (located only): " + F("%.1f", c.z_moved) + " SE" +
                                (c.left_out ? " (a located mismatch)" : "")
                          : Escape(c.correction) + " gives " + mrad(c.predicted) + ", leaving " + F("%.1f", c.z_left) +
                                " SE" + (c.left_out ? " (a doubt)" : "")) +
         ".</p>\n";
}

// The ground's standing tilt, real against sim, and every ground knob's curve (ground_search.h).
std::string GroundParagraph(const GroundSearch& g) {
  if (!g.ran) return g.why.empty() ? "" : "<p>The ground's standing tilt was not compared: " + Escape(g.why) + ".</p>\n";
  std::ostringstream o;
  o << "<h3>The ground: the standing tilt's spread</h3><p>Spread of the torso's tilt at the first execution of each "
    << "placement" << (g.on_slope ? " (z's radial part on the slope's circle)" : "") << ": real "
    << F("%.1f", 1e3 * g.real.value) << " mrad (SE " << F("%.1f", 1e3 * g.real.se) << ", " << g.real.placements
    << " placements), sim " << F("%.1f", 1e3 * g.sim.value) << " (SE " << F("%.1f", 1e3 * g.sim.se) << ", "
    << g.sim.placements << "); ratio " << F("%.3f", g.ratio) << " (SE " << F("%.3f", g.ratio_se) << ", z "
    << F("%.1f", g.z_moved) << ")" << (g.moved ? "" : ": alike") << ".</p>\n";
  if (g.curves.empty()) return o.str();
  o << "<table><tr><th>ground knob</th><th>values recorded: ratio to the nominal's spread</th><th>meets the real "
       "ratio at</th><th>its recording's ratio (SE from the real)</th><th>the real standing tilts' log density under "
       "its recording's (SE below the best)</th></tr>";
  for (const GroundCurve& c : g.curves) {
    o << "<tr><td>" << Escape(c.knob) << "</td><td>";
    for (size_t j = 0; j < c.values.size(); ++j) o << (j ? "; " : "") << F("%.3g", c.values[j]) << ": " << F("%.3f", c.ratios[j]);
    o << "</td><td>" << (std::isfinite(c.matched) ? F("%.3g", c.matched) : std::string("not in range")) << "</td><td>"
      << (std::isfinite(c.matched_ratio) ? F("%.3f", c.matched_ratio) + " (" + F("%.1f", c.match_z) + ")" : std::string("-"))
      << "</td><td>"
      << (std::isfinite(c.tilt_score) ? F("%.3f", c.tilt_score) + " (" + F("%.1f", c.tilt_z) + ")" : std::string("-"))
      << "</td></tr>";
  }
  o << "</table>\n";
  if (g.search.ran) o << LegSearchTable(g.search, "The ground knobs' values that meet it, each scored by a model of its own", false);
  else o << "<p>" << Escape(g.why) << ".</p>\n";
  return o.str();
}

std::string DetailsSection(const Analysis& a, const ReportContext& ctx, const std::filesystem::path& dir) {
  std::ostringstream o;
  o << "<h2>5. Details</h2>\n";
  if (a.knobs_analysed) {
    o << "<h3>Refinement by re-recording</h3><table><tr><th>knob</th><th>value recorded</th><th>coefficient</th>"
      << "<th>log-likelihood per real sample (likelihood search)</th></tr>";
    for (const auto& s : a.refinement.trace) {
      o << "<tr><td>" << Escape(s.knob) << "</td><td>" << F("%.4g", s.value) << "</td><td>"
        << (std::isfinite(s.coefficient) ? F("%.3f", s.coefficient) : std::string("-")) << "</td><td>"
        << (std::isfinite(s.score) ? F("%.4f", s.score) : std::string("-")) << "</td></tr>";
    }
    o << "</table>\n<p>Recordings: " << a.candidates.recorded << " for the signatures (" << a.candidates.from_cache
      << " from the cache), " << a.refinement.recorded << " for the refinement; " << a.ties.experiment_checks
      << " experiment checks.</p>\n";
    if (!a.every_execution_because.empty()) {
      o << "<p>The signatures were recorded again with every execution of a placement, and the analysis from them "
           "is the one reported: "
        << Escape(a.every_execution_because) << ".</p>\n";
    }
  }
  o << GroundParagraph(a.ground);
  if (a.runoff.ran) {
    o << LegSearchTable(a.runoff.search, "Runoff of the first step's contenders on uneven ground (each recording scored "
                                         "by a model of its own)", false);
  }
  if (a.leg_search.ran) o << LegSearchTable(a.leg_search, "Search of every leg's gain", true);
  if (a.payload_search.ran) o << PayloadSearchTables(a.payload_search);
  o << PostureParagraph(a.posture);
  if (!ctx.recalibrated_config_file.empty()) {
    o << "<p>The simulator config at the named values: <code>" << Escape(ctx.recalibrated_config_file)
      << "</code> (<code>dgmm simulate --config</code>).</p>\n";
  }
  o << "<p>Simulator config: " << Escape(ctx.simulator_config_source) << ".</p>\n";
  for (const auto& f : ctx.figures) {
    std::ifstream in(dir / f.file, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    o << "<figure><img alt='" << Escape(f.file) << "' src='data:image/png;base64," << Base64(ss.str())
      << "'><figcaption>" << Escape(f.caption) << "</figcaption></figure>\n";
  }
  return o.str();
}

}  // namespace

std::string ReportHtml(const Analysis& a, const ReportContext& ctx, const std::filesystem::path& dir) {
  std::ostringstream o;
  o << "<!DOCTYPE html><html><head><meta charset='utf-8'><title>dgmm sim2real report</title>"
       "<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;line-height:1.4}"
       "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:3px 7px;"
       "font-size:13px}tr.sig{font-weight:bold}table.heat td{text-align:center}"
       "img{max-width:100%}.note{color:#777}</style></head><body>\n";
  o << "<h1>Sim vs real: " << Escape(ctx.sim_path) << " vs " << Escape(ctx.real_path) << "</h1>\n";
  o << "<h2>Verdict: " << Escape(a.verdict.status) << "</h2><p>" << Escape(a.verdict.sentence) << "</p>\n";
  for (const auto& n : ctx.notes) o << "<p class=note>" << Escape(n) << "</p>\n";
  o << LocateSection(a) << PhysicsSection(a) << SureSection(a) << FitSection(a, ctx) << DetailsSection(a, ctx, dir);
  o << "<p class=note>Method, assumptions and limits: docs/sim2real.md. Analysis took " << F("%.1f", a.seconds.total)
    << " s.</p></body></html>\n";
  return o.str();
}

std::string ReportSummary(const Analysis& a, const ReportContext& ctx, const std::string& report_path) {
  std::ostringstream o;
  o << "verdict: " << a.verdict.status << "\n" << a.verdict.sentence << "\n";
  // Doubts added after the sentence was written (a search's rival, a refused payload that fits better)
  for (const std::string& d : a.verdict.doubts) {
    if (a.verdict.sentence.find(d) == std::string::npos) o << "doubt: " << d << "\n";
  }
  const LocateSummary& s = a.baseline.before;
  o << "located: " << s.conditional_flagged << " terrain, sequence or command region(s) significant";
  if (!s.significant.empty()) o << " (worst: " << s.significant.front().label << ")";
  o << "\n";
  o << "fit: held-out nats per real sample: sim " << F("%.3f", a.baseline.ll_sim);
  const LegSearch* own = NamedByOwnModels(a);
  if (own) {
    const std::string named = own->by == "runoff" || own->by == "ground_search" ? own->knob
                              : own->by == "payload_search"                      ? "payload"
                                                                                 : "weak " + own->leg;
    o << ", corrected (" << named << ") " << F("%.3f", BestScore(*own));
  } else if (a.knobs_analysed) {
    o << ", corrected " << F("%.3f", a.adequacy.ll_corrected);
  }
  o << ", ceiling " << F("%.3f", a.baseline.ll_ceiling);
  if (own) {
    o << " (" << (own->misfit_elsewhere ? MisfitSaid(*own) : MisfitRemoved(own->gap_closed) + " of the nominal recording's misfit removed")
      << ")";
  } else if (a.knobs_analysed && std::isfinite(a.adequacy.gap_closed)) {
    o << " (" << F("%.0f%%", 100 * a.adequacy.gap_closed) << " of the gap closed, SE " << F("%.0f%%", 100 * a.adequacy.gap_closed_se)
      << ")";
  }
  o << "\n";
  if (!a.every_execution_because.empty()) {
    o << "signatures recorded again with every execution of a placement: " << a.every_execution_because << "\n";
  }
  for (const auto& n : ctx.notes) o << "note: " << n << "\n";
  if (!ctx.recalibrated_config_file.empty()) o << "config at the named values: " << ctx.recalibrated_config_file << "\n";
  o << "report: " << report_path << "\n";
  return o.str();
}

}  // namespace dgmm::sim2real
