#pragma once
// Stage 8a of the analysis (analysis.h), before the runoff: on a height field, the ground's own
// shape (docs/sim2real.md, "The ground's own knobs"). Standing where it was placed, the robot tilts
// with the ground under its feet, and a rougher ground tilts it more variously; the models of x
// given z never compare z itself. The spread of the standing tilt, over the first execution of
// each placement,
//   s = mean_i |t_i - median_j t_j|,
// t_i the radial part of z on the slope's circle (SlopeGeometry, fitted to the sim set) or, where z
// traces no circle (level ground), the distance of z_i from the set's median z, compares the real
// set with the sim set by the ratio q = s_real / s_sim, its standard error from resampling
// placements (seeded). A ratio that moved by z SE is a located mismatch. Then every ground knob
// (family "ground": the terrain's roughness, stone and step heights) is recorded at the analysis's
// places at `up` (or `down`) factors of its nominal, each recording's spread relative to the
// nominal re-recording's at the same places (paired); the value whose ratio meets q is read between
// the recordings (linear), recorded, and named when its ratio matches q within match_z SE and its
// recording, scored by a model of its own (leg_search.h, SearchOwnModels), fits the real samples
// better than the nominal by the search's z SE with no other ground knob as well. A ground knob
// whose range cannot give q, or whose recording does not move the motion's fit, is said, not named.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "sim2real/leg_search.h"
#include "sim2real/posture.h"

namespace dgmm::sim2real {

struct GroundSearchOptions {
  bool enabled = true;   // `dgmm sim2real --no-ground-search` turns it off
  // Standard errors the ratio of the standing spreads must move from 1. On the octopod's rough
  // ground two null pairs moved 0.2 and 0.5 SE, a weak leg and 1.5 times higher boulders 1.0
  // (docs/sim2real.md).
  double z = 3.0;
  double match_z = 2.0;  // a ground knob's recording at the value read must meet q within this many SE
  // Of the knobs that meet q, only those whose recording's standing tilts have the real ones' shape
  // as well as the best (within shape_z SE of its log density) are scored by the motion: on the
  // octopod's rough ground a rougher ground and higher boulders spread the tilt alike at some value
  // each and fit the real motion alike, but the boulders tilt a few placements far (a heavy tail).
  double shape_z = 2.0;
  std::vector<double> up = {1.5, 2.0, 3.0};  // factors of a ground knob's nominal, the real spread larger
  std::vector<double> down = {0.5, 0.2};     // ... smaller
  int resamples = 200;   // placement resamples for the standard errors
  std::uint64_t seed = 1;
  LegSearchOptions search;  // the scoring and naming rules (factors unused)
  GroundSearchOptions() { search.refine_steps = 0; }
  bool IsValid(std::string* error) const;
};

// The spread s of a set's standing tilt (rad) and its SE over `placements` placements.
struct StandingSpread {
  double value = NAN, se = NAN;
  int placements = 0;
};

// s of `set` (columns pitch_col, roll_col of z) about the circle `slope` (nullptr: about the
// set's median z), with its SE from `resamples` placement resamples.
StandingSpread MeasureStandingSpread(const SampleSet& set, int pitch_col, int roll_col, const SlopeGeometry* slope,
                                     int resamples, std::uint64_t seed);

// One ground knob's recordings: the ratio of each recording's spread to the nominal re-recording's
// at the same places, by the knob's value (ascending, the nominal's ratio 1 among them).
struct GroundCurve {
  std::string knob;
  int knob_index = -1;
  std::vector<double> values, ratios;
  double matched = NAN;      // where the ratios meet q (NaN: not within the recorded values)
  double matched_ratio = NAN, matched_se = NAN;  // its recording's ratio, its paired SE
  double match_z = NAN;      // |matched_ratio - q| / SE
  bool meets = false;        // match_z <= options.match_z
  std::vector<double> matched_tilts;  // its recording's standing t, one per placement
  // The real standing tilts' mean log density under its recording's (TiltLogDensity), and how far
  // below the best meeting knob's that is (z over the real placements; 0 for the best).
  double tilt_score = NAN, tilt_z = NAN;
  bool tilt_as_well = false;  // within shape_z SE of the best: scored by the search
};

struct GroundSearch {
  bool ran = false;          // the standing spreads were compared
  std::string why;           // why not, or what the search found, in words
  bool on_slope = false;     // t is z's radial part on the slope's circle (clear, or a sloped_ground())
  StandingSpread real, sim;
  double ratio = NAN, ratio_se = NAN;  // q and its SE
  double z_moved = 0;        // (q - 1) / SE
  bool moved = false;        // |z_moved| >= options.z
  std::vector<GroundCurve> curves;  // every ground knob's, when moved
  LegSearch search;          // the values that meet q, scored by models of their own ("ground_search")
  int recorded = 0, from_cache = 0;
  double seconds = 0;
};

// Per real placement, log p(t_i) under a Gaussian kernel density of the reference tilts (Silverman's
// bandwidth), each set centred on its median: the shape of the spread, not its centre.
Eigen::VectorXd TiltLogDensity(const std::vector<double>& real, const std::vector<double>& reference);

// The simulator's ground knobs (family "ground", a shift role).
std::vector<int> GroundKnobs(const KnobSimulator& simulator);

// The comparison, and the search when the spread moved. Does not run (why) without ground knobs, on
// a plane, without pitch and roll, or with under 10 placements in either set.
GroundSearch SearchGround(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateSet& set,
                          const CandidateOptions& recording, const GroundSearchOptions& options);

// The search in the verdict: a named ground knob replaces the verdict's names (status
// partly_explained, the doubts of a search without bootstrap); a spread that moved with nothing
// named is a doubt (clean becomes unexplained, explained partly_explained) and a sentence.
void AddGroundSearch(const KnobSimulator& simulator, const GroundSearch& ground, Verdict* verdict);

}  // namespace dgmm::sim2real
