#include "sim2real/candidates.h"

#include <algorithm>
#include <cmath>

#include "sim2real/sentence_format.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

struct Probe {
  int knob = -1;
  double value = 0;
  SampleSet set;
};

bool SameRecording(const SampleSet& a, const SampleSet& b) {
  return a.x.rows() == b.x.rows() && a.x.cols() == b.x.cols() && a.z.rows() == b.z.rows() &&
         a.z.cols() == b.z.cols() && a.x == b.x && a.z == b.z;
}

Recording OwnRecording(const AnalysisInputs& in, const CandidateOptions& options) {
  Recording r = in.recording;
  r.placements = options.placements;
  r.executions_per_placement = options.executions_per_placement;
  return r;
}

// The requests recorded with the sim set's own recording, counted into *recorded and *from_cache.
RecordingBatch RecordCounted(const KnobSimulator& simulator, const AnalysisInputs& in,
                             const std::vector<std::vector<KnobValue>>& requests, const CandidateOptions& options,
                             int* recorded, int* from_cache) {
  RecordingBatch batch = RecordBatch(simulator, OwnRecording(in, options), requests, options.recording);
  *recorded += batch.recorded;
  *from_cache += batch.from_cache;
  return batch;
}

// Records the probes of the listed knobs (and the nominal when `set` has none yet).
std::vector<Probe> RecordProbes(const KnobSimulator& sim, const AnalysisInputs& in, const std::vector<int>& knobs,
                                const CandidateOptions& options, CandidateSet* set) {
  std::vector<std::vector<KnobValue>> requests;
  std::vector<Probe> probes;
  const bool need_nominal = set->nominal.size() == 0;
  const std::vector<KnobValue> replica = need_nominal ? ChanceRequest(sim, options.chance) : std::vector<KnobValue>{};
  if (need_nominal) requests.emplace_back();
  if (!replica.empty()) requests.push_back(replica);
  for (int k : knobs) {
    for (double v : sim.knobs()[k].probes) {
      requests.push_back({KnobValue{k, v}});
      probes.push_back({k, v, {}});
    }
  }
  RecordingBatch batch = RecordCounted(sim, in, requests, options, &set->recorded, &set->from_cache);
  set->requests += static_cast<int>(requests.size());
  set->seconds += batch.wall_seconds;
  if (need_nominal) set->nominal = std::move(batch.sets[0]);
  if (!replica.empty()) {
    set->chance = MeasureWalkChance(set->nominal, batch.sets[1], in.sim_set, in.real,
                                    replica[0].value - sim.knobs()[replica[0].knob].nominal, options.slope_ridge);
  } else if (need_nominal) {
    set->chance.why_not = options.chance.share > 0 ? "the simulator has no payload to add a negligible mass to"
                                                   : "not asked for (share 0)";
  }
  const size_t first = (need_nominal ? 1 : 0) + (replica.empty() ? 0 : 1);
  for (size_t p = 0; p < probes.size(); ++p) probes[p].set = std::move(batch.sets[p + first]);
  return probes;
}

void AddMeasurement(const KnobCandidate& c, const EffectSpec& spec, ExternalCandidate::Kind kind, CandidateSet* set) {
  set->candidates.push_back(c);
  set->library.push_back(spec);
  ExternalCandidate e;
  e.kind = kind;
  set->externals.push_back(e);
}

// Tracker bias (every pose axis but yaw) and noise: first in the library.
void AddTrackerEffects(const AnalysisInputs& in, CandidateSet* set) {
  const int dx = in.real.pose_dim();
  AddMeasurement({"tracker_bias", "tracker_bias", "tracker.offset", "x units"},
                 ExternalSpec("tracker_bias", "constant offset of the tracked pose", in.layout.dyaw >= 0 ? dx - 1 : dx,
                              "x units"),
                 ExternalCandidate::kTrackerBias, set);
  KnobCandidate noise{"tracker_noise", "tracker_noise", "tracker.noise_scale", ""};
  noise.nominal = 1;
  noise.physical_min = 0;
  AddMeasurement(noise, NoiseEffect(), ExternalCandidate::kShift, set);
}

