#include "tests/io/io_test_util.h"

#include <unistd.h>

#include <cstring>
#include <fstream>

namespace dgmm::test {
namespace {

double AwkwardDouble(std::mt19937_64& rng) {
  std::uniform_int_distribution<int> pick(0, 9);
  std::normal_distribution<double> normal(0.0, 1.0);
  switch (pick(rng)) {
    case 0:
      return -0.0;
    case 1:
      return 4.9e-324 * (1 + pick(rng));  // subnormal
    case 2:
      return 1.7976931348623157e308 / (1 + pick(rng));
    case 3:
      return normal(rng) * 1e-300;
    default:
      return normal(rng) * 3.0 + 1.0 / 3.0;  // all 53 bits in use
  }
}

Eigen::MatrixXd RandomMatrix(int rows, int cols, std::mt19937_64& rng) {
  Eigen::MatrixXd m(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) m(r, c) = AwkwardDouble(rng);
  }
  return m;
}

std::vector<std::string> Names(const std::string& prefix, int n) {
  std::vector<std::string> v;
  for (int i = 0; i < n; ++i) v.push_back(prefix + std::to_string(i) + " (ü)");
  return v;
}

// Removes this process's test folders after the last test.
class CleanTestDirs : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(std::filesystem::temp_directory_path() /
                                    ("dgmm-io-test-" + std::to_string(::getpid())),
                                ec);
  }
};
[[maybe_unused]] ::testing::Environment* const kCleanTestDirs =
    ::testing::AddGlobalTestEnvironment(new CleanTestDirs);

}  // namespace

SampleSet RandomSet(const RandomSetShape& shape, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  SampleSet s;
  s.command_dim_names = Names("c", shape.command_dims);
  s.commands = RandomMatrix(shape.commands, shape.command_dims, rng);
  for (int c = 0; c < shape.commands; ++c) s.command_labels.push_back("cmd " + std::to_string(c));
  std::uniform_int_distribution<int> command(0, shape.commands - 1);
  s.command.resize(shape.n);
  for (int i = 0; i < shape.n; ++i) s.command[i] = command(rng);
  s.x = RandomMatrix(shape.n, shape.dx, rng);
  s.x_names = Names("x", shape.dx);
  s.x_units = std::vector<std::string>(shape.dx, "m");
  if (shape.dz > 0) {
    s.z = RandomMatrix(shape.n, shape.dz, rng);
    s.z_names = Names("z", shape.dz);
    s.z_units = std::vector<std::string>(shape.dz, "rad");
  }
  if (shape.episodes) {
    s.episode.resize(shape.n);
    s.step.resize(shape.n);
    for (int i = 0; i < shape.n; ++i) {
      s.episode[i] = i / 7;
      s.step[i] = i % 7;
    }
  }
  s.source = "sim";
  s.metadata = {{"robot", "scorpion"}, {"note", "a, b; \"quoted\""}};
  if (shape.transform) {
    const int d = shape.dx + shape.dz;
    s.transform.offset = RandomMatrix(d, 1, rng);
    s.transform.scale = RandomMatrix(d, 1, rng).cwiseAbs().array() + 0.5;
  }
  return s;
}

MotionModel RandomModel(int pose_dim, int terrain_dim, int commands, std::uint64_t seed,
                        bool transform) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  MotionModel m;
  m.kind = "dgmm";
  m.pose_dim = pose_dim;
  m.terrain_dim = terrain_dim;
  m.pose_names = Names("x", pose_dim);
  m.pose_units = std::vector<std::string>(pose_dim, "m");
  m.terrain_names = Names("z", terrain_dim);
  m.command_dim_names = {"forward", "turn"};
  const int d = pose_dim + terrain_dim;
  for (int c = 0; c < commands; ++c) {
    m.command_values[c] = Eigen::Vector2d(normal(rng), c);
    m.command_labels[c] = "command " + std::to_string(c);
    if (c == commands - 1 && commands > 1) continue;  // a command without samples
    Mixture mixture(d);
    for (int k = 0; k <= c + 1; ++k) {
      Eigen::MatrixXd a = Eigen::MatrixXd::NullaryExpr(d, d, [&] { return normal(rng); });
      Eigen::MatrixXd cov = a * a.transpose() + 0.1 * Eigen::MatrixXd::Identity(d, d);
      Eigen::VectorXd mean = Eigen::VectorXd::NullaryExpr(d, [&] { return normal(rng); });
      mixture.Add(1.0 + k * 3.0 + normal(rng) * 1e-3 + 1.0 / 3.0, Gaussian(mean, cov));
    }
    m.mixtures[c] = mixture;
  }
  m.dgmm_options.k = 0.3 + 1.0 / 7.0;
  m.dgmm_options.variant = DgmmOptions::Variant::kImproved;
  m.dgmm_options.covariance_floor = 1e-7 / 3.0;
  m.dgmm_options.initial_covariance_diagonal = Eigen::VectorXd::Constant(d, 0.25);
  m.dgmm_options.initial_covariance_rule = DgmmOptions::InitialCovarianceRule::kData;
  m.dgmm_options.initial_covariance_fraction = 0.7;
  m.dgmm_options.covariance_rule = DgmmOptions::CovarianceRule::kPrior;
  m.dgmm_options.prior_pseudo_count = 2.5;
  m.dgmm_options.covariance_floor_relative = 3e-6;
  m.seed = 0xFEDCBA9876543210ULL;
  if (transform) {
    m.transform.offset = Eigen::VectorXd::NullaryExpr(d, [&] { return normal(rng); });
    m.transform.scale =
        Eigen::VectorXd::NullaryExpr(d, [&] { return 0.5 + std::abs(normal(rng)); });
  }
  m.metadata = {{"training_source", "sim"}, {"em", "{\"components\": 2}"}};
  return m;
}

