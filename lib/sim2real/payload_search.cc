#include "sim2real/payload_search.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "sim2real/refine_search.h"
#include "sim2real/sentence_format.h"
#include "sim2real/verdict_stage.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

using Clock = std::chrono::steady_clock;

// The probe's offset from the nominal (the first probe; 0 without one).
double ProbeStep(const Knob& k) { return k.probes.empty() ? 0.0 : k.probes.front() - k.nominal; }

// The positions searched: forward offsets at the nominal sideways one, then sideways offsets at the
// nominal forward one, inside the knobs' ranges, distinct.
std::vector<std::pair<double, double>> Positions(const Knob& kx, const Knob& ky, const PayloadSearchOptions& o) {
  std::vector<std::pair<double, double>> out;
  auto add = [&](double x, double y) {
    const std::pair<double, double> p{WithinKnob(kx, x), WithinKnob(ky, y)};
    if (std::find(out.begin(), out.end(), p) == out.end()) out.push_back(p);
  };
  for (double f : o.forward) add(kx.nominal + f * ProbeStep(kx), ky.nominal);
  for (double s : o.sideways) add(kx.nominal, ky.nominal + s * ProbeStep(ky));
  return out;
}

// The masses searched in every column: `masses` times the mass probe, inside the range, above 0.
std::vector<std::pair<int, double>> MassGrid(int knob, const Knob& km, const PayloadSearchOptions& o) {
  std::vector<std::pair<int, double>> out;
  for (double f : o.masses) {
    const double m = WithinKnob(km, km.nominal + f * ProbeStep(km));
    if (m > 0 && std::none_of(out.begin(), out.end(), [&](const auto& p) { return p.second == m; })) {
      out.push_back({knob, m});
    }
  }
  return out;
}

// "2.2 cm behind the middle", "1 cm ahead of and 0.5 cm left of the middle", "on the middle" (a
// column on a line through the middle keeps the other offset at exactly 0).
std::string WhereSaid(double x, double y) {
  std::vector<std::string> parts;
  if (x != 0) parts.push_back(Fmt("%.2g cm ", 100 * std::fabs(x)) + (x > 0 ? "ahead of" : "behind"));
  if (y != 0) parts.push_back(Fmt("%.2g cm ", 100 * std::fabs(y)) + (y > 0 ? "left of" : "right of"));
  if (parts.empty()) return "on the middle";
  return (parts.size() == 2 ? parts[0] + " and " + parts[1] : parts[0]) + " the middle";
}

// " (2.9 kg cm ahead of the middle)": the named payload's moment about the knobs' nominal position.
std::string MomentSaid(const PayloadSearch& p) {
  const auto [mx, my] = PayloadMoment(p);
  std::vector<std::string> parts;
  if (mx != 0) parts.push_back(Fmt("%.2g kg cm ", 100 * std::fabs(mx)) + (mx > 0 ? "ahead" : "behind"));
  if (my != 0) parts.push_back(Fmt("%.2g kg cm ", 100 * std::fabs(my)) + (my > 0 ? "to the left" : "to the right"));
  return parts.empty() ? " (none: on the middle)" : " (" + JoinWords(parts) + ")";
}

// Marks the columns whose best point fits the real samples as well as the best column's.
void MarkAsWell(const std::vector<LegSearch>& searches, const AnalysisInputs& in, double z, PayloadSearch* out) {
  std::vector<Eigen::VectorXd> rows;
  std::vector<int> column;
  int best_row = -1;
  for (size_t j = 0; j < searches.size(); ++j) {
    if (searches[j].best < 0) continue;
    if (static_cast<int>(j) == out->best_column) best_row = static_cast<int>(rows.size());
    rows.push_back(searches[j].best_rows);
    column.push_back(static_cast<int>(j));
  }
  const std::vector<bool> as_well = FitAsWellAsTheBest(rows, best_row, in.real.episode, z);
  for (size_t r = 0; r < rows.size(); ++r) out->columns[column[r]].fits_as_well = as_well[r];
}

