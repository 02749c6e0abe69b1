#include "sim2real/recalibrate.h"

#include <nlohmann/json.hpp>

#ifdef DGMM_SIM2REAL_HAVE_SIM
#include "sim/protocol.h"
#include "sim/sim_config.h"
#endif

namespace dgmm::sim2real {

bool RecalibrationOptions::IsValid(std::string* error) const {
  if (sim_config_path.empty() || placements < 5) {
    if (error) *error = "a sim config path and >= 5 placements are needed";
    return false;
  }
  return true;
}

std::string Recalibrate(const Sim2RealResult& result, const SampleSet& real,
                        const RecalibrationOptions& options) {
  nlohmann::json out;
  bool friction_effect = false;
  for (const auto& e : result.effects) {
    friction_effect |= e.spec.key == "slope_slip" || e.spec.key == "stride_loss" ||
                       e.spec.key == "slope_traction";
  }
  if (!friction_effect) {
    out["skipped"] = "no effect with a simulator mapping (slip, stride loss, traction -> friction) was found";
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
  const sim::SimConfig base = sim::LoadSimConfig(options.sim_config_path);
  const double nominal = base.friction.sliding;
  out["parameter"] = "friction.sliding";
  out["nominal"] = nominal;
  out["placements_per_simulation"] = options.placements;
  nlohmann::json candidates = nlohmann::json::array();
  std::vector<int> identity;
  double best_ll = -INFINITY, best_value = nominal, nominal_ll = NAN;
  for (double factor : {1.0, 0.85, 0.7, 0.55}) {
    sim::SimConfig config = base;
    config.friction.sliding = nominal * factor;
    sim::ProtocolOptions protocol;
    protocol.protocol = sim::Protocol::kPaper830;
    protocol.seed = options.seed;
    protocol.placements = options.placements;
    SampleSet resim = sim::SimulateProtocol(config, protocol);
    std::vector<int> id(resim.num_commands());
    for (int c = 0; c < resim.num_commands(); ++c) id[c] = c;
    Samples s = MakeSamples(resim, id);
    Samples r = MakeSamples(real, AlignCommands(resim, real));
    LinearGaussianModel model = LinearGaussianModel::Fit(s, LinearGaussianOptions{});
    const double ll = model.LogLikelihood(r).mean();
    candidates.push_back({{"value", config.friction.sliding}, {"mean_log_likelihood", ll},
                          {"samples", resim.size()}});
    if (factor == 1.0) nominal_ll = ll;
    if (ll > best_ll) {
      best_ll = ll;
      best_value = config.friction.sliding;
    }
  }
  out["candidates"] = candidates;
  out["best"] = best_value;
  out["improvement_nats_per_sample"] = best_ll - nominal_ll;
  return out.dump(2);
#endif
}

}  // namespace dgmm::sim2real
