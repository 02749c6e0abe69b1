#pragma once
// Test fixture that turns MuJoCo warnings and errors into GoogleTest failures
// (after MuJoCo's test/fixture.h).
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

namespace dgmm::sim::test {

class MujocoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    previous_warning_ = mju_user_warning;
    mju_user_warning = [](const char* message) { ADD_FAILURE() << "MuJoCo warning: " << message; };
  }
  void TearDown() override { mju_user_warning = previous_warning_; }

 private:
  void (*previous_warning_)(const char*) = nullptr;
};

}  // namespace dgmm::sim::test
