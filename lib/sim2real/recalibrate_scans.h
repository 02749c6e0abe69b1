#pragma once
// The three simulator-parameter scans of the recalibration (recalibrate.h). Each evaluates a
// handful of configs derived from the scorer's nominal one, returns its JSON record
// {"effect", "parameter", "nominal", "candidates", "best", "improvement_nats_per_sample", ...}
// and, when the best candidate beats the nominal config, writes its value into *recalibrated.
#include <nlohmann/json.hpp>

#include "sim/sim_config.h"
#include "sim2real/recalibrate_scorer.h"

namespace dgmm::sim2real {

// friction.sliding at {1, 0.85, 0.7, 0.55} x nominal, then at the vertex of the parabola
// through the best value and its neighbours (or one step beyond an end of the grid).
nlohmann::json ScanFriction(ResimScorer& scorer, sim::SimConfig* recalibrated);

// Payload: probes of mass m0 = 15% of the robot at the centre, +r0 forward and +r0 left
// (r0 = 0.1 m) give shifts theta_c, theta_x, theta_y; with the local linear response
//   theta(m, a, b) = (m/m0) theta_c + (m a / (m0 r0)) (theta_x - theta_c) + (m b / (m0 r0)) (theta_y - theta_c)
// the real data's best (m, a, b) is a weighted least-squares solve, then simulated with its
// moment x {0.7, 1, 1.4}. The moment m (a, b) is what the data identify; mass and offset trade.
nlohmann::json ScanPayload(ResimScorer& scorer, sim::SimConfig* recalibrated);

// Per-leg gain: each leg at 0.5 x nominal gain (8 probes), the best leg then at 0.25 and 0.75
// and at the vertex of the parabola through the best three gains (1.0 = nominal included).
nlohmann::json ScanLegGain(ResimScorer& scorer, sim::SimConfig* recalibrated);

}  // namespace dgmm::sim2real