// IMU pitch/roll bias (with terrain, unless `imu_offset` is false) and heading drift (with yaw):
// last in the library.
void AddImuAndHeading(const AnalysisInputs& in, bool imu_offset, CandidateSet* set) {
  if (imu_offset && in.real.terrain_dim() >= 2) {
    AddMeasurement({"imu_bias", "imu_bias", kImuOffsetKnob, "rad"},
                   ExternalSpec("imu_bias", "IMU (terrain) pitch/roll offset", 2, "rad"), ExternalCandidate::kImuBias, set);
  }
  if (in.layout.dyaw >= 0) {
    AddMeasurement({"heading_drift", "heading_drift", "tracker.yaw_drift", "rad per execution"},
                   ExternalSpec("heading_drift", "heading drift per execution", 1, "rad per execution"),
                   ExternalCandidate::kHeading, set);
  }
}

// One-parameter shift candidates, the payload and the tracker's spread probe from the probes (in
// knob order); inert probes are listed, not candidates.
void AddKnobCandidates(const KnobSimulator& sim, const AnalysisInputs& in, const std::vector<Probe>& probes,
                       double slope_ridge, CandidateSet* set) {
  const auto& knobs = sim.knobs();
  for (const Probe& p : probes) {
    const Knob& k = knobs[p.knob];
    const bool payload = k.role == Knob::Role::kPayloadMass || k.role == Knob::Role::kPayloadX ||
                         k.role == Knob::Role::kPayloadY;
    if (!payload && SameRecording(p.set, set->nominal)) {
      AddUnique(&set->inert_knobs, k.name);
      continue;
    }
    try {
      set->shifts.push_back(PairedShift::Fit(set->nominal, p.set, in.sim_set, slope_ridge));
    } catch (const InputError&) {  // too few paired samples: the robot fell at this value
      set->unwalkable_probes.push_back(k.name + Fmt("@%.4g", p.value));
      continue;
    }
    const int s = static_cast<int>(set->shifts.size()) - 1;
    if (payload) {
      const int slot = k.role == Knob::Role::kPayloadMass ? 0 : k.role == Knob::Role::kPayloadX ? 1 : 2;
      set->payload_knob[slot] = p.knob;
      set->payload_shift[slot] = s;
      continue;
    }
    if (k.role == Knob::Role::kSpread) {
      set->tracker_knob = p.knob, set->tracker_shift = s, set->tracker_probe = p.value;
      continue;
    }
    KnobCandidate c{k.name + Fmt("@%.4g", p.value), k.family, k.name, k.unit, p.knob, k.nominal, p.value, k.lo, k.hi,
                    k.physical_min, true, k.leg, k.side};
    set->candidates.push_back(c);
    set->library.push_back(ExternalSpec(c.key, k.name + " (simulated)", 1, "fraction of the probe's change"));
    ExternalCandidate e;
    e.shifts = {s};
    set->externals.push_back(e);
  }
}

void AddPayload(const KnobSimulator& sim, CandidateSet* set) {
  if (set->payload_shift[0] < 0 || set->payload_shift[1] < 0 || set->payload_shift[2] < 0) return;
  const Knob& k = sim.knobs()[set->payload_knob[0]];
  KnobCandidate c{"payload", "payload", k.name, k.unit, -1, k.nominal, k.probes.empty() ? k.nominal : k.probes[0],
                  k.lo, k.hi, k.physical_min, true, "", ""};
  set->candidates.push_back(c);
  set->library.push_back(ExternalSpec("payload", "payload on the torso (simulated)", 3, "fraction of the probe"));
  ExternalCandidate e;
  e.kind = ExternalCandidate::kPayload;
  e.shifts = {set->payload_shift[0], set->payload_shift[1], set->payload_shift[2]};
  set->externals.push_back(e);
}

// Builds the library from the probes (library order: tracker bias, tracker noise, knob probes in
// knob order, payload, IMU bias, heading drift).
void BuildLibrary(const KnobSimulator& sim, const AnalysisInputs& in, std::vector<Probe> probes,
                  const CandidateOptions& options, CandidateSet* set) {
  std::stable_sort(probes.begin(), probes.end(), [](const Probe& a, const Probe& b) { return a.knob < b.knob; });
  set->candidates.clear(), set->library.clear(), set->externals.clear(), set->shifts.clear();
  set->inert_knobs.clear();
  set->unwalkable_probes.clear();
  AddTrackerEffects(in, set);
  AddKnobCandidates(sim, in, probes, options.slope_ridge, set);
  AddPayload(sim, set);
  AddImuAndHeading(in, options.imu_offset, set);
  set->chance_share.assign(set->candidates.size(), NAN);
  for (size_t k = 0; k < set->candidates.size(); ++k) {
    if (set->candidates[k].simulated) {
      set->chance_share[k] = ChanceShare(set->chance, set->shifts, set->externals[k].shifts, in.real);
    }
  }
}

