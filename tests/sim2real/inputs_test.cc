// Stage 1: the two sets as the analysis sees them.
#include "sim2real/inputs.h"

#include <gtest/gtest.h>

#include "tests/sim2real/fake_simulator.h"
#include "tests/sim2real/synthetic.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

TEST(Inputs, TheSimSetsRecordingAndTheRealCommandsItLacks) {
  const test::FakeSimulator fake;
  test::FakePair pair = test::MakeFakePair(fake, {});
  // The real set also recorded a command the sim set never did: its samples are dropped, named.
  pair.real.commands.conservativeResize(pair.real.commands.rows() + 1, Eigen::NoChange);
  pair.real.commands.row(pair.real.commands.rows() - 1) << 0.25, 0.25, 0.25;
  pair.real.command_labels.push_back("new");
  pair.real.command(0) = pair.real.commands.rows() - 1;
  const AnalysisInputs in = PrepareInputs(pair.sim, pair.real, 99);
  EXPECT_TRUE(in.recording_from_metadata);
  EXPECT_EQ(in.recording.protocol, "paper");
  EXPECT_EQ(in.recording.seed, 7u);
  EXPECT_EQ(in.dropped_commands, std::vector<std::string>{"new"});
  EXPECT_EQ(in.dropped_samples, 1);
  EXPECT_EQ(in.real.size(), pair.real.size() - 1);
  EXPECT_EQ(in.real_source_row.front(), 1);
  EXPECT_EQ(in.layout.dyaw, 2);
  EXPECT_NEAR(in.first_execution_share, 0.2, 0.01);  // 5 executions per placement
  pair.sim.metadata.clear();
  EXPECT_FALSE(PrepareInputs(pair.sim, pair.real, 99).recording_from_metadata);
  EXPECT_EQ(PrepareInputs(pair.sim, pair.real, 99).recording.seed, 99u);
}

TEST(Inputs, SetsThatShareNoCommandAreRefused) {
  const test::FakeSimulator fake;
  test::FakePair pair = test::MakeFakePair(fake, {});
  pair.real.commands.array() += 0.125;
  for (auto& l : pair.real.command_labels) l += "x";
  EXPECT_THROW(PrepareInputs(pair.sim, pair.real, 1), InputError);
}

TEST(Inputs, ASimSetNoLargerThanTheRealSetIsWarnedAbout) {
  const SampleSet paper = GenerateSynthetic(SyntheticWorld{}, "paper", 1);      // 3 placements per command
  const SampleSet paper830 = GenerateSynthetic(SyntheticWorld{}, "paper-830", 2);  // 6 or 7
  const AnalysisInputs small = PrepareInputs(paper, GenerateSynthetic(SyntheticWorld{}, "paper", 3), 1);
  EXPECT_EQ(CountPlacementsPerCommand(small).sim, 3);
  EXPECT_EQ(CountPlacementsPerCommand(small).real, 3);
  const std::string note = SmallSimSetNote(small, "sim.h5");
  EXPECT_EQ(note.rfind("sim.h5: 3 placements per command (median), no more than the real set's 3", 0), 0u) << note;
  const AnalysisInputs large = PrepareInputs(paper830, GenerateSynthetic(SyntheticWorld{}, "paper", 3), 1);
  EXPECT_GT(CountPlacementsPerCommand(large).sim, 5);
  EXPECT_EQ(SmallSimSetNote(large, "sim.h5"), "");
}

}  // namespace
}  // namespace dgmm::sim2real
