#pragma once
// The simulator-in-the-loop analysis (--sim-config; docs/sim2real.md, "Knobs"): candidate
// effects are the simulator's own knobs (lib/sim/knobs.h) with signatures simulated on the sim
// set's protocol and seed (signatures.h), plus measurement effects no simulator models
// (imu_bias: z offset through the sim model's slopes; tracker_bias; heading_drift; tracker_noise).
// Forward selection by held-out real likelihood (selection.h), ties from the signatures'
// correlation on the observed samples with a discriminating experiment, the most important knobs
// refined by re-simulation (each followed by a new selection), the residual tested for structure,
// and the verdict.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/sample_set.h"
#include "sim/sim_config.h"
#include "sim2real/drift.h"
#include "sim2real/experiment_check.h"
#include "sim2real/pipeline.h"
#include "sim2real/residual_structure.h"
#include "sim2real/signatures.h"
#include "sim2real/spread.h"
#include "sim2real/verdict.h"

namespace dgmm::sim2real {

struct KnobAnalysisOptions {
  std::uint64_t seed = 1;
  SignatureOptions signatures;
  SelectionOptions selection;      // bootstrap_selection 0: inclusion not computed
  ResidualStructureOptions residual;
  DriftOptions drift;              // is each named effect constant over the session?
  SpreadOptions spread;            // is a wider spread the tracker's or the named knobs'?
  double tie_correlation = 0.9;    // |corr| of whitened signatures on the real samples
  int refine_iterations = 3;       // re-simulations per refined knob (0: no refinement)
  int refine_knobs = 2;            // knobs refined at most (most important first), each followed by a new selection
  ExperimentCheckOptions experiment;  // the check by simulation of each tie's proposed experiment
  int max_experiment_checks = 3;      // ties checked at most (the rest say so)
  bool IsValid(std::string* error) const;
};

struct KnobCandidate {
  std::string key;      // e.g. "floor.friction.sliding@0.6"
  std::string family;
  std::string knob;     // knob name ("payload" for the payload effect)
  std::string unit;
  double nominal = 0, probe = 0, lo = 0, hi = 0;  // probe: the simulated value (1 param effects)
  bool physical = false;
  double theta = 0;     // fitted (first parameter) when selected
};

struct KnobAnalysis {
  Verdict verdict;
  std::vector<KnobCandidate> candidates;  // library order of `steps`
  std::vector<SelectionStep> steps;
  std::vector<int> selected;              // candidate indices, by importance
  ResidualStructure residual;
  struct DriftTest {
    int candidate = -1;   // index into candidates
    EffectDrift drift;           // over the session
    EffectDrift step_variation;  // with the execution index
  };
  std::vector<DriftTest> drift_tests;     // per selected mean-shift effect
  EffectDrift total_drift;                // of the sum of their shifts (the whole correction)
  EffectDrift total_step_variation;
  SpreadTest spread;                      // run when the noise scale was selected and a tracker knob exists
  double tracker_scale = NAN;             // the tracker-noise scale refined by re-simulation (NaN: not needed)
  int simulations = 0, from_cache = 0, placements = 0;
  // Of those, the signature stage's (nominal + probes): 0 simulated = "signatures cached".
  int signature_simulations = 0, signature_requests = 0;
  double signature_seconds = 0, refine_seconds = 0, seconds = 0;
  int experiment_checks = 0;        // ties whose experiment was simulated (2 cell runs each)
  double experiment_seconds = 0;    // wall time of those checks
  std::string cache_dir;
  std::vector<int> removed;               // candidate indices dropped by the selection's backward pass
  std::vector<std::string> inert_knobs;   // knobs whose probe changed nothing in simulation (not candidates)
  struct RefineStep {
    std::string knob;
    double value = 0, coefficient = 0;  // value simulated, fitted coefficient of its signature
  };
  std::vector<RefineStep> refine_trace;
  double ll_sim = 0, ll_corrected = 0, ll_ceiling = 0;
  std::string note;
};

// Candidates of `step` (indices into fp.library, `family` per library entry) the data cannot
// tell apart from `chosen`: of another family, and either flagged by the selection (gain within
// one SE of the paired difference, correlated fitted shifts) or with a held-out gain within two
// SE of the best and whitened fitted shifts (each effect fitted alone on all samples) at
// |cosine| >= tie_correlation. `correlation` (optional) gets the |cosine| of each.
std::vector<int> TiedCandidates(const FitProblem& fp, const SelectionStep& step, int chosen,
                                const std::vector<std::string>& family, double tie_correlation,
                                const EffectFitOptions& fit, std::vector<double>* correlation = nullptr);

// Throws InputError when the sim set lacks what the signatures need (command table, episodes).
KnobAnalysis AnalyseKnobs(const SampleSet& sim_set, const SampleSet& real_set, const sim::SimConfig& config,
                          const Sim2RealResult& base, const KnobAnalysisOptions& options);

// JSON text of the analysis details (candidates, steps, refinement, residual tests, timing).
std::string KnobAnalysisJson(const KnobAnalysis& a);

}  // namespace dgmm::sim2real