// "; the searched positions 5 cm behind the middle and on the middle fit as well" (or "").
std::string PositionsAsWell(const PayloadSearch& p) {
  std::vector<std::string> where;
  for (size_t j = 0; j < p.columns.size(); ++j) {
    if (p.columns[j].fits_as_well && static_cast<int>(j) != p.best_column) {
      where.push_back(WhereSaid(p.columns[j].best_x, p.columns[j].best_y));
    }
  }
  if (where.empty()) return "";
  return "; the searched position" + std::string(where.size() > 1 ? "s " : " ") + JoinWords(where) +
         (where.size() > 1 ? " fit" : " fits") + " as well";
}

// " Of the positions that fit the real samples as well, the torso's posture chose 1.5 cm ahead of the
// middle (0.7 SE of posture left), over the likelihood's best, 0.74 cm ahead of the middle (3 SE)." or "".
std::string PostureChoiceSaid(const PayloadSearch& p) {
  if (p.likelihood_best < 0 || p.best_column == p.likelihood_best) return "";
  const PayloadColumn &chosen = p.columns[p.best_column], &best = p.columns[p.likelihood_best];
  return " Of the positions that fit the real samples as well, the torso's posture chose " +
         WhereSaid(chosen.best_x, chosen.best_y) + Fmt(" (%.1f SE of posture left),", chosen.posture_z) +
         " over the likelihood's best, " + WhereSaid(best.best_x, best.best_y) + Fmt(" (%.1f SE).", best.posture_z);
}

VerdictNamed NamedPayload(const PayloadSearch& p) {
  const LegSearch& s = p.search;
  VerdictNamed n = SearchNamed(s, "payload", "kg");
  const std::string after =
      !p.leg_challenged.empty() ? "after the leg search named a weak " + p.leg_challenged +
                                      Fmt(", which it fits the real samples better than (z %.1f)", s.z_vs_named)
      : s.challenged.empty()    ? "after the probes' mean shifts and the leg search named nothing"
                                : "after the probes' mean shifts named " + JoinWords(s.challenged) +
                                   Fmt(", which it fits the real samples better than (z %.1f)", s.z_vs_named);
  n.doubts.push_back(Fmt("found by a search of a payload's mass and position (%.0f positions, each recording scored by a ",
                         static_cast<double>(p.columns.size())) +
                     "model of its own) " + after + ": no bootstrap, its range is the masses that fit as well; it sits " +
                     WhereSaid(p.x, p.y) + PositionsAsWell(p));
  AddRemainingMismatchDoubt(s, "the payload", &n);
  return n;
}

// The payload's columns screened so far: each position's masses scored (no refinement), the best
// column kept in the search's result.
struct Columns {
  const KnobSimulator& simulator;
  const AnalysisInputs& in;
  const CandidateSet& set;
  const CandidateOptions& recording;
  LegSearchOptions options;
  std::vector<std::pair<int, double>> grid;
  PayloadKnobs k;
  std::vector<LegSearch> searches;

  // The column through (x, y) at the mass probe keeps its moment: a payload of mass m sits at
  // nominal + (x - nominal) probe / m (clamped to the range), and likewise sideways.
  AlsoAt Line(double x, double y) const {
    const Knob &km = simulator.knobs()[k.mass], &kx = simulator.knobs()[k.x], &ky = simulator.knobs()[k.y];
    const double probe = km.nominal + ProbeStep(km);
    const int ix = k.x, iy = k.y;
    return [=](int, double m) {
      const double share = m > 0 ? probe / m : 0.0;  // no payload: where it sits does not matter
      return std::vector<KnobValue>{{ix, WithinKnob(kx, kx.nominal + (x - kx.nominal) * share)},
                                    {iy, WithinKnob(ky, ky.nominal + (y - ky.nominal) * share)}};
    };
  }

