#include "sim2real/recalibrate.h"

#include <chrono>
#include <exception>
#include <nlohmann/json.hpp>

#ifdef DGMM_SIM2REAL_HAVE_SIM
#include "sim/sim_config.h"
#include "sim2real/recalibrate_scans.h"
#include "sim2real/recalibrate_scorer.h"
#endif

namespace dgmm::sim2real {

bool RecalibrationOptions::IsValid(std::string* error) const {
  if (sim_config_path.empty() || placements < 5 || threads < 1 ||
      (verify_placements != 0 && verify_placements < 5)) {
    if (error) {
      *error = "a sim config path, >= 5 placements per re-simulation (and per check, or 0) and "
               ">= 1 thread are needed";
    }
    return false;
  }
  return true;
}

std::string Recalibrate(const Sim2RealResult& result, const SampleSet& real,
                        const RecalibrationOptions& options) {
  using json = nlohmann::json;
  json out;
  auto selected = [&](std::initializer_list<const char*> keys) {
    for (const auto& e : result.effects) {
      for (const char* k : keys) {
        if (e.spec.key == k) return true;
      }
    }
    return false;
  };
  const bool friction = selected({"slope_slip", "stride_loss", "slope_traction"});
  const bool payload = selected({"payload_offset"});
  const bool legs = selected({"actuator_asymmetry"});
  if (!friction && !payload && !legs) {
    out["skipped"] = "no selected effect has a simulator mapping (slip, stride loss, traction -> "
                     "friction; payload offset -> payload; actuator asymmetry -> leg gains)";
    return out.dump(2);
  }
#ifndef DGMM_SIM2REAL_HAVE_SIM
  out["skipped"] = "dgmm was built without the simulator";
  return out.dump(2);
#else
  std::string error;
  if (!options.IsValid(&error)) {
    out["skipped"] = error;
    return out.dump(2);
  }
  const auto start = std::chrono::steady_clock::now();
  try {
    const sim::SimConfig base = sim::LoadSimConfig(options.sim_config_path);
    std::vector<EffectSpec> effects;
    json projected = json::array();
    for (const auto& e : result.effects) {
      effects.push_back(e.spec);
      if (!e.spec.is_noise && e.spec.num_params() > 0) projected.push_back(e.spec.key);
    }
    ResimOptions resim;
    resim.seed = options.seed;
    resim.placements = options.placements;
    resim.threads = options.threads;
    ResimScorer scorer(result, real, base, effects, resim);
    out["placements_per_simulation"] = options.placements;
    out["projected_on"] = projected;
    out["nominal_mean_log_likelihood"] = scorer.NominalLogLikelihood();
    // The scans are separate (each from the nominal config); their winners are combined.
    sim::SimConfig recalibrated = base;
    json scans = json::array();
    if (friction) {
      json f = ScanFriction(scorer, &recalibrated);
      for (const char* k : {"parameter", "nominal", "candidates", "best", "improvement_nats_per_sample"}) {
        out[k] = f[k];
      }
      scans.push_back(f);
    }
    if (payload) scans.push_back(ScanPayload(scorer, &recalibrated));
    if (legs) scans.push_back(ScanLegGain(scorer, &recalibrated));
    out["scans"] = scans;
    out["recalibrated_config"] = json::parse(sim::SimConfigToJson(recalibrated));
    out["recalibrated_mean_log_likelihood"] = scorer.Evaluate({recalibrated})[0].mean_log_likelihood;
    if (options.verify_placements > 0) {
      // The literal check: models trained on new re-simulations (another seed) of the nominal
      // and the recalibrated config, each scored on the real set.
      const std::vector<double> direct =
          scorer.DirectLogLikelihoods({base, recalibrated}, options.verify_placements);
      out["verification"] = {{"placements", options.verify_placements},
                             {"nominal_mean_log_likelihood", direct[0]},
                             {"recalibrated_mean_log_likelihood", direct[1]},
                             {"improvement_nats_per_sample", direct[1] - direct[0]}};
    }
    out["simulations"] = scorer.simulations();
  } catch (const std::exception& e) {
    out = json{{"skipped", std::string("re-simulation failed: ") + e.what()}};
  }
  out["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out.dump(2);
#endif
}

}  // namespace dgmm::sim2real
