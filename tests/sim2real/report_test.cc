// Stage 9: one story. For a null, a single-knob and an out-of-library pair, report.json,
// report.html and the stdout summary say the same thing: the verdict's status and sentence, once,
// and nothing else concludes.
#include "sim2real/report.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tests/sim2real/fake_simulator.h"

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

}  // namespace
}  // namespace dgmm::sim2real