  void Screen(const std::vector<std::pair<double, double>>& positions, PayloadSearch* out) {
    for (const auto& [x, y] : positions) {
      searches.push_back(SearchOwnModels(simulator, in, set, recording, options, grid, Line(x, y)));
      const LegSearch& s = searches.back();
      const bool any = s.best >= 0 && s.also.size() == 2;
      out->columns.push_back({x, y, s.value, any ? s.also[0].value : x, any ? s.also[1].value : y, BestScore(s), false});
      if (s.best >= 0 && (out->best_column < 0 || BestScore(s) > out->columns[out->best_column].score)) {
        out->best_column = static_cast<int>(out->columns.size()) - 1;
      }
    }
  }
};

// Half-way from the best column to its searched neighbours along its own axis (forward for a
// column on the middle line, else sideways), or half a probe's offset beyond the last one, inside
// the range, not yet searched.
std::vector<std::pair<double, double>> PositionHalfSteps(const PayloadSearch& p, const Knob& kx, const Knob& ky) {
  const PayloadColumn& b = p.columns[p.best_column];
  const bool forward = b.y == WithinKnob(ky, ky.nominal);
  const double at = forward ? b.x : b.y, reach = std::fabs(ProbeStep(forward ? kx : ky));
  double below = at - reach, above = at + reach;
  for (const PayloadColumn& c : p.columns) {
    const bool same_line = forward ? c.y == b.y : c.x == b.x;
    const double v = forward ? c.x : c.y;
    if (!same_line) continue;
    if (v < at) below = std::max(below, v);
    if (v > at) above = std::min(above, v);
  }
  std::vector<std::pair<double, double>> out;
  for (double v : {0.5 * (at + below), 0.5 * (at + above)}) {
    const std::pair<double, double> q = forward ? std::make_pair(WithinKnob(kx, v), b.y) : std::make_pair(b.x, WithinKnob(ky, v));
    const bool searched = std::any_of(p.columns.begin(), p.columns.end(),
                                      [&](const PayloadColumn& c) { return c.x == q.first && c.y == q.second; });
    if (!searched && std::find(out.begin(), out.end(), q) == out.end()) out.push_back(q);
  }
  return out;
}

// The best point's simulator knobs of a column's search: the mass and where the column places it.
std::vector<KnobValue> BestValues(const LegSearch& s) {
  std::vector<KnobValue> values = {{s.knob_index, s.value}};
  values.insert(values.end(), s.also.begin(), s.also.end());
  return values;
}

// The columns that fit as well as the best, each with the posture its best point leaves
// (PayloadColumn::posture_z), in the order the posture ranks them: those that leave less of it than
// the likelihood's best, least first (ties and columns the posture cannot check keep the
// likelihood's choice, which ends the list).
std::vector<int> RankByPosture(const std::vector<LegSearch>& searches, const PostureLeft& posture_left,
                               PayloadSearch* out) {
  for (size_t j = 0; j < searches.size(); ++j) {
    PayloadColumn& c = out->columns[j];
    if (c.fits_as_well && searches[j].best >= 0) c.posture_z = posture_left(BestValues(searches[j]));
  }
  const double at_best = out->columns[out->likelihood_best].posture_z;
  std::vector<int> ranked;
  for (size_t j = 0; j < searches.size(); ++j) {
    if (std::isfinite(out->columns[j].posture_z) && out->columns[j].posture_z < at_best) ranked.push_back(j);
  }
  std::sort(ranked.begin(), ranked.end(),
            [&](int a, int b) { return out->columns[a].posture_z < out->columns[b].posture_z; });
  ranked.push_back(out->likelihood_best);
  return ranked;
}

// The columns in the order `ranked` refined (the search options' refine steps) until one names a
// payload (the last, the likelihood's best, stays when none does): a column the posture chose
// that, refined, fits no better than the nominal gives way to the next.
void RefineRanked(const Columns& columns, const LegSearchOptions& options, const std::vector<int>& ranked,
                  PayloadSearch* out) {
  int recorded = 0, from_cache = 0;
  for (int j : ranked) {
    out->best_column = j;
    out->search = SearchOwnModels(columns.simulator, columns.in, columns.set, columns.recording, options, columns.grid,
                                  columns.Line(out->columns[j].x, out->columns[j].y));
    recorded += out->search.recorded, from_cache += out->search.from_cache;
    if (out->search.named) break;
  }
  out->search.recorded = recorded, out->search.from_cache = from_cache;
}

}  // namespace

