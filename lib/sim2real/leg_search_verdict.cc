// The leg search's answer in the verdict (leg_search.h: AddLegSearch, and SearchNamed and
// ReplaceNamed, which the runoff shares).
#include "sim2real/leg_search.h"
#include "sim2real/sentence_format.h"
#include "sim2real/verdict_stage.h"

namespace dgmm::sim2real {
namespace {

// Under this share of the nominal's misfit removed, some mismatch remains.
constexpr double kMostOfTheMisfit = 0.9;

// "every leg's gain", or "every leg's and every side's gain" (LegSearch::sides_searched).
std::string Searched(const LegSearch& s) {
  return s.sides_searched ? "every leg's and every side's gain" : "every leg's gain";
}

VerdictNamed NamedLeg(const LegSearch& s) {
  VerdictNamed n = SearchNamed(s, "actuator_gain", "");
  const std::string after = s.challenged.empty()
                                ? "after the probes' mean shifts named nothing"
                                : "after the probes' mean shifts named " + JoinWords(s.challenged) +
                                      Fmt(", which it fits the real samples better than (z %.1f)", s.z_vs_named);
  n.doubts.push_back("found by a search of " + Searched(s) +
                     Fmt(" (%.0f recordings, each scored by a model of its own, ", static_cast<double>(s.points.size())) +
                     "its spread and falls included) " + after + ": no bootstrap, its range is the gains that fit as well");
  AddRemainingMismatchDoubt(s, s.side ? "the weak side" : "the weak leg", &n);
  return n;
}

}  // namespace

// A challenger that fits the real samples at least as well as the named knobs: the data do not tell
// them apart, so the named knobs are not the only reading.
void AddRivalDoubt(const LegSearch& s, const std::string& subject, Verdict* v) {
  AddVerdictDoubt(subject +
                  Fmt(" fits the real samples as well as the named knobs (better by z %.2f, under the search's bar of "
                      "%.3g):",
                      s.z_vs_named, s.bar_z) +
                  " these data do not tell the two apart",
                  v);
}

std::string LegSaid(const LegSearch& s) { return s.leg + Fmt(s.side ? " (gain %.3g)" : " leg (gain %.3g)", s.value); }

VerdictNamed SearchNamed(const LegSearch& s, const std::string& family, const std::string& unit) {
  VerdictNamed n;
  n.family = family;
  n.knob = s.knob;
  n.unit = unit;
  n.value = n.fitted = s.value;
  n.nominal = s.nominal;
  n.lo = s.lo, n.hi = s.hi;
  n.as_well = s.as_well;
  if (s.value <= s.lo) n.flags.push_back("pinned_low");
  if (s.value >= s.hi) n.flags.push_back("pinned_high");
  return n;
}

// Against recordings at other places (uneven ground): the real samples fit the point's model more
// than 1 SE worse than its own recording there does; else under 90% of the nominal's misfit removed.
bool MismatchRemains(const LegSearch& s) {
  if (s.misfit_elsewhere) return s.best_misfit > s.best_misfit_se;
  return s.gap_closed < kMostOfTheMisfit;
}

void AddRemainingMismatchDoubt(const LegSearch& s, const std::string& subject, VerdictNamed* n) {
  if (!MismatchRemains(s)) return;
  if (s.misfit_elsewhere) {
    n->doubts.push_back(subject + Fmt(" leaves the real samples %.3g nats per sample", s.best_misfit) +
                        Fmt(" below its own recording at other places (%.1f SE): some mismatch may remain",
                            s.best_misfit / s.best_misfit_se));
  } else {
    n->doubts.push_back(subject + Fmt(" removes %.0f%% of the nominal's misfit: some mismatch remains", 100 * s.gap_closed));
  }
}

void ReplaceNamed(const LegSearch& s, const VerdictNamed& n, Verdict* v) {
  v->status = "partly_explained";
  v->named = {n};
  v->doubts = n.doubts;
  v->weak.clear();
  v->gap_closed = s.gap_closed;
  v->unexplained_present = MismatchRemains(s);
  v->sentence = VerdictSentence(*v, nullptr, nullptr, nullptr);
}

void AddLegSearch(const LegSearch& s, Verdict* v) {
  if (!s.ran) return;
  if (!s.named) {
    v->sentence += " A search of " + Searched(s) +
                   Fmt(" (%.0f recordings, each scored by a model of its own) names ", static_cast<double>(s.points.size())) +
                   (s.sides_searched ? "no leg or side: " : "no leg: ") + s.why + ".";
    if (s.rivals_named) AddRivalDoubt(s, "a weak " + LegSaid(s), v);
    return;
  }
  ReplaceNamed(s, NamedLeg(s), v);
  v->sentence += " The weak " + s.leg + (s.side ? "" : " leg") +
                 Fmt(" fits the real samples %.3g nats per sample better than the nominal (z %.1f); ",
                     s.points[s.best].score - s.nominal_score, s.z_vs_nominal) +
                 (s.sides_searched ? "no other leg's or side's gain fits as well." : "no other leg's gain fits as well.");
}

}  // namespace dgmm::sim2real
