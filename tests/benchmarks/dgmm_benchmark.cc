// ADDSAMPLE throughput (Algorithm 2, faithful variant, default options but S0 = I): a stream of
// 10^6 samples drawn from a three-component mixture in d = 2, 6, 8 dimensions, k = 0.7. Items/second = samples/second of
// one Dgmm on one core. Run by scripts/bench_dgmm.sh, which records medians in
// docs/performance.md.
#include <benchmark/benchmark.h>

#include <map>
#include <random>

#include "core/dgmm.h"
#include "core/mixture.h"

namespace dgmm {
namespace {

constexpr int kStreamLength = 1000000;

// The source: three components with means 3 apart along different axes, weights 1:2:3,
// isotropic covariances 0.5, 0.75, 1.0; drawn once per dimension with seed 42.
const Eigen::MatrixXd& Stream(int d) {
  static std::map<int, Eigen::MatrixXd> cache;
  auto it = cache.find(d);
  if (it != cache.end()) return it->second;
  Mixture source(d);
  for (int i = 0; i < 3; ++i) {
    Eigen::VectorXd mean = Eigen::VectorXd::Zero(d);
    mean[i % d] = 3.0;
    source.Add(1.0 + i, Gaussian(mean, Eigen::MatrixXd::Identity(d, d) * (0.5 + 0.25 * i)));
  }
  std::mt19937_64 rng(42);
  return cache.emplace(d, source.Sample(kStreamLength, rng)).first->second;
}

void BM_AddSample(benchmark::State& state) {
  const int d = static_cast<int>(state.range(0));
  const auto seed = static_cast<std::uint64_t>(state.range(1));
  const Eigen::MatrixXd& stream = Stream(d);
  DgmmOptions options;
  options.k = 0.7;
  options.initial_covariance_rule = DgmmOptions::InitialCovarianceRule::kIdentity;  // N(0, I)-scale
  int components = 0;
  for (auto _ : state) {
    Dgmm model(d, options);
    std::mt19937_64 rng(seed);
    for (int j = 0; j < kStreamLength; ++j) model.AddSample(stream.col(j), rng);
    components = model.mixture().size();
    benchmark::DoNotOptimize(model.mixture().weight(0));
  }
  state.SetItemsProcessed(state.iterations() * kStreamLength);
  state.counters["components"] = components;
}
// {d, seed of the model's generator}: the faithful algorithm's early random merges decide how
// many of the three source components the model keeps, and the cost per sample grows with that
// count, so each d runs with three seeds and the table reports the components of each.
BENCHMARK(BM_AddSample)
    ->ArgsProduct({{2, 6, 8}, {1, 2, 3}})
    ->ArgNames({"d", "seed"})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace dgmm

BENCHMARK_MAIN();
