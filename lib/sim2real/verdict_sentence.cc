// The verdict's plain-language paragraph (verdict_stage.h, VerdictSentence).
#include "sim2real/sentence_format.h"
#include "sim2real/verdict_stage.h"

namespace dgmm::sim2real {
namespace {

std::string Unit(const std::string& u) { return u.empty() ? "" : " " + u; }

// " - recordings from 1.6 to 2.56 kg at forward offsets 0.0066 to 0.027 m fit the real samples as well
// (...)": the values the likelihood search could not tell from the named one.
std::string AsWellPart(const VerdictNamed& n) {
  const SearchSpan& a = n.as_well;
  std::string s = Fmt(" - recordings from %.4g", a.lower) + Fmt(" to %.4g", a.upper) + Unit(n.unit);
  if (std::isfinite(a.x_lower) && a.x_upper > a.x_lower) {
    s += Fmt(" at forward offsets %.3g", a.x_lower) + Fmt(" to %.3g m", a.x_upper);
  }
  return s + Fmt(" fit the real samples as well (%.0f", a.points) + Fmt(" of the %.0f the search scored, within", a.searched) +
         Fmt(" %.3g SE of the best): these data do not tell those values apart", a.z);
}

std::string NamedPart(const Verdict& v, size_t k) {
  const auto& n = v.named[k];
  std::string s = Fmt(" (%.0f) ", k + 1.0) + n.family + " (" + n.knob + Fmt(" = %.4g", n.value) + Unit(n.unit);
  if (std::isfinite(n.value_lower) && std::isfinite(n.value_upper) && n.value_upper > n.value_lower) {
    s += Fmt(", 95%% interval %.4g to %.4g", n.value_lower, n.value_upper);
  }
  if (std::isfinite(n.lo) && std::isfinite(n.hi)) s += Fmt(", range %.4g to %.4g", n.lo, n.hi);
  s += Fmt(", nominal %.4g", n.nominal) +
       (n.inclusion < 0 ? std::string(", inclusion not computed") : Fmt(", inclusion %.0f%%", 100 * n.inclusion)) + ")";
  if (n.as_well.Beyond(n.value_lower, n.value_upper)) s += AsWellPart(n);
  if (n.tie_group >= 0) {
    const auto& t = v.ties[n.tie_group];
    s += " - cannot be told apart from";
    for (size_t f = 1; f < t.families.size(); ++f) s += " " + t.families[f];
    s += " on these data (" + t.why + ")";
    if (!t.experiment.commands.empty()) s += "; to separate them, " + DescribeExperiment(t.experiment);
  }
  return s;
}

std::string Headline(const Verdict& v) {
  if (v.status == "clean") {
    return v.doubts.empty() ? "No simulator knob or measurement effect improves the held-out real likelihood: clean."
                            : "No mismatch located: clean.";
  }
  if (v.status == "located") return "Mismatch located; no physics named.";
  if (v.named.empty() && !v.weak.empty()) {
    return "Unexplained mismatch: a simulator knob improves the held-out fit, but the resamples do not agree on "
           "which one.";
  }
  if (v.named.empty()) return "Unexplained mismatch: no simulator knob or measurement effect fits.";
  std::string s = "Simulator knobs and measurement effects, in order of evidence:";
  for (size_t k = 0; k < v.named.size(); ++k) s += NamedPart(v, k) + (k + 1 < v.named.size() ? ";" : "");
  return s + ".";
}

std::string DriftPart(const VerdictDrifting& d) {
  std::string s = " " + d.family + " fits on average (" + d.knob + Fmt(" = %.4g", d.value) + Unit(d.unit) +
                  Fmt(", nominal %.4g", d.nominal) + ") but is not named: ";
  if (d.along == "session order") {
    return s + Fmt("it drifts over the session, its size changing by %+.0f%% from the first episodes to the last ", 100 * d.gamma) +
           Fmt("(value %.4g to %.4g; p %.2g)", d.first, d.last, d.p_value) +
           "; no constant simulator setting explains a drift (wear, heating, a tracker drifting over the day?).";
  }
  return s + Fmt("its size varies with the execution index (RMS %.0f%% of its size; ", 100 * d.gamma) +
         Fmt("value %.4g at step %.0f to ", d.first, d.first_step) + Fmt("%.4g at step %.0f; p %.2g)", d.last, d.last_step, d.p_value) +
         "; a constant setting only matches it on average (a step-periodic or step-dependent effect?).";
}

std::string WholeCorrectionPart(const Adequacy& a, const Verdict& v) {
  std::string s;
  if (a.total_step_variation.drifting && v.drifting.empty()) {
    s += Fmt(" The correction as a whole varies with the execution index (RMS %.0f%% of its size, p %.3g); no "
             "single effect carries it.", 100 * a.total_step_variation.gamma, a.total_step_variation.p_value);
  }
  if (a.total_drift.drifting && v.drifting.empty()) {
    s += Fmt(" The correction as a whole changes over the session (by %.0f%% of its size from the first to the last "
             "episode, p %.3g); no single effect carries the drift.", 100 * a.total_drift.gamma, a.total_drift.p_value);
  }
  return s;
}

std::string SpreadPart(const Naming& naming, const Refinement& r) {
  std::string s;
  if (naming.noise_withheld) {
    s += " A wider variance (tracker noise) also fits better, but is not named: what remains is not a pure change of scale.";
  }
  if (naming.spread_from_knobs) {
    s += " The real spread is wider than simulated, but " +
         std::string(r.spread.knob_log_ratio.size() > 0 && r.spread.knob_log_ratio.maxCoeff() > 0.05
                         ? "the named knobs widen it as much in simulation"
                         : "not in the way a noisier tracker widens it in simulation") +
         Fmt(" (a noisier tracker adds %.3f nats per sample held out, z %.1f): tracker noise is not named.", r.spread.gain,
             r.spread.z);
  }
  return s;
}

// The first few entries of a list, "a, b, c and 4 more".
std::string FirstFew(const std::vector<std::string>& items, const std::string& separator) {
  constexpr size_t kShown = 5;
  std::string s;
  for (size_t w = 0; w < items.size() && w < kShown; ++w) s += (w == 0 ? " " : separator) + items[w];
  if (items.size() > kShown) s += Fmt(" and %.0f more", static_cast<double>(items.size() - kShown));
  return s;
}

}  // namespace

std::string VerdictSentence(const Verdict& v, const Adequacy* adequacy, const Naming* naming, const Refinement* r) {
  std::string s = Headline(v);
  if (v.unexplained_present && !v.structured_in.empty() && v.status != "located") {
    s += " The residual is structured in" + FirstFew(v.structured_in, ", ") + ".";
  }
  if (v.status == "located") s += " Where the sim model fails:" + FirstFew(v.structured_in, "; ") + ".";
  for (const auto& w : v.weak) {
    s += " " + w.family + " (" + w.knob + Fmt(" = %.4g)", w.value) + (v.named.empty() ? "" : " also") +
         Fmt(" fitted but is not named: inclusion %.0f%%", 100 * w.inclusion) +
         Fmt(" is below %.0f%%.", 100 * v.min_inclusion);
  }
  for (const auto& d : v.drifting) s += DriftPart(d);
  if (adequacy) s += WholeCorrectionPart(*adequacy, v);
  if (naming && r) s += SpreadPart(*naming, *r);
  if (!v.doubts.empty()) {
    s += v.status == "located" || v.status == "clean" ? " Note:" : " Doubts:";
    for (size_t d = 0; d < v.doubts.size(); ++d) s += Fmt(" (%.0f) ", d + 1.0) + v.doubts[d] + (d + 1 < v.doubts.size() ? ";" : ".");
    if (v.status == "partly_explained" || v.status == "unexplained") {
      s += " What the knobs leave may be physics outside the knob list (e.g. leg geometry, a mass on one leg, a worn foot)";
      s += v.uneven_ground ? ", or a change in how the outcomes spread (how often the robot hangs up on the ground), "
                             "which the correction, a shift of the means, does not model."
                           : ".";
    }
  }
  return s;
}

}  // namespace dgmm::sim2real
