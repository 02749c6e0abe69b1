// EM reference speed: FitEm (k-means++ init, n_init restarts, E/M steps) single-threaded.
// scripts/bench_em.sh runs this side by side with scikit-learn on the same CSV files:
//   em_benchmark --em_case=NAME,PATH.csv,K [--em_case=...] [--em_n_init=10] [--em_max_iter=100]
//                [--em_tol=0] [--benchmark_* flags]
// Without --em_case it fits built-in seeded synthetic sets (d = 2, 6, 8; n = 5000).
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "em/em.h"
#include "em/kmeans.h"

namespace {

struct Case {
  std::string name;
  Eigen::MatrixXd X;
  int components = 2;
};

// Numeric CSV (one sample per line, comma-separated); a first line that is not numeric is a
// header and skipped.
Eigen::MatrixXd ReadCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    std::fprintf(stderr, "em_benchmark: cannot read %s\n", path.c_str());
    std::exit(2);
  }
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<double> row;
    std::stringstream ss(line);
    std::string cell;
    bool numeric = true;
    while (std::getline(ss, cell, ',')) {
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      if (end == cell.c_str()) numeric = false;
      row.push_back(v);
    }
    if (!numeric) {
      if (rows.empty()) continue;  // header
      std::fprintf(stderr, "em_benchmark: %s: non-numeric line '%s'\n", path.c_str(), line.c_str());
      std::exit(2);
    }
    rows.push_back(std::move(row));
  }
  if (rows.empty()) {
    std::fprintf(stderr, "em_benchmark: %s: no samples\n", path.c_str());
    std::exit(2);
  }
  Eigen::MatrixXd X(rows.size(), rows[0].size());
  for (size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() != rows[0].size()) {
      std::fprintf(stderr, "em_benchmark: %s: ragged line %zu\n", path.c_str(), i + 2);
      std::exit(2);
    }
    for (size_t j = 0; j < rows[i].size(); ++j) X(i, j) = rows[i][j];
  }
  return X;
}

// n samples from K unit-ish Gaussians with means 3 apart along a random direction per component.
Eigen::MatrixXd Synthetic(int n, int d, int K, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd means(K, d);
  for (Eigen::Index a = 0; a < means.size(); ++a) means.data()[a] = 3.0 * normal(rng);
  Eigen::MatrixXd X(n, d);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < d; ++j) X(i, j) = means(i % K, j) + normal(rng);
  return X;
}

bool TakeFlag(const std::string& arg, const std::string& name, std::string* value) {
  const std::string prefix = "--" + name + "=";
  if (arg.rfind(prefix, 0) != 0) return false;
  *value = arg.substr(prefix.size());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  std::vector<Case> cases;
  dgmm::EmOptions options;
  options.n_init = 10;
  options.max_iterations = 100;
  options.tolerance = 0;  // always max_iterations E/M steps per restart
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    std::string v;
    if (TakeFlag(arg, "em_case", &v)) {
      const size_t c1 = v.find(','), c2 = v.rfind(',');
      if (c1 == std::string::npos || c2 == c1) {
        std::fprintf(stderr, "em_benchmark: --em_case=NAME,PATH,K, got '%s'\n", v.c_str());
        return 2;
      }
      cases.push_back({v.substr(0, c1), ReadCsv(v.substr(c1 + 1, c2 - c1 - 1)),
                       std::atoi(v.c_str() + c2 + 1)});
    } else if (TakeFlag(arg, "em_n_init", &v)) {
      options.n_init = std::atoi(v.c_str());
    } else if (TakeFlag(arg, "em_max_iter", &v)) {
      options.max_iterations = std::atoi(v.c_str());
    } else if (TakeFlag(arg, "em_tol", &v)) {
      options.tolerance = std::atof(v.c_str());
    } else {
      std::fprintf(stderr, "em_benchmark: unknown argument '%s'\n", arg.c_str());
      return 2;
    }
  }
  std::string error;
  if (!options.IsValid(&error)) {
    std::fprintf(stderr, "em_benchmark: %s\n", error.c_str());
    return 2;
  }
  if (cases.empty()) {
    cases.push_back({"synthetic_d2", Synthetic(5000, 2, 3, 1), 3});
    cases.push_back({"synthetic_d6", Synthetic(5000, 6, 4, 2), 4});
    cases.push_back({"synthetic_d8", Synthetic(5000, 8, 3, 3), 3});
  }
  for (const Case& c : cases) {
    dgmm::EmOptions o = options;
    o.components = c.components;
    benchmark::RegisterBenchmark(("FitEm/" + c.name).c_str(), [c, o](benchmark::State& state) {
      dgmm::EmResult result;
      for (auto _ : state) {
        result = dgmm::FitEm(c.X, o);
        benchmark::DoNotOptimize(result.summary.log_likelihood);
      }
      state.counters["mean_log_likelihood"] = result.summary.mean_log_likelihood;
      state.counters["iterations"] = result.summary.iterations;
      state.counters["samples"] = static_cast<double>(c.X.rows());
      state.counters["dim"] = static_cast<double>(c.X.cols());
      state.counters["components"] = c.components;
    })->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("KMeans/" + c.name).c_str(), [c](benchmark::State& state) {
      dgmm::KMeansOptions k;
      k.clusters = c.components;
      std::mt19937_64 rng(1);
      for (auto _ : state) benchmark::DoNotOptimize(dgmm::FitKMeans(c.X, k, rng).inertia);
    })->Unit(benchmark::kMillisecond);
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