// The first pass: forward selection with the backward pass over every candidate but the legs.
SelectionResult FirstPass(const FitProblem& fp, const Baseline& base, const CandidateOptions& options) {
  std::vector<int> rows(fp.n);
  for (int i = 0; i < fp.n; ++i) rows[i] = i;
  SelectionOptions quick = options.first_pass;
  quick.bootstrap_selection = 0;
  quick.backward = true;
  return ForwardSelect(fp, rows, base.fold, quick);
}

// The per-leg knobs of the implicated sides (every leg when a side does not list its legs).
std::vector<int> LegsOf(const std::vector<Knob>& knobs, const std::vector<int>& sides, const std::vector<int>& legs) {
  std::vector<int> out;
  for (int l : legs) {
    for (int s : sides) {
      const auto& members = knobs[s].members;
      if (members.empty() || std::find(members.begin(), members.end(), knobs[l].leg) != members.end()) {
        out.push_back(l);
        break;
      }
    }
  }
  return out;
}

// Why the sides cannot gate the per-leg probes: a side probe toppled the robot (empty if none did).
std::string SideProbeToppled(const CandidateSet& set, const std::vector<Knob>& knobs) {
  for (const std::string& probe : set.unwalkable_probes) {
    for (const Knob& k : knobs) {
      if (!k.side.empty() && probe.rfind(k.name + "@", 0) == 0) {
        return "the side probe " + probe + " toppled the robot, so the sides could not be tested first";
      }
    }
  }
  return "";
}

// The candidates of CandidateOptions::only_knobs' probes alone (sorted, once each).
CandidateSet OnlyTheseKnobs(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateOptions& options,
                            CandidateSet set) {
  const auto& knobs = simulator.knobs();
  std::vector<int> only = *options.only_knobs;
  std::sort(only.begin(), only.end());
  only.erase(std::unique(only.begin(), only.end()), only.end());
  if (!only.empty() && only.back() >= static_cast<int>(knobs.size())) {
    throw MakeInputError("", "candidate options", Fmt("only_knobs: knob index %.0f", only.back()) +
                                                      Fmt(" is not below the simulator's %.0f knobs",
                                                          static_cast<double>(knobs.size())));
  }
  BuildLibrary(simulator, in, RecordProbes(simulator, in, only, options, &set), options, &set);
  set.legs_probed = std::any_of(only.begin(), only.end(), [&](int k) { return !knobs[k].leg.empty(); });
  set.legs_note = set.legs_probed ? "per-leg probes recorded: the legs a first look screened in"
                                  : "per-leg probes not recorded: a first look screened in no leg";
  return set;
}

}  // namespace

std::vector<int> ImplicatedSides(const CandidateSet& set, const SelectionResult& sel, const CandidateOptions& options,
                                 std::string* why) {
  std::vector<int> sides;
  auto implicate = [&](int e, const std::string& because) {
    const KnobCandidate& c = set.candidates[e];
    if (c.side.empty() || std::find(sides.begin(), sides.end(), c.knob_index) != sides.end()) return;
    if (sides.empty()) *why = c.knob + because;
    sides.push_back(c.knob_index);
  };
  for (int e : sel.selected) implicate(e, " was selected in the first pass");
  for (size_t s = 0; s < sel.steps.size(); ++s) {
    int rank = 0;  // among the simulator's knobs: a measurement effect is no alternative to a leg
    for (const CandidateScore& c : sel.steps[s].candidates) {
      if (!set.candidates[c.effect].simulated) continue;
      if (++rank > options.side_top) break;
      if (c.gain > 0 && c.z >= options.side_min_z) {
        implicate(c.effect, Fmt(" ranked %.0f among the simulator's knobs", rank) +
                                Fmt(" in the first pass's step %.0f", s + 1.0) + Fmt(" (held-out z %.1f)", c.z));
      }
    }
  }
  return sides;
}

