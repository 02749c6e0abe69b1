// The verdict object's JSON (the contract with scripts/sim2real_battery.py).
#include "sim2real/verdict.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>


namespace dgmm::sim2real {
namespace {

TEST(Verdict, DriftingEffectsAreWrittenApartFromTheNamedOnes) {
  Verdict v;
  v.status = "unexplained";
  VerdictDrifting d;
  d.family = "actuator_gain", d.knob = "actuators.kp_scale", d.value = 0.72, d.nominal = 1.0;
  d.first = 0.95, d.last = 0.49, d.gamma = 1.4, d.p_value = 0.001;
  v.drifting.push_back(d);
  d.along = "execution index", d.family = "tracker_bias", d.first = -0.01, d.last = 0.03, d.first_step = 1, d.last_step = 3;
  v.drifting.push_back(d);
  v.structured_in = {"session order"};
  const auto j = nlohmann::json::parse(VerdictJson(v));
  EXPECT_TRUE(j["named"].empty());
  ASSERT_EQ(j["drifting"].size(), 2u);
  EXPECT_EQ(j["drifting"][0]["along"], "session order");
  EXPECT_EQ(j["drifting"][1]["along"], "execution index");
  EXPECT_DOUBLE_EQ(j["drifting"][1]["highest"].get<double>(), 0.03);
  EXPECT_EQ(j["drifting"][1]["lowest_step"], 1);
  EXPECT_FALSE(j["drifting"][1].contains("first"));
  EXPECT_EQ(j["drifting"][0]["family"], "actuator_gain");
  EXPECT_DOUBLE_EQ(j["drifting"][0]["first"].get<double>(), 0.95);
  EXPECT_DOUBLE_EQ(j["drifting"][0]["last"].get<double>(), 0.49);
  EXPECT_DOUBLE_EQ(j["drifting"][0]["relative_change"].get<double>(), 1.4);
  EXPECT_TRUE(j["drifting"][0]["inclusion"].is_null());
  EXPECT_EQ(j["unexplained"]["structured_in"][0], "session order");
}

}  // namespace
}  // namespace dgmm::sim2real