bool SameBits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  return a.size() == 0 || std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0;
}

void ExpectSameSet(const SampleSet& a, const SampleSet& b) {
  EXPECT_EQ(a.command_dim_names, b.command_dim_names);
  EXPECT_TRUE(SameBits(a.commands, b.commands));
  EXPECT_EQ(a.command_labels, b.command_labels);
  EXPECT_EQ(a.command, b.command);
  EXPECT_TRUE(SameBits(a.x, b.x));
  EXPECT_EQ(a.x_names, b.x_names);
  EXPECT_EQ(a.x_units, b.x_units);
  EXPECT_EQ(a.terrain_dim(), b.terrain_dim());
  if (a.terrain_dim() > 0) EXPECT_TRUE(SameBits(a.z, b.z));
  EXPECT_EQ(a.z_names, b.z_names);
  EXPECT_EQ(a.z_units, b.z_units);
  EXPECT_EQ(a.episode, b.episode);
  EXPECT_EQ(a.step, b.step);
  EXPECT_EQ(a.source, b.source);
  EXPECT_EQ(a.metadata, b.metadata);
  EXPECT_TRUE(SameBits(a.transform.offset, b.transform.offset));
  EXPECT_TRUE(SameBits(a.transform.scale, b.transform.scale));
}

void ExpectSameModel(const MotionModel& a, const MotionModel& b) {
  EXPECT_EQ(a.kind, b.kind);
  EXPECT_EQ(a.pose_dim, b.pose_dim);
  EXPECT_EQ(a.terrain_dim, b.terrain_dim);
  EXPECT_EQ(a.pose_names, b.pose_names);
  EXPECT_EQ(a.pose_units, b.pose_units);
  EXPECT_EQ(a.terrain_names, b.terrain_names);
  EXPECT_EQ(a.command_dim_names, b.command_dim_names);
  ASSERT_EQ(a.command_values.size(), b.command_values.size());
  for (const auto& [id, v] : a.command_values) {
    ASSERT_TRUE(b.command_values.count(id));
    EXPECT_TRUE(SameBits(v, b.command_values.at(id)));
  }
  EXPECT_EQ(a.command_labels, b.command_labels);
  ASSERT_EQ(a.mixtures.size(), b.mixtures.size());
  for (const auto& [id, ma] : a.mixtures) {
    ASSERT_TRUE(b.mixtures.count(id)) << id;
    const Mixture& mb = b.mixtures.at(id);
    ASSERT_EQ(ma.size(), mb.size());
    EXPECT_EQ(ma.dim(), mb.dim());
    for (int k = 0; k < ma.size(); ++k) {
      EXPECT_EQ(std::memcmp(&ma.weights()[k], &mb.weights()[k], sizeof(double)), 0);
      EXPECT_TRUE(SameBits(ma.component(k).mean(), mb.component(k).mean()));
      EXPECT_TRUE(SameBits(ma.component(k).covariance(), mb.component(k).covariance()));
    }
  }
  EXPECT_EQ(a.dgmm_options.variant, b.dgmm_options.variant);
  EXPECT_EQ(a.dgmm_options.k, b.dgmm_options.k);
  EXPECT_EQ(a.dgmm_options.covariance_floor, b.dgmm_options.covariance_floor);
  EXPECT_EQ(a.dgmm_options.covariance_floor_relative, b.dgmm_options.covariance_floor_relative);
  EXPECT_EQ(a.dgmm_options.covariance_rule, b.dgmm_options.covariance_rule);
  EXPECT_EQ(a.dgmm_options.prior_pseudo_count, b.dgmm_options.prior_pseudo_count);
  EXPECT_EQ(a.dgmm_options.initial_covariance_rule, b.dgmm_options.initial_covariance_rule);
  EXPECT_EQ(a.dgmm_options.initial_covariance_fraction,
            b.dgmm_options.initial_covariance_fraction);
  EXPECT_TRUE(SameBits(a.dgmm_options.initial_covariance_diagonal,
                       b.dgmm_options.initial_covariance_diagonal));
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_TRUE(SameBits(a.transform.offset, b.transform.offset));
  EXPECT_TRUE(SameBits(a.transform.scale, b.transform.scale));
  EXPECT_EQ(a.metadata, b.metadata);
}

std::filesystem::path TestDir() {
  namespace fs = std::filesystem;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  fs::path dir = fs::temp_directory_path() / ("dgmm-io-test-" + std::to_string(::getpid())) /
                 (std::string(info->test_suite_name()) + "." + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

int CountTempFiles(const std::filesystem::path& dir) {
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    n += e.path().filename().string().find(".tmp-") != std::string::npos;
  }
  return n;
}

void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

}  // namespace dgmm::test
