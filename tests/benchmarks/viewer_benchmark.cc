// `dgmm view` slider redraw: one terrain slider moved on an 8-D model with 26 commands (a DGMM
// learnt from datasets/scorpion_sim_830.h5, k = 10, S0 scale 1, nu0 = 4:
// the settings `dgmm tune` chose for it in docs/reproduction.md, seed 1; or the model in $DGMM_VIEW_MODEL).
// BM_SliderRedraw is what a slider move costs in the window: conditioning (eqs. 15-19), the
// 200 x 200 density grid, the contours, the VTK chart and the render. BM_SliderRecompute is the
// VTK-free part alone. Needs an X display: run by scripts/bench_viewer.sh under
// scripts/with-display.sh.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <memory>

#include "core/motion_model.h"
#include "io/model_io.h"
#include "io/sample_set_io.h"
#include "render/display.h"
#include "render/viewer.h"

namespace dgmm {
namespace {

const MotionModel& Model() {
  static const MotionModel model = [] {
    if (const char* path = std::getenv("DGMM_VIEW_MODEL")) return ReadModel(path);
    MotionModelOptions options;
    options.dgmm.k = 10;  // Table I's tuned settings for this set, with terrain
    options.dgmm.initial_covariance_fraction = 1;
    options.dgmm.prior_pseudo_count = 4;
    options.seed = 1;
    return LearnMotionModel(ReadSampleSet(DGMM_SOURCE_DIR "/datasets/scorpion_sim_830.h5"),
                            options);
  }();
  return model;
}

ExplorerInputs Inputs(bool compare) {
  ExplorerInputs in;
  in.model = Model();
  in.model_file = "scorpion_sim_830-dgmm.h5";
  if (compare) {
    in.compare = Model();
    in.compare_file = "copy.h5";
  }
  return in;
}

void Describe(benchmark::State& state, const SliceExplorer& explorer) {
  const MotionModel& m = Model();
  state.counters["dims"] = m.dim();
  state.counters["commands"] = static_cast<double>(m.mixtures.size());
  state.counters["components"] = explorer.slices().front().mixture.size();  // first command
}

// Alternates slider 0 between 25% and 75% of its span (every iteration is a real change).
double SliderValue(const TerrainSlider& s, long long i) {
  return s.min + (i % 2 == 0 ? 0.25 : 0.75) * (s.max - s.min);
}

void BM_SliderRedraw(benchmark::State& state) {
  if (DisplayProblem()) {
    state.SkipWithError("no X display (run under scripts/with-display.sh)");
    return;
  }
  const bool compare = state.range(0) == 1;
  ExplorerOptions options;
  if (compare) {
    options.figure.width = 560;
    options.figure.height = 448;
  }
  std::unique_ptr<Viewer> owned;
  try {
    owned = std::make_unique<Viewer>(SliceExplorer(Inputs(compare), options), ViewerOptions{});
  } catch (const std::exception& e) {  // e.g. the display went away
    state.SkipWithError(e.what());
    return;
  }
  Viewer& viewer = *owned;
  if (viewer.explorer().terrain().empty()) {
    state.SkipWithError("the model has no terrain dimension");
    return;
  }
  const TerrainSlider slider = viewer.explorer().terrain()[0];
  long long i = 0;
  for (auto _ : state) viewer.MoveSlider(0, SliderValue(slider, i++));
  Describe(state, viewer.explorer());
}
BENCHMARK(BM_SliderRedraw)->ArgName("compare")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_SliderRecompute(benchmark::State& state) {
  SliceExplorer explorer(Inputs(false), {});
  if (explorer.terrain().empty()) {
    state.SkipWithError("the model has no terrain dimension");
    return;
  }
  const TerrainSlider slider = explorer.terrain()[0];
  long long i = 0;
  for (auto _ : state) {
    explorer.SetTerrain(0, SliderValue(slider, i++));
    benchmark::DoNotOptimize(explorer.Panels());
  }
  Describe(state, explorer);
}
BENCHMARK(BM_SliderRecompute)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace dgmm

BENCHMARK_MAIN();