bool CandidateOptions::IsValid(std::string* error) const {
  if (placements < 0 || executions_per_placement < 0 || !(slope_ridge >= 0) || side_top < 1) {
    if (error) *error = "placements >= 0, executions_per_placement >= 0, slope_ridge >= 0 and side_top >= 1";
    return false;
  }
  if (only_knobs && std::any_of(only_knobs->begin(), only_knobs->end(), [](int k) { return k < 0; })) {
    if (error) *error = "only_knobs: knob indices >= 0";
    return false;
  }
  return recording.IsValid(error) && first_pass.IsValid(error) && chance.IsValid(error);
}

Eigen::VectorXd CandidateLogVariance(const CandidateSet& set, int k) {
  if (!set.candidates[k].simulated || set.externals[k].shifts.empty()) return {};
  return set.shifts[set.externals[k].shifts[0]].log_variance_ratio();
}

void FillCandidateDesign(const AnalysisInputs& in, const Baseline& base, const CandidateSet& set, int k,
                         FitProblem* fp) {
  if (set.library[k].is_noise) return;
  if (set.spread_signatures) fp->log_var[k] = CandidateLogVariance(set, k);
  const Samples& real = in.real;
  for (int i = 0; i < real.size(); ++i) {
    SetDesign(fp, k, i,
              ExternalDesign(set.externals[k], set.shifts, base.sim_model, in.layout, real.pose_dim(), real.command[i],
                             real.z.row(i).transpose(), real.first_execution[i]));
  }
}

namespace {

// Appends first_look's candidate k with the shifts `shifts` (first_look's indices) copied into set.
void KeepCandidate(const CandidateSet& first_look, int k, const std::vector<int>& shifts, CandidateSet* set) {
  ExternalCandidate e = first_look.externals[k];
  e.shifts.clear();
  for (int s : shifts) {
    set->shifts.push_back(first_look.shifts.at(s));
    e.shifts.push_back(static_cast<int>(set->shifts.size()) - 1);
  }
  set->candidates.push_back(first_look.candidates[k]);
  set->library.push_back(first_look.library[k]);
  set->externals.push_back(std::move(e));
  set->chance_share.push_back(k < static_cast<int>(first_look.chance_share.size()) ? first_look.chance_share[k] : NAN);
}

}  // namespace

int KeepFirstLookCandidates(const CandidateSet& first_look, const std::vector<int>& recorded_knobs, CandidateSet* set) {
  auto recorded = [&](int knob) {
    return std::find(recorded_knobs.begin(), recorded_knobs.end(), knob) != recorded_knobs.end();
  };
  int kept = 0;
  for (size_t k = 0; k < first_look.candidates.size(); ++k) {
    const KnobCandidate& c = first_look.candidates[k];
    const ExternalCandidate& e = first_look.externals[k];
    const bool knob = c.simulated && c.knob_index >= 0 && !recorded(c.knob_index) && e.shifts.size() == 1;
    const bool payload = e.kind == ExternalCandidate::kPayload && e.shifts.size() == 3 &&
                         !recorded(first_look.payload_knob[0]) && set->payload_shift[0] < 0;
    if (!knob && !payload) continue;
    KeepCandidate(first_look, static_cast<int>(k), e.shifts, set);
    if (payload) {
      for (int j = 0; j < 3; ++j) {
        set->payload_knob[j] = first_look.payload_knob[j];
        set->payload_shift[j] = set->externals.back().shifts[j];
      }
    }
    ++kept;
  }
  for (const std::string& k : first_look.inert_knobs) AddUnique(&set->inert_knobs, k);
  for (const std::string& p : first_look.unwalkable_probes) AddUnique(&set->unwalkable_probes, p);
  if (first_look.legs_probed && !set->legs_probed) set->legs_probed = true, set->legs_note = first_look.legs_note;
  return kept;
}

FitProblem MakeCandidateProblem(const AnalysisInputs& in, const Baseline& base, const CandidateSet& set) {
  FitProblem fp = MakeFitProblem(in.real, base.sim_model, set.library);
  for (size_t k = 0; k < set.library.size(); ++k) FillCandidateDesign(in, base, set, static_cast<int>(k), &fp);
  return fp;
}