std::string PayloadSaid(const PayloadSearch& p) { return Fmt("a payload of %.3g kg ", p.search.value) + WhereSaid(p.x, p.y); }

bool PayloadSearchOptions::IsValid(std::string* error) const {
  if (masses.empty() || std::any_of(masses.begin(), masses.end(), [](double m) { return !(m > 0); })) {
    *error = "payload search masses must be positive multiples of the mass probe";
    return false;
  }
  if (position_steps < 0) {
    *error = "payload search position_steps must be 0 or more";
    return false;
  }
  if (forward.empty() && sideways.empty()) {
    *error = "payload search needs at least one position";
    return false;
  }
  return search.IsValid(error);
}

std::pair<double, double> PayloadMoment(const PayloadSearch& p) {
  return {p.search.value * (p.x - p.x_nominal), p.search.value * (p.y - p.y_nominal)};
}

PayloadKnobs FindPayloadKnobs(const KnobSimulator& simulator) {
  PayloadKnobs out;
  const auto& knobs = simulator.knobs();
  for (int k = 0; k < static_cast<int>(knobs.size()); ++k) {
    if (knobs[k].role == Knob::Role::kPayloadMass) out.mass = k;
    if (knobs[k].role == Knob::Role::kPayloadX) out.x = k;
    if (knobs[k].role == Knob::Role::kPayloadY) out.y = k;
  }
  return out;
}

PayloadSearch SearchPayload(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateSet& set,
                            const CandidateOptions& recording, const PayloadSearchOptions& options,
                            const PostureLeft& posture_left) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "payload search options", error);
  const auto start = Clock::now();
  PayloadSearch out;
  const PayloadKnobs k = FindPayloadKnobs(simulator);
  const auto& knobs = simulator.knobs();
  const auto grid = k.found() ? MassGrid(k.mass, knobs[k.mass], options) : std::vector<std::pair<int, double>>{};
  if (grid.empty()) {
    out.why = "the simulator has no payload knobs";
    return out;
  }
  out.ran = true;
  Columns columns{simulator, in, set, recording, options.search, grid, k};
  columns.options.refine_steps = 0;
  columns.Screen(Positions(knobs[k.x], knobs[k.y], options), &out);
  for (int round = 0; out.best_column >= 0 && round < options.position_steps; ++round) {
    columns.Screen(PositionHalfSteps(out, knobs[k.x], knobs[k.y]), &out);
  }
  const std::vector<LegSearch>& searches = columns.searches;
  if (out.best_column < 0) {
    out.why = "every recording lost most of its placements (the robot fell)";
    return out;
  }
  MarkAsWell(searches, in, options.search.z, &out);
  out.likelihood_best = out.best_column;
  const std::vector<int> ranked = options.posture_chooses && posture_left ? RankByPosture(searches, posture_left, &out)
                                                                          : std::vector<int>{out.best_column};
  RefineRanked(columns, options.search, ranked, &out);
  const PayloadColumn& best = out.columns[out.best_column];
  out.search.by = "payload_search";
  out.x_nominal = knobs[k.x].nominal, out.y_nominal = knobs[k.y].nominal;
  out.x = out.search.also.empty() ? best.best_x : out.search.also[0].value;
  out.y = out.search.also.empty() ? best.best_y : out.search.also[1].value;
  for (const LegSearch& s : searches) out.search.recorded += s.recorded, out.search.from_cache += s.from_cache;
  out.why = out.search.why;
  out.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

void PayloadSearchChallenge(const AnalysisInputs& in, const std::vector<std::string>& named,
                            const Eigen::VectorXd& corrected, const PayloadSearchOptions& options, PayloadSearch* p) {
  if (!p->ran || p->search.best < 0) return;
  LegSearchChallenge(in, named, corrected, options.search, &p->search, PayloadSaid(*p));
  p->why = p->search.why;
}

