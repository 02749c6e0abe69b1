// Stage 9: one story. For a null, a single-knob and an out-of-library pair, report.json,
// report.html and the stdout summary say the same thing: the verdict's status and sentence, once,
// and nothing else concludes.
#include "sim2real/report.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "sim2real/ground_search.h"
#include "sim2real/leg_search.h"
#include "sim2real/payload_search.h"
#include "tests/sim2real/fake_simulator.h"
#include "tests/sim2real/stage_fixture.h"

namespace dgmm::sim2real {
namespace {

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

std::string Escaped(std::string s) {
  std::string o;
  for (char c : s) o += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : c == '"' ? "&quot;" : std::string(1, c);
  return o;
}

TEST(Report, NullSingleKnobAndOutOfLibraryPairsTellOneStory) {
  const test::FakeSimulator fake;
  test::FakeExtras geometry;
  geometry.geometry = 0.03;
  const std::vector<std::pair<std::vector<KnobValue>, test::FakeExtras>> cases = {
      {{}, {}}, {{{test::kFriction, 0.6}}, {}}, {{}, geometry}};
  std::vector<std::string> statuses;
  for (const auto& [planted, extras] : cases) {
    const test::FakePair pair = test::MakeFakePair(fake, planted, extras);
    const Analysis a = Analyse(pair.sim, pair.real, &fake, test::FastOptions());
    ReportContext ctx;
    ctx.sim_path = "sim.h5", ctx.real_path = "real.h5";
    const auto json = nlohmann::json::parse(ReportJson(a, ctx));
    const std::string html = ReportHtml(a, ctx, ".");
    const std::string summary = ReportSummary(a, ctx, "out/report.html");
    const std::string status = json["verdict"]["status"], sentence = json["verdict"]["sentence"];
    statuses.push_back(status);
    EXPECT_EQ(status, a.verdict.status);
    EXPECT_EQ(Count(summary, sentence), 1u) << summary;
    EXPECT_EQ(Count(summary, "verdict: " + status), 1u);
    EXPECT_EQ(Count(html, Escaped(sentence)), 1u);
    EXPECT_EQ(Count(html, "<h2>Verdict: " + status + "</h2>"), 1u);
    EXPECT_EQ(Count(json.dump(), "\"status\""), 1u) << "one verdict object";
    for (const std::string& text : {summary, html, json.dump()}) {
      EXPECT_EQ(text.find("onclusion"), std::string::npos);
    }
    // The gap closed is reported once, by the adequacy stage, and the same in every form.
    EXPECT_EQ(json["verdict"]["gap_closed"], json["fit"]["gap_closed"]);
    // The HTML has a section for every stage.
    for (const std::string h : {"1. Where", "2. What physics", "3. How sure", "4. The fit", "5. Details"}) {
      EXPECT_NE(html.find(h), std::string::npos) << h;
    }
  }
  EXPECT_EQ(statuses[0], "clean");
  EXPECT_EQ(statuses[1], "explained");
  EXPECT_TRUE(statuses[2] == "unexplained" || statuses[2] == "partly_explained") << statuses[2];
}

// The values a likelihood search could not tell from the named one show beside its value in the
// HTML's table where they widen the bootstrap interval by half or more, not otherwise.
TEST(Report, TheHtmlTableShowsWhatTheSearchCouldNotTellApart) {
  const test::FakeSimulator fake;
  const test::FakePair pair = test::MakeFakePair(fake, {{test::kFriction, 0.6}}, {});
  Analysis a = Analyse(pair.sim, pair.real, &fake, test::FastOptions());
  ASSERT_FALSE(a.verdict.named.empty());
  ReportContext ctx;
  VerdictNamed& n = a.verdict.named[0];
  n.value_lower = 0.55, n.value_upper = 0.65;
  n.as_well.lower = 0.56, n.as_well.upper = 0.64, n.as_well.points = 2, n.as_well.searched = 6, n.as_well.z = 2;
  EXPECT_EQ(ReportHtml(a, ctx, ".").find("fit as well"), std::string::npos);
  n.as_well.lower = 0.4;
  EXPECT_NE(ReportHtml(a, ctx, ".").find("fit as well: 0.4 to 0.64"), std::string::npos);
}

// When the search of every leg's gain names a leg, every output tells that story: the HTML's
// physics section says the knob path named nothing and the leg search named the leg, the fit rows
// are the leg's, and the summary speaks of the misfit removed, not of the knob path's gap.
TEST(Report, ALegNamedByTheLegSearchIsOneStoryInEveryOutput) {
  const test::Stages s = test::RunStages({{test::kLeg1Gain, 0.38}}, 3);
  LegSearchOptions options;
  options.model = s.options.locate.model;
  const test::FakePair pair = test::MakeFakePair(test::SharedFake(), {}, {});
  Analysis a = Analyse(pair.sim, pair.real, &test::SharedFake(), test::FastOptions());
  a.leg_search = SearchLegGains(test::SharedFake(), s.in, s.set, s.options.candidates, options);
  ASSERT_TRUE(a.leg_search.named) << a.leg_search.why;
  a.verdict.status = "unexplained";
  a.verdict.named.clear();
  AddLegSearch(a.leg_search, &a.verdict);
  ReportContext ctx;
  const std::string html = ReportHtml(a, ctx, ".");
  const std::string summary = ReportSummary(a, ctx, "out/report.html");
  const auto json = nlohmann::json::parse(ReportJson(a, ctx));
  EXPECT_EQ(json["verdict"]["status"], "partly_explained");
  EXPECT_EQ(json["fit"]["corrected_by"], "leg_search");
  EXPECT_EQ(json["verdict"]["gap_closed"], json["fit"]["gap_closed"]);
  // The fit is the score the search named the leg by (its recording's own model, sags included),
  // not the plain core model, which a few sags can send far below the sim model's.
  EXPECT_DOUBLE_EQ(json["fit"]["heldout_log_likelihood_per_sample"]["corrected"].get<double>(),
                   a.leg_search.points[a.leg_search.best].score);
  EXPECT_EQ(Count(html, Escaped(a.verdict.sentence)), 1u);
  EXPECT_NE(html.find("the search of every leg's gain (section 5) named actuators.leg1.gain"), std::string::npos);
  EXPECT_NE(html.find("(b) corrected (the weak leg"), std::string::npos);
  EXPECT_EQ(html.find("the knob correction)"), std::string::npos);
  EXPECT_NE(summary.find("corrected (weak leg1)"), std::string::npos) << summary;
  EXPECT_NE(summary.find("misfit removed"), std::string::npos) << summary;
  EXPECT_EQ(summary.find("of the gap closed"), std::string::npos) << summary;
  // A point whose model fits the real samples better than its own recording's unseen samples
  // removes all of the misfit, not 209% of it.
  a.leg_search.gap_closed = 2.09;
  const std::string html_all = ReportHtml(a, ctx, ".");
  const std::string summary_all = ReportSummary(a, ctx, "out/report.html");
  EXPECT_EQ(html_all.find("209%"), std::string::npos);
  EXPECT_EQ(summary_all.find("209%"), std::string::npos) << summary_all;
  EXPECT_NE(summary_all.find("(all of the nominal recording's misfit removed)"), std::string::npos) << summary_all;
  EXPECT_NE(html_all.find("removes all of the nominal's misfit"), std::string::npos);
  // On uneven ground the misfit is against a recording at other places and says so, with its SE,
  // and no share of a nominal misfit that may be negative there.
  a.leg_search.misfit_elsewhere = true;
  a.leg_search.nominal_misfit = -0.144, a.leg_search.best_misfit = -0.026, a.leg_search.best_misfit_se = 0.05;
  a.leg_search.gap_closed = NAN;
  const std::string html_else = ReportHtml(a, ctx, ".");
  const std::string summary_else = ReportSummary(a, ctx, "out/report.html");
  const auto json_else = nlohmann::json::parse(ReportJson(a, ctx));
  EXPECT_EQ(json_else["leg_search"]["misfit_against"], "other_places");
  EXPECT_DOUBLE_EQ(json_else["leg_search"]["best_misfit_se"].get<double>(), 0.05);
  EXPECT_NE(summary_else.find("as well as its own recording at other places does (misfit -0.026"), std::string::npos)
      << summary_else;
  EXPECT_EQ(html_else.find("nan%"), std::string::npos);
  EXPECT_EQ(summary_else.find("nan%"), std::string::npos) << summary_else;
}

// The fake pair's analysis with a payload search (planted 2.4 kg 10 cm behind) against a named weak
// leg3 that fits `leg_below` nats per real sample worse; `refused`: the payload's own gates refused
// it. PayloadVersusLeg, then the searches in the verdict as the analysis adds them.
Analysis PayloadAgainstLeg(double leg_below, bool refused) {
  const test::Stages s = test::RunStages({{test::kPayloadMass, 2.4}, {test::kPayloadX, -0.1}}, 3);
  PayloadSearchOptions options;
  options.search.model = s.options.locate.model;
  const test::FakePair pair = test::MakeFakePair(test::SharedFake(), {}, {});
  Analysis a = Analyse(pair.sim, pair.real, &test::SharedFake(), test::FastOptions());
  a.payload_search = SearchPayload(test::SharedFake(), s.in, s.set, s.options.candidates, options);
  EXPECT_TRUE(a.payload_search.search.named) << a.payload_search.why;
  if (refused) a.payload_search.search.named = false, a.payload_search.why = "its walk did not converge";
  a.leg_search.ran = a.leg_search.named = true;
  a.leg_search.leg = "leg3", a.leg_search.knob = "actuators.leg3.gain", a.leg_search.value = 0.45;
  a.leg_search.best_rows = a.payload_search.search.best_rows;
  for (int i = 0; i < a.leg_search.best_rows.size(); ++i) {
    a.leg_search.best_rows(i) -= leg_below + 0.1 * (s.in.real.episode[i] % 3);
  }
  a.leg_search.points = {{"leg3", a.leg_search.knob, test::kLeg3Gain, 0.45, a.leg_search.best_rows.mean(), true}};
  a.leg_search.best = 0;
  PayloadVersusLeg(s.in, options, &a.leg_search, &a.payload_search);
  a.verdict.status = "unexplained";
  a.verdict.named.clear();
  AddLegSearch(a.leg_search, &a.verdict);
  AddPayloadSearch(a.payload_search, &a.verdict);
  return a;
}

// A payload that took the name of a leg the leg search named (PayloadVersusLeg): every output names
// the payload, the JSON says which leg it replaced, the HTML says it beat it.
TEST(Report, APayloadThatTookALegsNameIsOneStoryInEveryOutput) {
  const Analysis a = PayloadAgainstLeg(1.0, false);
  ASSERT_FALSE(a.leg_search.named);
  ReportContext ctx;
  const auto json = nlohmann::json::parse(ReportJson(a, ctx));
  const std::string html = ReportHtml(a, ctx, ".");
  EXPECT_EQ(json["fit"]["corrected_by"], "payload_search");
  EXPECT_EQ(json["verdict"]["named"][0]["knob"], "payload.mass_kg");
  EXPECT_EQ(json["payload_search"]["leg_challenged"], "leg3 leg (gain 0.45)");
  EXPECT_EQ(json["payload_search"]["challenged"][0], "actuators.leg3.gain");
  EXPECT_FALSE(json["payload_search"]["refused_fits_better_than_leg"].get<bool>());
  EXPECT_FALSE(json["leg_search"]["named"].get<bool>());
  EXPECT_EQ(Count(html, Escaped(a.verdict.sentence)), 1u);
  EXPECT_NE(html.find("Against the weak leg3 leg (gain 0.45) the leg search named: its best point fits the real samples "
                      "better (z"),
            std::string::npos);
}

// A payload its gates refused that fits better than the named leg: every output keeps the leg, and
// the JSON, the HTML and the summary carry the one doubt.
TEST(Report, ARefusedPayloadThatFitsBetterIsTheLegsDoubtInEveryOutput) {
  const Analysis a = PayloadAgainstLeg(1.0, true);
  ASSERT_TRUE(a.leg_search.named);
  ReportContext ctx;
  const auto json = nlohmann::json::parse(ReportJson(a, ctx));
  const std::string html = ReportHtml(a, ctx, ".");
  const std::string summary = ReportSummary(a, ctx, "report.html");
  EXPECT_EQ(json["verdict"]["named"][0]["knob"], "actuators.leg3.gain");
  EXPECT_EQ(json["verdict"]["status"], "partly_explained");
  EXPECT_TRUE(json["payload_search"]["refused_fits_better_than_leg"].get<bool>());
  const std::string doubt = "though its own gates refused it (its walk did not converge)";
  int in_json = 0;
  for (const auto& d : json["verdict"]["doubts"]) in_json += d.get<std::string>().find(doubt) != std::string::npos;
  EXPECT_EQ(in_json, 1);
  EXPECT_NE(html.find(Escaped(doubt)), std::string::npos);
  EXPECT_NE(summary.find(doubt), std::string::npos) << summary;
  EXPECT_NE(html.find("its best point fits the real samples better, but its own gates refused it (z"), std::string::npos);
}

// The runoff's JSON speaks of knobs: no leg for a knob that is not a leg's, the knobs that fit as
// well by knob name, none of the leg search's challenge fields.
TEST(Report, TheRunoffsJsonNamesKnobsNotLegs) {
  const test::FakePair pair = test::MakeFakePair(test::SharedFake(), {}, {});
  Analysis a = Analyse(pair.sim, pair.real, &test::SharedFake(), test::FastOptions());
  a.runoff.ran = true;
  a.runoff.contenders = {"floor.friction@0.6", "actuators.leg1.gain@0.5"};
  LegSearch& s = a.runoff.search;
  s.ran = true, s.by = "runoff";
  s.points = {{"floor.friction", "floor.friction", 0, 0.6, -1.0, true},
              {"leg1", "actuators.leg1.gain", 1, 0.5, -1.1, true},
              {"floor.friction", "floor.friction", 0, 0.8, -1.5, false}};
  s.best = 0, s.leg = "floor.friction", s.knob = "floor.friction", s.value = 0.6;
  s.legs_as_well = {"leg1"};
  const auto j = nlohmann::json::parse(ReportJson(a, ReportContext{}))["runoff"];
  EXPECT_TRUE(j["leg"].is_null()) << j.dump();
  EXPECT_EQ(j["knob"], "floor.friction");
  EXPECT_TRUE(j["points"][0]["leg"].is_null());
  EXPECT_EQ(j["points"][1]["leg"], "leg1");
  EXPECT_EQ(j["knobs_as_well"], nlohmann::json::array({"actuators.leg1.gain"}));
  for (const char* leg_only : {"legs_as_well", "challenged", "z_vs_named", "rivals_named"}) EXPECT_FALSE(j.contains(leg_only)) << leg_only;
  EXPECT_EQ(j["contenders"].size(), 2u);
}

// A ground knob the ground stage named is one story: the JSON's ground block and fit say the
// search, the stdout summary names the knob, the HTML shows its curve.
TEST(Report, AGroundKnobNamedByTheGroundStageIsOneStory) {
  const test::FakePair pair = test::MakeFakePair(test::SharedFake(), {}, {});
  Analysis a = Analyse(pair.sim, pair.real, &test::SharedFake(), test::FastOptions());
  EXPECT_FALSE(a.ground.ran) << "the fake has no ground knobs";
  GroundSearch& g = a.ground;
  g.ran = g.moved = true;
  g.real = {0.0176, 0.0012, 166}, g.sim = {0.0129, 0.0006, 166};
  g.ratio = 1.36, g.ratio_se = 0.11, g.z_moved = 3.2;
  GroundCurve c;
  c.knob = "terrain.rough.rms_scale", c.knob_index = 0, c.values = {1, 1.5, 2}, c.ratios = {1, 1.27, 1.56};
  c.matched = 1.66, c.matched_ratio = 1.36, c.matched_se = 0.05, c.match_z = 0.02, c.meets = c.tilt_as_well = true;
  g.curves = {c};
  LegSearch& s = g.search;
  s.ran = s.named = true, s.by = "ground_search";
  s.points = {{"terrain.rough.rms_scale", "terrain.rough.rms_scale", 0, 1.66, 11.2, true}};
  s.best = 0, s.leg = s.knob = "terrain.rough.rms_scale", s.knob_index = 0, s.value = 1.66, s.nominal_score = 10.6;
  const auto j = nlohmann::json::parse(ReportJson(a, ReportContext{}));
  EXPECT_EQ(j["ground"]["named"], true) << j["ground"].dump();
  EXPECT_EQ(j["ground"]["curves"][0]["knob"], "terrain.rough.rms_scale");
  EXPECT_FALSE(j["ground"]["search"].contains("leg"));
  EXPECT_EQ(j["fit"]["corrected_by"], "ground_search");
  const std::string summary = ReportSummary(a, ReportContext{}, "report.html");
  EXPECT_NE(summary.find("corrected (terrain.rough.rms_scale)"), std::string::npos) << summary;
  const std::string html = ReportHtml(a, ReportContext{}, ".");
  EXPECT_NE(html.find("The ground: the standing tilt"), std::string::npos);
  EXPECT_NE(html.find("the ground knob of the ground search"), std::string::npos);
}

// The null's source is said where its value is: the JSON's source and count, the HTML's words.
TEST(Report, TheNullSaysWhereItCameFrom) {
  const test::FakePair pair = test::MakeFakePair(test::SharedFake(), {}, {});
  Analysis a = Analyse(pair.sim, pair.real, &test::SharedFake(), test::FastOptions());
  for (const bool recorded : {false, true}) {
    a.null_shortfall.recorded = recorded;
    a.null_shortfall.draws = recorded ? 3 : 20;
    a.null_shortfall.mean_se = recorded ? 0.25 : 0;
    const auto j = nlohmann::json::parse(ReportJson(a, ReportContext{}))["adequacy"];
    const std::string html = ReportHtml(a, ReportContext{}, ".");
    EXPECT_EQ(j["null_shortfall_source"], recorded ? "recorded" : "drawn");
    EXPECT_EQ(j["null_shortfall_draws"], recorded ? 3 : 20);
    EXPECT_EQ(j["null_shortfall_se"], recorded ? 0.25 : 0.0);
    EXPECT_EQ(html.find("3 re-recordings, SE of their mean 0.250") != std::string::npos, recorded);
    EXPECT_EQ(html.find("sets drawn from the sim model") != std::string::npos, !recorded);
  }
}

// The advice where the evidence stopped short of a name is in report.json as written, null
// without advice, and says the same in the verdict's sentence of every output.
TEST(Report, TheAdviceOfMorePlacementsIsOneStory) {
  const test::FakePair pair = test::MakeFakePair(test::SharedFake(), {}, {});
  Analysis a = Analyse(pair.sim, pair.real, &test::SharedFake(), test::FastOptions());
  ASSERT_FALSE(a.more_data.advised) << a.verdict.sentence;
  EXPECT_TRUE(nlohmann::json::parse(ReportJson(a, ReportContext{}))["more_data"].is_null());
  a.more_data.advised = true;
  a.more_data.knob = "payload.mass_kg", a.more_data.family = "payload", a.more_data.reason = "near_miss";
  a.more_data.z = a.more_data.z_effective = 2.4, a.more_data.z_required = 2.81;
  a.more_data.placements = 48, a.more_data.executions_per_placement = 5, a.more_data.placements_needed = 121;
  a.verdict.sentence += MoreDataSentence(a.more_data);
  const auto j = nlohmann::json::parse(ReportJson(a, ReportContext{}));
  EXPECT_EQ(j["more_data"]["placements_needed"], 121);
  EXPECT_EQ(j["more_data"]["reason"], "near_miss");
  EXPECT_TRUE(j["more_data"]["inclusion"].is_null()) << "a near miss has no inclusion";
  const std::string advice = "at least about 121 placements would be needed to decide it";
  EXPECT_EQ(Count(j["verdict"]["sentence"].get<std::string>(), advice), 1u);
  EXPECT_EQ(Count(ReportHtml(a, ReportContext{}, "."), advice), 1u);
  EXPECT_EQ(Count(ReportSummary(a, ReportContext{}, "report.html"), advice), 1u);
  a.more_data.placements_needed = -1, a.more_data.max_factor = 12;
  const auto beyond = nlohmann::json::parse(ReportJson(a, ReportContext{}))["more_data"];
  EXPECT_TRUE(beyond["placements_needed"].is_null());
  EXPECT_EQ(beyond["max_factor"], 12) << "null placements_needed means more than this many times the placements";
}

}  // namespace
}  // namespace dgmm::sim2real
