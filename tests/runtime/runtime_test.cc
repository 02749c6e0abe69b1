// lib/runtime/dgmm_runtime.h agrees with the library to 1e-9 on models fitted (DGMM and EM) from
// every shipped sample set and from the standardised Old Faithful set, exported with `dgmm export`.
#include "runtime/dgmm_runtime.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <unistd.h>

#include "io/model_io.h"
#include "io/sample_set_io.h"

namespace dgmm {
namespace {

namespace fs = std::filesystem;

class RuntimeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("dgmm_runtime_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void Dgmm(const std::string& args) {
    const char* exe = std::getenv("DGMM_EXE");
    ASSERT_NE(exe, nullptr);
    ASSERT_EQ(std::system((std::string(exe) + " --quiet " + args + " > /dev/null 2>&1").c_str()), 0) << args;
  }
  std::string Read(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  // Fits `fit_args` on `set`, exports, and compares the runtime with the library at every sample.
  void ExpectAgreement(const fs::path& set, const std::string& fit_args) {
    const fs::path model = dir_ / "model.h5", json = dir_ / "model.json";
    Dgmm(fit_args + " " + set.string() + " -o " + model.string());
    Dgmm("export " + model.string() + " -o " + json.string());
    const MotionModel lib = ReadModel(model.string());
    const auto rt = dgmm_runtime::Model::FromJson(Read(json));
    const SampleSet data = ReadSampleSet(set.string());
    ASSERT_EQ(rt.pose_dim(), lib.pose_dim);
    ASSERT_EQ(rt.terrain_dim(), lib.terrain_dim);
    std::map<int, int> index;  // library command id -> runtime index, by label
    for (const auto& [id, label] : lib.command_labels) index[id] = rt.CommandIndex(label);
    double worst = 0;
    for (int i = 0; i < data.size(); ++i) {
      const int c = data.command[i];
      if (!lib.HasCommand(c)) continue;
      const Eigen::VectorXd x = data.x.row(i).transpose();
      const double a = lib.LogLikelihood(c, x), b = rt.LogDensity(index.at(c), x);
      worst = std::max(worst, std::abs(a - b) / std::max(1.0, std::abs(a)));
      if (lib.terrain_dim > 0) {
        const Eigen::VectorXd z = data.z.row(i).transpose();
        const double ac = lib.LogLikelihood(c, x, z), bc = rt.LogDensity(index.at(c), x, z);
        worst = std::max(worst, std::abs(ac - bc) / std::max(1.0, std::abs(ac)));
      }
    }
    EXPECT_LE(worst, 1e-9) << set << " " << fit_args;
  }
  fs::path dir_;
};

TEST_F(RuntimeTest, AgreesWithTheLibraryOnEveryShippedSet) {
  const fs::path root = fs::path(DGMM_SOURCE_DIR) / "datasets";
  int sets = 0;
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (entry.path().extension() != ".h5") continue;
    ExpectAgreement(entry.path(), "fit --k 0.7 --seed 1");
    ++sets;
  }
  EXPECT_GE(sets, 10);
  ExpectAgreement(root / "scorpion_sim_390.h5", "em --components 2 --n-init 2 --seed 1");
  ExpectAgreement(root / "scorpion_sim_390.h5", "fit --k 0.7 --seed 1 --without-terrain");
}

TEST_F(RuntimeTest, AgreesOnAStandardisedSetAndMapsRawUnits) {
  const fs::path set = dir_ / "faithful.h5";
  Dgmm("import " + (fs::path(DGMM_SOURCE_DIR) / "datasets/old_faithful.csv").string() + " -o " + set.string() +
       " --pose-cols eruptions,waiting --standardize");
  ExpectAgreement(set, "fit --k 0.7 --seed 1");
  const fs::path model = dir_ / "model.h5", json = dir_ / "model.json";
  Dgmm("export " + model.string() + " -o " + json.string());
  const auto rt = dgmm_runtime::Model::FromJson(Read(json));
  const SampleSet data = ReadSampleSet(set.string());
  const Eigen::VectorXd raw = data.transform.offset + data.transform.scale.cwiseProduct(data.x.row(0).transpose());
  EXPECT_LT((rt.ToModelUnits(raw) - data.x.row(0).transpose()).norm(), 1e-12);
}

TEST_F(RuntimeTest, ConditionalSamplesFollowTheConditionalMixture) {
  const fs::path set = fs::path(DGMM_SOURCE_DIR) / "datasets/scorpion_sim_390.h5";
  const fs::path model = dir_ / "model.h5", json = dir_ / "model.json";
  Dgmm("fit " + set.string() + " -o " + model.string() + " --k 0.7 --seed 1");
  Dgmm("export " + model.string() + " -o " + json.string());
  const auto rt = dgmm_runtime::Model::FromJson(Read(json));
  const Eigen::Vector2d z(0.2, -0.1);
  const dgmm_runtime::Mixture cond = rt.Conditional(0, z);
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(rt.pose_dim());
  for (int i = 0; i < cond.size(); ++i) mean += cond.weight(i) * cond.component(i).mean();
  std::mt19937_64 rng(3);
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(rt.pose_dim());
  const int n = 20000;
  for (int s = 0; s < n; ++s) sum += cond.Sample(rng);
  EXPECT_LT((sum / n - mean).norm(), 0.05 * (1 + mean.norm()));
  EXPECT_THROW(rt.Conditional(0, Eigen::Vector3d::Zero()), std::runtime_error);
  EXPECT_THROW(rt.CommandIndex("no such command"), std::runtime_error);
  EXPECT_THROW(dgmm_runtime::Model::FromJson("{\"dgmm_format\": \"sample_set\"}"), std::runtime_error);
}

}  // namespace
}  // namespace dgmm