void PayloadVersusLeg(const AnalysisInputs& in, const PayloadSearchOptions& options, LegSearch* leg,
                      PayloadSearch* p) {
  LegSearch& s = p->search;
  if (!p->ran || s.best < 0 || !leg->named || leg->best_rows.size() != s.best_rows.size()) return;
  const double chance = std::max(leg->draws.chance, s.draws.chance) * static_cast<double>(s.best_rows.size());
  const double z = PairedZ(s.best_rows, leg->best_rows, in.real.episode, chance);
  if (!s.named && z < options.search.z) return;  // refused by its own gates, and no better than the leg
  const std::string leg_said = LegSaid(*leg);
  p->leg_challenged = leg_said;
  s.z_vs_named = z;
  s.bar_z = options.search.z;
  if (!s.named) {  // refused by its own gates: the leg stays, doubted (AddPayloadSearch)
    p->refused_fits_better = true;
    return;
  }
  s.challenged = {leg->knob};
  const std::string scores = Fmt(" (%.3g against %.3g nats per sample, z %.2f)", BestScore(s), BestScore(*leg), s.z_vs_named);
  if (s.z_vs_named >= options.search.z) {
    leg->named = false;
    leg->why = "its best point (" + leg->leg + Fmt(" at gain %.3g", leg->value) + ") fits the real samples worse than " +
               PayloadSaid(*p) + scores;
    return;
  }
  s.named = false;
  s.rivals_named = s.z_vs_named > 0;
  p->why = "its best point (" + PayloadSaid(*p) + ") fits the real samples " +
           (s.rivals_named ? "better than the weak " + leg_said + Fmt(" the leg search named, but by under %.3g SE", options.search.z)
                           : "no better than the weak " + leg_said + " the leg search named") +
           scores;
  s.why = p->why;
}

namespace {
// A payload its own gates refused that fits the real samples better than the named leg by the bar:
// the leg's name is not the best fit the searches found, so it is doubted.
void AddRefusedPayloadDoubt(const PayloadSearch& p, Verdict* v) {
  AddVerdictDoubt(PayloadSaid(p) + " fits the real samples better than the weak " + p.leg_challenged +
                  Fmt(" the leg search named (z %.2f, over the bar of %.3g), though its own gates refused it (",
                      p.search.z_vs_named, p.search.bar_z) +
                  p.why + "): neither may be the physics these data show",
                  v);
}
}  // namespace

void AddPayloadSearch(const PayloadSearch& p, Verdict* v) {
  if (!p.ran) return;
  const LegSearch& s = p.search;
  const std::string what = Fmt("A search of a payload's mass and position (%.0f positions, each recording scored by a model "
                               "of its own)",
                               static_cast<double>(p.columns.size()));
  if (!s.named) {
    v->sentence += " " + what + " names none: " + p.why + ".";
    if (s.rivals_named) AddRivalDoubt(s, PayloadSaid(p), v);
    if (p.refused_fits_better) AddRefusedPayloadDoubt(p, v);
    return;
  }
  ReplaceNamed(s, NamedPayload(p), v);
  const std::string than_named =
      !p.leg_challenged.empty() ? " and than the weak " + p.leg_challenged + Fmt(" the leg search named (z %.1f)", s.z_vs_named)
      : s.challenged.empty()    ? ""
                                : Fmt(" and than the named knobs' correction (z %.1f)", s.z_vs_named);
  v->sentence += " " + what + ": " + PayloadSaid(p) +
                 Fmt(" fits the real samples %.3g nats per sample better than the nominal (z %.1f)",
                     s.points[s.best].score - s.nominal_score, s.z_vs_nominal) + than_named + "; " +
                 "what the data fix is its moment, mass times offset" + MomentSaid(p) +
                 ", more than its mass: every mass of its column sits at that moment." + PostureChoiceSaid(p);
}

}  // namespace dgmm::sim2real
