#pragma once
// The null shortfall recorded by the simulator (ceiling.h has the parametric one): the nominal
// re-recorded `draws` times with the real set's design (its placements, executions per placement
// and commands) at seeds of its own. Each re-recording is a real set where the physics agree, so
//   null = mean over d of [ceiling(R_d) - sim model(R_d)],  R_d the d-th re-recording,
// with the real set's folds by placement and the sim model fitted once on the sim set. It needs no
// model of how samples spread: where the linear Gaussian is a poor description of the recordings
// (uneven ground, where the parametric draws put the null at 0.12-0.14 nats per real sample and
// null pairs measured 0.18-0.90, docs/sim2real.md), the recorded null is what a null pair gives.
#include <cstdint>

#include "sim2real/baseline.h"
#include "sim2real/ceiling.h"
#include "sim2real/inputs.h"
#include "sim2real/knob_simulator.h"
#include "sim2real/simulation_cache.h"

namespace dgmm::sim2real {

enum class NullSource { kAuto, kDrawn, kRecorded };

struct RecordedNullOptions {
  int draws = 3;             // re-recordings of the nominal (>= 2: the spread needs two)
  std::uint64_t seed = 1;    // the re-recordings' seeds are drawn from it
  int folds = 5;             // of the ceiling on each re-recording, by placement (the baseline's)
  LinearGaussianOptions model;
  RecordingOptions recording;
  bool IsValid(std::string* error) const;
};

// The recorded null. Its sd, the spread of one null pair's shortfall, is the re-recordings' SD but
// at least the root mean square of their own SEs clustered by placement (three draws can put
// their SD near 0 by chance); mean_se = sd / sqrt(draws).
// Throws InputError when the simulator cannot record the sim set's protocol.
NullShortfall RecordNullShortfall(const KnobSimulator& simulator, const AnalysisInputs& in, const Baseline& base,
                                  const RecordedNullOptions& options);

// The real set's design as a recording of the sim set's protocol at `seed` (moved on while it is the
// sim set's own or, when its metadata says, the real set's, so never their places): its number of
// placements and its executions per placement; without sequence data as many placements as
// samples, one execution each (the analysis then treats every sample as its own placement).
Recording RealDesign(const AnalysisInputs& in, std::uint64_t seed);

// A recording of RealDesign's samples with the real set's commands only (the sim set's command
// table), as the analysis's samples are.
Samples RealCommandsOf(const SampleSet& set, const AnalysisInputs& in);

}  // namespace dgmm::sim2real
