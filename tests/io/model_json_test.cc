// JSON export: everything a user outside C++ needs, and raw-unit components that agree with
// the model's transform.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "io/model_io.h"
#include "tests/io/io_test_util.h"
#include "util/error.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json Export(const MotionModel& model) {
  const fs::path path = test::TestDir() / "m.json";
  WriteModelJson(model, path);
  std::ifstream in(path);
  return json::parse(in);
}

TEST(ModelJson, HoldsDimsNamesOptionsAndEveryComponent) {
  const MotionModel model = test::RandomModel(2, 1, 3, 5, false);
  const json j = Export(model);
  EXPECT_EQ(j["kind"], "dgmm");
  EXPECT_EQ(j["pose_dim"], 2);
  EXPECT_EQ(j["terrain_dim"], 1);
  EXPECT_EQ(j["pose_names"].get<std::vector<std::string>>(), model.pose_names);
  EXPECT_EQ(j["terrain_names"].get<std::vector<std::string>>(), model.terrain_names);
  EXPECT_EQ(j["seed"].get<std::uint64_t>(), model.seed);
  EXPECT_EQ(j["dgmm_options"]["variant"], "improved");
  EXPECT_EQ(j["dgmm_options"]["k"].get<double>(), model.dgmm_options.k);
  EXPECT_EQ(j["dgmm_options"]["covariance_rule"], "prior");
  EXPECT_EQ(j["dgmm_options"]["prior_pseudo_count"].get<double>(),
            model.dgmm_options.prior_pseudo_count);
  EXPECT_EQ(j["dgmm_options"]["initial_covariance_rule"], "data");
  EXPECT_EQ(j["dgmm_options"]["covariance_floor_relative"].get<double>(),
            model.dgmm_options.covariance_floor_relative);
  EXPECT_TRUE(j["transform"].is_null());
  ASSERT_EQ(j["commands"].size(), model.command_values.size());
  for (const json& c : j["commands"]) {
    const int id = c["id"];
    EXPECT_EQ(c["label"], model.command_labels.at(id));
    EXPECT_FALSE(c.contains("raw_units"));
    if (!model.mixtures.count(id)) {
      EXPECT_EQ(c["num_components"], 0);  // a command without samples is listed, empty
      continue;
    }
    const Mixture& m = model.mixtures.at(id);
    ASSERT_EQ(c["num_components"], m.size());
    double sum = 0;
    for (int k = 0; k < m.size(); ++k) {
      // Doubles are printed with enough digits to read back exactly.
      EXPECT_EQ(c["raw_weights"][k].get<double>(), m.weight(k));
      EXPECT_EQ(c["weights"][k].get<double>(), m.weight(k) / m.total_weight());
      sum += c["weights"][k].get<double>();
      for (int a = 0; a < m.dim(); ++a) {
        EXPECT_EQ(c["means"][k][a].get<double>(), m.component(k).mean()[a]);
        for (int b = 0; b < m.dim(); ++b) {
          EXPECT_EQ(c["covariances"][k][a][b].get<double>(), m.component(k).covariance()(a, b));
        }
      }
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
  }
}

TEST(ModelJson, RawUnitComponentsFollowTheTransform) {
  const MotionModel model = test::RandomModel(2, 1, 2, 6, true);
  const json j = Export(model);
  EXPECT_EQ(j["transform"]["scale"].size(), 3u);
  const Eigen::VectorXd& offset = model.transform.offset;
  const Eigen::VectorXd& scale = model.transform.scale;
  for (const json& c : j["commands"]) {
    const int id = c["id"];
    if (!model.mixtures.count(id)) continue;
    const Mixture& m = model.mixtures.at(id);
    ASSERT_TRUE(c.contains("raw_units"));
    for (int k = 0; k < m.size(); ++k) {
      for (int a = 0; a < 3; ++a) {
        // y_raw = offset + scale .* y: mean maps affinely, covariance by scale_a scale_b.
        EXPECT_DOUBLE_EQ(c["raw_units"]["means"][k][a].get<double>(),
                         offset[a] + scale[a] * m.component(k).mean()[a]);
        for (int b = 0; b < 3; ++b) {
          EXPECT_DOUBLE_EQ(c["raw_units"]["covariances"][k][a][b].get<double>(),
                           scale[a] * scale[b] * m.component(k).covariance()(a, b));
        }
      }
    }
  }
}

TEST(ModelJson, UnwritablePathIsAnInputError) {
  EXPECT_THROW(WriteModelJson(test::RandomModel(2, 0, 1, 1, false), "/no/such/dir/m.json"),
               InputError);
}

}  // namespace
}  // namespace dgmm
