#include "sim/protocol.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <set>

#include "core/set_warnings.h"
#include "robot_files.h"
#include "sim/sim_config.h"
#include "util/error.h"

namespace dgmm::sim {
namespace {

// A short paper protocol: 6 placements (2 commands x 3 headings), 2 executions each.
ProtocolOptions Short(std::uint64_t seed) {
  ProtocolOptions o;
  o.seed = seed;
  o.placements = 6;
  o.executions_per_placement = 2;
  return o;
}

TEST(ProtocolTest, RecordsTheDocumentedLayout) {
  SimSummary summary;
  long long last_done = 0, last_total = 0;
  const SampleSet set = SimulateProtocol(SimConfig{}, Short(3), [&](long long d, long long t) {
    last_done = d;
    last_total = t;
  }, &summary);
  EXPECT_EQ(set.Validate(), "");
  EXPECT_EQ(set.size(), 12);
  EXPECT_EQ(summary.samples, 12);
  EXPECT_EQ(summary.falls, 0);
  EXPECT_EQ(last_done, 6);
  EXPECT_EQ(last_total, 6);
  EXPECT_EQ(set.num_commands(), 26);
  EXPECT_EQ(set.command_dim_names, (std::vector<std::string>{"long", "lat", "turn"}));
  EXPECT_EQ(set.x_names, (std::vector<std::string>{"dx", "dy", "dz", "droll", "dpitch", "dyaw"}));
  EXPECT_EQ(set.z_names, (std::vector<std::string>{"pitch", "roll"}));
  EXPECT_EQ(set.source, "sim");
  EXPECT_TRUE(set.has_sequence());
  EXPECT_EQ(set.metadata.at("seed"), "3");
  EXPECT_EQ(set.metadata.at("protocol"), "paper");
  EXPECT_NE(set.metadata.at("sim_config").find("slope_deg"), std::string::npos);
  // No no-op command; every level in {-0.5, 0, 0.5}.
  for (int c = 0; c < set.num_commands(); ++c) {
    EXPECT_GT(set.commands.row(c).cwiseAbs().sum(), 0);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(std::abs(set.commands(c, k)) * 2, std::round(std::abs(set.commands(c, k)) * 2));
  }
  // Three placements per command (headings 0, 90, -90 deg), two steps each.
  EXPECT_EQ(std::set<int>(set.command.data(), set.command.data() + set.size()).size(), 2u);
  for (int i = 0; i < set.size(); ++i) {
    EXPECT_EQ(set.episode[i], i / 2);
    EXPECT_EQ(set.step[i], i % 2);
  }
  // Headings: across (|roll| ~ slope), downhill (pitch ~ +slope), uphill (pitch ~ -slope).
  const double slope = 18 * M_PI / 180, kTol = 0.1;  // rad: IMU noise plus stance tilt
  EXPECT_NEAR(std::abs(set.z(0, 1)), slope, kTol);
  EXPECT_NEAR(set.z(2, 0), slope, kTol);
  EXPECT_NEAR(set.z(4, 0), -slope, kTol);
}

TEST(ProtocolTest, SameSeedSameSetOtherSeedOtherSet) {
  const SampleSet a = SimulateProtocol(SimConfig{}, Short(7));
  const SampleSet b = SimulateProtocol(SimConfig{}, Short(7));
  const SampleSet c = SimulateProtocol(SimConfig{}, Short(8));
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.z, b.z);
  EXPECT_EQ(a.command, b.command);
  EXPECT_NE(a.x, c.x);
}

TEST(ProtocolTest, AChunkedRecordingDoesNotDependOnTheThreadCount) {
  ProtocolOptions o = Short(7);
  o.placements = 5;
  o.executions_per_placement = 2;
  o.chunk_placements = 2;
  const SampleSet one = SimulateProtocol(SimConfig{}, o);
  o.threads = 3;
  const SampleSet three = SimulateProtocol(SimConfig{}, o);
  EXPECT_EQ(one.x, three.x);
  EXPECT_EQ(one.z, three.z);
  EXPECT_EQ(one.episode, three.episode);
  EXPECT_EQ(three.metadata.at("random_streams"), "one per chunk of 2 placements");
  // The same plan as one stream (placements and commands); the chunks' own streams change the noise.
  o.chunk_placements = 0;
  const SampleSet single = SimulateProtocol(SimConfig{}, o);
  EXPECT_EQ(single.command, one.command);
  EXPECT_EQ(single.episode, one.episode);
  EXPECT_EQ(single.metadata.count("random_streams"), 0u);
  EXPECT_NE(single.z, one.z);
}

TEST(ProtocolTest, FullPaperPlanDrawsEveryCommandThreeTimes) {
  // Plan check without physics cost: one execution of a very short gait per placement.
  SimConfig fast;
  fast.command_duration_s = fast.gait.period_s;
  fast.settle_duration_s = 0.05;
  ProtocolOptions o;
  o.executions_per_placement = 1;
  const SampleSet set = SimulateProtocol(fast, o);
  ASSERT_EQ(set.size(), 78);
  std::vector<int> count(26, 0);
  for (int i = 0; i < set.size(); ++i) ++count[set.command[i]];
  for (int c = 0; c < 26; ++c) EXPECT_EQ(count[c], 3) << c;
  // Drawn without replacement: consecutive triples share a command.
  for (int i = 0; i < set.size(); i += 3) {
    EXPECT_EQ(set.command[i], set.command[i + 1]);
    EXPECT_EQ(set.command[i], set.command[i + 2]);
  }
}

TEST(ProtocolTest, FallsAreCountedNotRecorded) {
  SimConfig c;
  c.slope_deg = 30;
  c.payload.mass_kg = 60;
  c.payload.position_body_m = Eigen::Vector3d(0, 0.8, 0.8);
  ProtocolOptions o = Short(1);
  o.max_retries_per_placement = 0;
  SimSummary summary;
  const SampleSet set = SimulateProtocol(c, o, {}, &summary);
  EXPECT_GT(summary.falls, 0);
  EXPECT_EQ(set.size(), 2 * (6 - summary.abandoned_placements));
  EXPECT_EQ(summary.abandoned_placements, summary.falls);
  EXPECT_EQ(set.metadata.at("falls"), std::to_string(summary.falls));
}

// Samples of placement `episode`, step by step: x then z of each.
std::vector<double> PlacementSamples(const SampleSet& set, int episode) {
  std::vector<double> out;
  for (int i = 0; i < set.size(); ++i) {
    if (set.episode[i] != episode) continue;
    for (int j = 0; j < set.x.cols(); ++j) out.push_back(set.x(i, j));
    for (int j = 0; j < set.z.cols(); ++j) out.push_back(set.z(i, j));
  }
  return out;
}

// Recordings of one plan, paired or not, that retry a fall or give up on it: with paired streams
// the two record every placement after the first fall alike; without, the retries' draws shift
// every later placement's sensor noise. The plan must make the robot fall at some of its
// `placements` and hold at a later one.
void ExpectLaterPlacementsPaired(const std::function<SampleSet(bool paired, int retries)>& record, int placements) {
  const SampleSet gives_up = record(true, 0), retries = record(true, 2);
  const SampleSet gives_up_unpaired = record(false, 0), retries_unpaired = record(false, 2);
  int first_fall = -1, later_in_both = 0, unpaired_differ = 0;
  for (int p = 0; p < placements; ++p) {
    const std::vector<double> a = PlacementSamples(gives_up, p), b = PlacementSamples(retries, p);
    if (a.empty() && first_fall < 0) first_fall = p;
    if (first_fall < 0 || p == first_fall || a.empty() || b.empty()) continue;
    ++later_in_both;
    EXPECT_EQ(a, b) << "placement " << p << " after the fall at " << first_fall;
    unpaired_differ += PlacementSamples(gives_up_unpaired, p) != PlacementSamples(retries_unpaired, p);
  }
  ASSERT_GE(first_fall, 0) << "the plan makes the robot fall";
  ASSERT_GT(later_in_both, 0) << "a placement after the fall held in both";
  EXPECT_GT(unpaired_differ, 0) << "without paired streams the retries shift later noise";
}

// A payload heavy and high on one side on a 30 deg slope: the robot falls at some headings and
// commands, at every attempt.
SimConfig FallingConfig() {
  SimConfig c;
  c.slope_deg = 30;
  c.payload.mass_kg = 3;
  c.payload.position_body_m = Eigen::Vector3d(0, 0.4, 0.4);
  return c;
}

// With paired streams a fall's retries draw from streams of their own: a recording that retries
// and one that gives up on the same falls record every later placement alike (placements 2, 4 and
// 5 of seed 1 fall, 0, 1 and 3 hold).
TEST(ProtocolTest, PairedStreamsKeepLaterPlacementsNoiseWhateverFalls) {
  ExpectLaterPlacementsPaired(
      [](bool paired, int retries) {
        ProtocolOptions o = Short(1);
        o.max_retries_per_placement = retries;
        o.paired_streams = paired;
        return SimulateProtocol(FallingConfig(), o);
      },
      6);
}

// The same for one cell of the experiment check (sim2real compares cells at two knob values).
TEST(ProtocolCellTest, PairedStreamsKeepLaterPlacementsNoiseWhateverFalls) {
  ExpectLaterPlacementsPaired(
      [](bool paired, int retries) {
        CellOptions cell;
        cell.command = Eigen::Vector3d(0.5, 0, 0);
        // Facing uphill (heading 0) the robot falls at every attempt, sideways it holds.
        cell.headings_rad = {M_PI / 2, M_PI / 2, 0, M_PI / 2, 0, M_PI / 2, M_PI / 2, M_PI / 2};
        cell.placements = 8;
        cell.executions_per_placement = 3;
        cell.seed = 1;
        cell.max_retries_per_placement = retries;
        cell.paired_streams = paired;
        return SimulateCell(FallingConfig(), cell);
      },
      8);
}

TEST(ProtocolTest, PairedStreamsLeaveARecordingWithoutFallsAsItWas) {
  ProtocolOptions o = Short(3);
  SimSummary summary;
  const SampleSet plain = SimulateProtocol(SimConfig{}, o, {}, &summary);
  ASSERT_EQ(summary.falls, 0);
  o.paired_streams = true;
  const SampleSet paired = SimulateProtocol(SimConfig{}, o);
  EXPECT_EQ(paired.x, plain.x);
  EXPECT_EQ(paired.z, plain.z);
}

TEST(ProtocolTest, TrajectoriesRunASequenceOfCommandsPerPlacement) {
  ProtocolOptions o;
  o.protocol = ParseProtocol("trajectories");
  EXPECT_EQ(ProtocolName(o.protocol), "trajectories");
  o.seed = 4;
  o.placements = 3;
  o.executions_per_placement = 6;
  const SampleSet set = SimulateProtocol(SimConfig{}, o);
  ASSERT_EQ(set.Validate(), "");
  ASSERT_EQ(set.size(), 18);
  std::set<int> commands_of_first;
  for (int i = 0; i < set.size(); ++i) {
    EXPECT_EQ(set.step[i], i % 6);
    EXPECT_EQ(set.episode[i], i / 6);
    if (set.episode[i] == 0) commands_of_first.insert(set.command[i]);
  }
  EXPECT_GT(commands_of_first.size(), 1u) << "a sequence of commands, not one repeated";
  EXPECT_EQ(set.metadata.at("protocol"), "trajectories");
}

// Issue #25: continuous commands drawn uniformly from [-0.5, 0.5]^3, one "velocity" command, the
// values stored as the first three conditioning dimensions of z; and the robot really follows
// them (the turn command's sign is the yaw change's).
TEST(ProtocolTest, ContinuousCommandsAreConditioningDimensions) {
  ProtocolOptions o;
  o.protocol = ParseProtocol("continuous");
  EXPECT_EQ(ProtocolName(o.protocol), "continuous");
  o.seed = 5;
  o.placements = 4;
  o.executions_per_placement = 3;
  const SampleSet set = SimulateProtocol(SimConfig{}, o);
  ASSERT_EQ(set.Validate(), "");
  ASSERT_EQ(set.size(), 12);
  EXPECT_EQ(set.command_labels, std::vector<std::string>{"velocity"});
  ASSERT_EQ(set.terrain_dim(), 5);
  EXPECT_EQ(set.z_names,
            (std::vector<std::string>{"cmd_long", "cmd_lat", "cmd_turn", "pitch", "roll"}));
  EXPECT_EQ(set.metadata.at("continuous_command_columns"), "3");
  std::set<double> distinct;
  int turns_followed = 0, strong_turns = 0;
  for (int i = 0; i < set.size(); ++i) {
    for (int j = 0; j < 3; ++j) {
      EXPECT_GE(set.z(i, j), -0.5);
      EXPECT_LE(set.z(i, j), 0.5);
      distinct.insert(set.z(i, j));
    }
    if (std::abs(set.z(i, 2)) > 0.2) {
      ++strong_turns;
      turns_followed += (set.z(i, 2) > 0) == (set.x(i, 5) > 0);
    }
  }
  EXPECT_EQ(distinct.size(), 36u);  // every value drawn anew
  EXPECT_GT(strong_turns, 0);
  EXPECT_EQ(turns_followed, strong_turns);
}

TEST(ProtocolTest, ParsesNamesAndRejectsBadOptions) {
  EXPECT_EQ(ParseProtocol("paper"), Protocol::kPaper);
  EXPECT_EQ(ParseProtocol("paper-830"), Protocol::kPaper830);
  EXPECT_THROW(ParseProtocol("paper830"), InputError);
  ProtocolOptions o;
  o.executions_per_placement = 0;
  EXPECT_THROW(SimulateProtocol(SimConfig{}, o), InputError);
  ProtocolOptions chunks;
  chunks.chunk_placements = -1;
  EXPECT_THROW(SimulateProtocol(SimConfig{}, chunks), InputError);
  ProtocolOptions threads;
  threads.threads = 0;
  EXPECT_THROW(SimulateProtocol(SimConfig{}, threads), InputError);
  SimConfig bad;
  bad.timestep_s = -1;
  EXPECT_THROW(SimulateProtocol(bad, ProtocolOptions{}), InputError);
}


TEST(ProtocolSensedTerrainTest, RecordsTheTerrainAsTheRobotSensesIt) {
  SimConfig c;
  c.slope_deg = 5;
  TerrainDescription t;
  t.half_size_m = 2.5;
  t.resolution_m = 0.04;
  t.stones = {0.04, 0.1, 3};
  t.sensed = {"foot_relief", "height_ahead"};
  c.terrain = t;
  const SampleSet set = SimulateProtocol(c, Short(5));
  ASSERT_EQ(set.z.cols(), 4);
  EXPECT_EQ(set.z_names, (std::vector<std::string>{"pitch", "roll", "foot_relief", "height_ahead"}));
  EXPECT_EQ(set.z_units[3], "m");
  EXPECT_GE(set.z.col(2).minCoeff(), 0.0);
  EXPECT_GT(set.z.col(2).maxCoeff(), 2e-3);  // some placement has a foot on a stone
  EXPECT_GT(set.z.col(3).cwiseAbs().maxCoeff(), 1e-3);

  // The same on featureless ground: nothing ahead, the feet in one plane.
  c.terrain->stones = {};
  const SampleSet flat = SimulateProtocol(c, Short(5));
  EXPECT_EQ(flat.z.col(3).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(flat.z.col(2).maxCoeff(), 0.0);
  // Without sensed descriptors, the set is the one the plane config records (pitch, roll).
  c.terrain->sensed.clear();
  EXPECT_EQ(SimulateProtocol(c, Short(5)).z.cols(), 2);
}


TEST(ProtocolCellTest, OnRoughGroundEachPlacementGetsItsOwnHeading) {
  SimConfig c;
  c.slope_deg = 10;
  CellOptions cell;
  cell.command = Eigen::Vector3d(0.5, 0, 0);
  cell.placements = 3;
  cell.executions_per_placement = 1;
  cell.seed = 4;
  // On the plane every position reads the same: one heading for all.
  const std::vector<double> plane = HeadingsForTerrain(c, cell, 0.1, 0.05, 12);
  ASSERT_EQ(plane.size(), 3u);
  EXPECT_EQ(plane[0], HeadingForTerrain(c, 0.1, 0.05, 12));
  EXPECT_EQ(plane[1], plane[0]);
  EXPECT_EQ(plane[2], plane[0]);
  // The placements then stand where asked and face as matched.
  cell.headings_rad = plane;
  const SampleSet set = SimulateCell(c, cell);
  EXPECT_EQ(set.size(), 3);
  cell.headings_rad.pop_back();
  EXPECT_THROW(SimulateCell(c, cell), InputError);
}

// The hexapod's foot targets are fixed in its torso frame: on its rough ground its tilt carries over
// from step to step and the protocol says so; on its own slope it walks level and says nothing.
TEST(ProtocolTest, ATorsoThatStartsTiltedIsCountedAndWarnedOf) {
  ProtocolOptions o;
  o.seed = 5;
  o.placements = 8;
  o.executions_per_placement = 5;
  SimSummary rough, plane;
  const SampleSet rough_set =
      SimulateProtocol(LoadSimConfig((test::kRobots / "hexapod_rough_ground.json").string()), o, {}, &rough);
  const SampleSet plane_set = SimulateProtocol(LoadSimConfig((test::kRobots / "hexapod.json").string()), o, {}, &plane);
  EXPECT_TRUE(rough.TiltedTooOften()) << rough.tilted_executions << " of " << rough.executions;
  ASSERT_FALSE(rough.warnings.empty());
  EXPECT_NE(rough.warnings.back().find("tilted more than 25 degrees"), std::string::npos) << rough.warnings.back();
  EXPECT_NE(rough.warnings.back().find("robot.gait.level"), std::string::npos) << rough.warnings.back();
  EXPECT_EQ(plane.tilted_executions, 0);
  for (const std::string& w : plane.warnings) EXPECT_EQ(w.find("tilted"), std::string::npos) << w;
  // The set keeps the counts and the warnings, one per line, for the analyses that read it.
  EXPECT_EQ(rough_set.metadata.at("executions"), std::to_string(rough.executions));
  EXPECT_EQ(rough_set.metadata.at("tilted_executions"), std::to_string(rough.tilted_executions));
  EXPECT_EQ(KeptWarnings(rough_set), rough.warnings);
  EXPECT_EQ(plane_set.metadata.at("tilted_executions"), "0");
  EXPECT_EQ(KeptWarnings(plane_set), plane.warnings);
}

}  // namespace
}  // namespace dgmm::sim
