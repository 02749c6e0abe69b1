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

// A sim set's metadata seed is digits or refused, naming it ("-5" would wrap round to 2^64 - 5, "7x"
// read as 7); a real set's is read the same way and ignored when it is not one.
TEST(Inputs, AMetadataSeedIsDigitsOnly) {
  const test::FakeSimulator fake;
  test::FakePair pair = test::MakeFakePair(fake, {});
  for (const char* bad : {"-5", "7x", "", "99999999999999999999999"}) {
    pair.sim.metadata["seed"] = bad;
    try {
      PrepareInputs(pair.sim, pair.real, 99);
      ADD_FAILURE() << "seed '" << bad << "' accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("metadata seed"), std::string::npos) << e.what();
    }
    pair.real.metadata["seed"] = bad;
  }
  pair.sim.metadata["seed"] = "18446744073709551615";
  const AnalysisInputs in = PrepareInputs(pair.sim, pair.real, 99);
  EXPECT_EQ(in.recording.seed, 18446744073709551615u);
  EXPECT_FALSE(in.real_seed.has_value()) << "the real set's last seed was too large";
}

TEST(Inputs, SetsThatShareNoCommandAreRefused) {
  const test::FakeSimulator fake;
  test::FakePair pair = test::MakeFakePair(fake, {});
  pair.real.commands.array() += 0.125;
  for (auto& l : pair.real.command_labels) l += "x";
  EXPECT_THROW(PrepareInputs(pair.sim, pair.real, 1), InputError);
}

// Three headings per command, one placement each: a held-out sim placement leaves its heading out.
TEST(Inputs, ASimSetWithOnePlacementPerSettingIsWarnedAbout) {
  const SampleSet paper = GenerateSynthetic(SyntheticWorld{}, "paper", 1);
  const SampleSet real = GenerateSynthetic(SyntheticWorld{}, "paper", 3);
  const AnalysisInputs small = PrepareInputs(paper, real, 1);
  const SettingCoverage c = MeasureSettingCoverage(small);
  EXPECT_GT(c.sim_to_sim, 10 * c.real_to_sim) << c.sim_to_sim << " " << c.real_to_sim;
  const std::string note = SmallSimSetNote(small, "sim.h5");
  EXPECT_EQ(note.rfind("sim.h5: a sim placement's terrain z lies ", 0), 0u) << note;
  // paper-830 repeats each command's headings: covered, no warning.
  const AnalysisInputs large = PrepareInputs(GenerateSynthetic(SyntheticWorld{}, "paper-830", 2), real, 1);
  EXPECT_EQ(SmallSimSetNote(large, "sim.h5"), "");
  // Nor for a real log whose every execution is its own episode (the settings are what counts).
  SampleSet single = real;
  for (int i = 0; i < single.size(); ++i) single.episode(i) = i, single.step(i) = 0;
  EXPECT_EQ(SmallSimSetNote(PrepareInputs(GenerateSynthetic(SyntheticWorld{}, "paper-830", 2), single, 1), "sim.h5"), "");
}

TEST(Inputs, WhatASetsRecordingWarnedOfIsANoteNamingTheSet) {
  SampleSet set = GenerateSynthetic(SyntheticWorld{}, "paper", 1);
  EXPECT_TRUE(RecordingNotes(set, "sim.h5").empty()) << "a log or an older set: nothing to relay";
  set.metadata["recording_warnings"] = "robot: its torso started 9 of 20 executions tilted\n\nrobot: its legs touched";
  const std::vector<std::string> notes = RecordingNotes(set, "sim.h5");
  ASSERT_EQ(notes.size(), 2u) << "one note per warning, empty lines skipped";
  EXPECT_EQ(notes[0], "sim.h5: dgmm warned when it made this set: robot: its torso started 9 of 20 executions tilted");
  EXPECT_EQ(notes[1], "sim.h5: dgmm warned when it made this set: robot: its legs touched");
}

}  // namespace
}  // namespace dgmm::sim2real