PairedShift RecordShift(const KnobSimulator& simulator, const AnalysisInputs& in, const CandidateSet& set,
                        const std::vector<KnobValue>& values, const CandidateOptions& options, int* recorded,
                        int* from_cache) {
  return RecordShifts(simulator, in, set, {values}, options, recorded, from_cache)[0];
}

std::vector<PairedShift> RecordShifts(const KnobSimulator& simulator, const AnalysisInputs& in,
                                      const CandidateSet& set, const std::vector<std::vector<KnobValue>>& requests,
                                      const CandidateOptions& options, int* recorded, int* from_cache) {
  const RecordingBatch batch = RecordCounted(simulator, in, requests, options, recorded, from_cache);
  std::vector<PairedShift> out;
  for (const SampleSet& s : batch.sets) out.push_back(PairedShift::Fit(set.nominal, s, in.sim_set, options.slope_ridge));
  return out;
}

std::vector<std::optional<PairedShift>> RecordWalkableShifts(const KnobSimulator& simulator, const AnalysisInputs& in,
                                                             const CandidateSet& set,
                                                             const std::vector<std::vector<KnobValue>>& requests,
                                                             const CandidateOptions& options, int* recorded,
                                                             int* from_cache) {
  const RecordingBatch batch = RecordCounted(simulator, in, requests, options, recorded, from_cache);
  std::vector<std::optional<PairedShift>> out;
  for (const SampleSet& s : batch.sets) {
    try {
      out.push_back(PairedShift::Fit(set.nominal, s, in.sim_set, options.slope_ridge));
    } catch (const InputError&) {  // too few paired samples: the robot fell at these values
      out.push_back(std::nullopt);
    }
  }
  return out;
}

CandidateSet BuildCandidates(const KnobSimulator& simulator, const AnalysisInputs& in, const Baseline& base,
                             const CandidateOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "candidate options", error);
  if (!in.sim_set.has_sequence()) {
    throw MakeInputError("--sim", "episode", "signatures need the sim set's episodes and steps");
  }
  CandidateSet set;
  set.recording = OwnRecording(in, options);
  set.spread_signatures = options.spread_signatures;
  if (options.only_knobs) return OnlyTheseKnobs(simulator, in, options, std::move(set));
  const auto& knobs = simulator.knobs();
  std::vector<int> first, legs;
  bool any_side = false;
  for (int k = 0; k < static_cast<int>(knobs.size()); ++k) {
    (knobs[k].leg.empty() ? first : legs).push_back(k);
    any_side |= !knobs[k].side.empty();
  }
  const bool gate = options.legs_only_when_implicated && any_side && !legs.empty();
  std::vector<Probe> probes = RecordProbes(simulator, in, gate ? first : [&] {
    std::vector<int> all = first;
    all.insert(all.end(), legs.begin(), legs.end());
    return all;
  }(), options, &set);
  BuildLibrary(simulator, in, probes, options, &set);
  set.legs_probed = !gate && !legs.empty();
  if (!gate) {
    set.legs_note = legs.empty() ? "" : "per-leg probes recorded (the robot has no side knobs to test first)";
    if (!options.legs_only_when_implicated && !legs.empty()) set.legs_note = "per-leg probes recorded (always)";
    return set;
  }
  std::string why = SideProbeToppled(set, knobs);
  if (why.empty()) {
    const std::vector<int> sides =
        ImplicatedSides(set, FirstPass(MakeCandidateProblem(in, base, set), base, options), options, &why);
    if (sides.empty()) {
      set.legs_note = "per-leg probes not recorded: no side knob is implicated by the first pass";
      return set;
    }
    legs = LegsOf(knobs, sides, legs);
    if (sides.size() > 1) why += "; and " + knobs[sides[1]].name;
    if (sides.size() == 1 && !knobs[sides[0]].members.empty()) why += "; the legs of that side only";
  }
  std::vector<Probe> leg_probes = RecordProbes(simulator, in, legs, options, &set);
  probes.insert(probes.end(), std::make_move_iterator(leg_probes.begin()), std::make_move_iterator(leg_probes.end()));
  BuildLibrary(simulator, in, probes, options, &set);
  set.legs_probed = true;
  set.legs_note = "per-leg probes recorded: " + why;
  return set;
}

}  // namespace dgmm::sim2real
