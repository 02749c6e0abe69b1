#pragma once
// Shared helpers of the io tests: seeded random sets and models, bitwise comparisons, temp files.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <random>
#include <string>

#include "core/motion_model.h"
#include "core/sample_set.h"

namespace dgmm::test {

// What a random set holds besides x.
struct RandomSetShape {
  int n = 100, dx = 2, dz = 0, commands = 1, command_dims = 0;
  bool episodes = false, transform = false;
};
// A valid set with awkward doubles (tiny, huge, negative zero, many digits) from `seed`.
SampleSet RandomSet(const RandomSetShape& shape, std::uint64_t seed);
// A model with `commands` mixtures of random SPD components over d = pose + terrain dims.
MotionModel RandomModel(int pose_dim, int terrain_dim, int commands, std::uint64_t seed,
                        bool transform);

// Every field equal, doubles compared bit for bit.
void ExpectSameSet(const SampleSet& a, const SampleSet& b);
void ExpectSameModel(const MotionModel& a, const MotionModel& b);
bool SameBits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

// A fresh folder for one test (removed at the start of the next run of the same test).
std::filesystem::path TestDir();
// Files in dir whose name contains ".tmp-" (left-over temporary outputs).
int CountTempFiles(const std::filesystem::path& dir);
// Writes text to a file.
void WriteText(const std::filesystem::path& path, const std::string& text);

}  // namespace dgmm::test
