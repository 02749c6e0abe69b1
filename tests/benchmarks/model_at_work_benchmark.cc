// The model at work (issue #26): conditioned log-density evaluations and Monte Carlo prediction,
// on a DGMM fitted to the shipped 830-sample set (d = 8: x in R^6, terrain (pitch, roll)).
//   BM_ConditionedLogDensity: log p(x | c, z) for a batch of 10^4 x at one (c, z): items/s =
//     evaluations per second (the conditional formed once per batch, as a planner would).
//   BM_ConditionAndEvaluate: the same with the conditional formed for every x (z changes).
//   BM_Predict: 10^4 trajectories x 20 commands (issue target: under 1 s on one core).
// Run: build/tests/benchmarks/model_at_work_benchmark --benchmark_repetitions=3 (medians).
#include <benchmark/benchmark.h>

#include <random>

#include "core/motion_model.h"
#include "io/sample_set_io.h"
#include "predict/predict.h"

namespace dgmm {
namespace {

const MotionModel& Model() {
  static const MotionModel model = [] {
    const SampleSet set = ReadSampleSet(std::string(DGMM_SOURCE_DIR) + "/datasets/scorpion_sim_830.h5");
    MotionModelOptions options;
    options.seed = 1;
    return LearnMotionModel(set, options);
  }();
  return model;
}

int ForwardCommand() {
  for (const auto& [id, label] : Model().command_labels) {
    if (label == "+0.5,0,0") return id;
  }
  return Model().mixtures.begin()->first;
}

Eigen::MatrixXd Points(int n) {
  std::mt19937_64 rng(3);
  return Model().Conditional(ForwardCommand(), Eigen::Vector2d(0.1, 0.0)).Sample(n, rng);
}

void BM_ConditionedLogDensity(benchmark::State& state) {
  const Eigen::MatrixXd x = Points(10000);
  for (auto _ : state) {
    const Mixture c = Model().Conditional(ForwardCommand(), Eigen::Vector2d(0.1, 0.0));
    benchmark::DoNotOptimize(c.LogDensity(x).sum());
  }
  state.SetItemsProcessed(state.iterations() * x.cols());
  state.counters["components"] = Model().MixtureFor(ForwardCommand()).size();
}
BENCHMARK(BM_ConditionedLogDensity)->Unit(benchmark::kMillisecond);

void BM_ConditionAndEvaluate(benchmark::State& state) {
  const Eigen::MatrixXd x = Points(1000);
  for (auto _ : state) {
    double sum = 0;
    for (int i = 0; i < x.cols(); ++i) {
      sum += Model().LogLikelihood(ForwardCommand(), x.col(i), Eigen::Vector2d(0.1, 0.001 * i));
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * x.cols());
}
BENCHMARK(BM_ConditionAndEvaluate)->Unit(benchmark::kMillisecond);

void BM_Predict(benchmark::State& state) {
  const std::vector<predict::Step> steps(20, predict::Step{ForwardCommand(), Eigen::Vector2d(0.1, 0.0)});
  predict::PredictOptions options;
  options.trajectories = 10000;
  for (auto _ : state) {
    const predict::Prediction p = predict::Predict(Model(), Eigen::Vector3d::Zero(), steps, options);
    benchmark::DoNotOptimize(p.steps.back().mean[0]);
  }
  state.SetItemsProcessed(state.iterations() * options.trajectories * steps.size());
}
BENCHMARK(BM_Predict)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace dgmm

BENCHMARK_MAIN();
