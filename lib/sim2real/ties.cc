#include "sim2real/ties.h"

#include <algorithm>
#include <chrono>

#include "sim2real/sentence_format.h"
#include "util/error.h"

namespace dgmm::sim2real {
namespace {

double Cosine(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const double d = a.norm() * b.norm();
  return d > 0 ? a.dot(b) / d : 0.0;
}

// The cell the proposal would record: the command x terrain centre where the two candidates'
// fitted predictions (each fitted alone) differ most, whitened, per execution.
struct Proposal {
  int other = -1, command = -1, terrain = -1;
  double theta_chosen = 0, theta_other = 0, separation = 0;
};

void ProposeCell(const AnalysisInputs& in, const Baseline& base, const CandidateSet& set, const FitProblem& fp,
                 int chosen, int other, const EffectFitOptions& fit_options, Proposal* best) {
  const EffectFit a = FitEffects(fp, {chosen}, {}, fit_options);
  const EffectFit b = FitEffects(fp, {other}, {}, fit_options);
  const int nt = std::max<int>(1, base.terrain_centres.rows());
  const int dx = in.real.pose_dim();
  for (int c : in.real_commands) {
    for (int t = 0; t < nt; ++t) {
      const Eigen::VectorXd z = base.terrain_centres.rows() > 0 ? Eigen::VectorXd(base.terrain_centres.row(t).transpose())
                                                                 : Eigen::VectorXd::Zero(in.real.terrain_dim());
      const Prediction p = base.sim_model.Predict(c, z, 0.0);
      auto design = [&](int k, const EffectFit& f) -> Eigen::VectorXd {
        return ExternalDesign(set.externals[k], set.shifts, base.sim_model, in.layout, dx, c, z, 0.0) * f.theta[0];
      };
      const Eigen::VectorXd delta = p.chol.triangularView<Eigen::Lower>().solve(design(chosen, a) - design(other, b));
      if (delta.squaredNorm() > best->separation) {
        *best = {other, c, t, a.theta[0](0), b.theta[0](0), delta.squaredNorm()};
      }
    }
  }
}

// The check by recording the proposed cell at each knob's fitted value.
void CheckProposal(const KnobSimulator* simulator, const AnalysisInputs& in, const Baseline& base,
                   const CandidateSet& set, const Refinement& r, int chosen, const Proposal& p,
                   const TieOptions& options, TieResult* out, VerdictExperiment* ex) {
  const KnobCandidate& a = set.candidates[chosen];
  const KnobCandidate& b = set.candidates[p.other];
  if (p.other < 0 || ex->executions <= 0) {
    ex->not_checked_because = "no experiment proposed (a pure change of scale has no cell where the means differ)";
  } else if (!options.experiment.enabled) {
    ex->not_checked_because = "the check was turned off (--no-experiment-check)";
  } else if (a.knob_index < 0 || b.knob_index < 0) {
    const KnobCandidate& m = a.knob_index < 0 ? a : b;
    ex->not_checked_because = m.simulated ? m.family + " is a multi-parameter knob; not simulated"
                                          : m.family + " is a measurement effect: no simulator models it";
  } else if (out->experiment_checks >= options.max_experiment_checks) {
    ex->not_checked_because = Fmt("only the first %.0f ties are checked (cost bound)", options.max_experiment_checks);
  } else if (!simulator || base.terrain_centres.rows() <= p.terrain) {
    ex->not_checked_because = "no simulator or no terrain cell to record";
  } else {
    const KnobValue va{a.knob_index, std::clamp(a.nominal + p.theta_chosen * (r.signature_at[chosen] - a.nominal), a.lo, a.hi)};
    const KnobValue vb{b.knob_index, std::clamp(b.nominal + p.theta_other * (r.signature_at[p.other] - b.nominal), b.lo, b.hi)};
    try {
      const ExperimentCheck check = CheckExperiment(*simulator, va, vb, in.sim_set.commands.row(p.command).transpose(),
                                                    base.terrain_centres.row(p.terrain).transpose(), ex->executions,
                                                    options.experiment, std::max(1.0, std::exp(r.selection.fit.log_tau)));
      ++out->experiment_checks;
      RecordCheck(check, options.experiment.z_required, ex);
    } catch (const InputError& e) {
      ex->not_checked_because = std::string("simulation failed: ") + e.what();
    }
  }
}

}  // namespace

bool TieOptions::IsValid(std::string* error) const {
  if (!(tie_correlation > 0 && tie_correlation <= 1) || max_experiment_checks < 0) {
    if (error) *error = "0 < tie_correlation <= 1 and max_experiment_checks >= 0";
    return false;
  }
  return experiment.IsValid(error);
}

std::vector<int> TiedCandidates(const FitProblem& fp, const SelectionStep& step, int chosen,
                                const std::vector<TieScope>& scope, double tie_correlation,
                                const EffectFitOptions& fit_options, std::vector<double>* correlation) {
  std::vector<int> out;
  if (step.candidates.empty()) return out;
  const CandidateScore& best = step.candidates.front();
  Eigen::VectorXd shift_a;
  if (!fp.library[chosen].is_noise) shift_a = WhitenedShift(fp, FitEffects(fp, {chosen}, {}, fit_options), 0);
  for (const auto& cand : step.candidates) {
    const int o = cand.effect;
    if (o == chosen || !scope[o].Distinct(scope[chosen])) continue;
    const bool flagged = std::find(step.confusable.begin(), step.confusable.end(), o) != step.confusable.end();
    double r = 0;
    if (!fp.library[o].is_noise && shift_a.size() > 0) {
      r = std::abs(Cosine(shift_a, WhitenedShift(fp, FitEffects(fp, {o}, {}, fit_options), 0)));
    }
    const bool close = cand.gain > 0 && cand.gain >= best.gain - 2 * best.se;
    if (flagged || (close && r >= tie_correlation)) {
      out.push_back(o);
      if (correlation) correlation->push_back(r);
    }
  }
  return out;
}

TieResult FindTies(const KnobSimulator* simulator, const AnalysisInputs& in, const Baseline& base,
                   const CandidateSet& set, const Refinement& r, const std::vector<int>& named,
                   const TieOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) throw MakeInputError("", "tie options", error);
  const auto start = std::chrono::steady_clock::now();
  TieResult out;
  std::vector<TieScope> scope;
  for (const auto& c : set.candidates) scope.push_back({c.family, c.WholeRobot()});
  const EffectFitOptions& fit = r.selection_options.fit;
  for (const int chosen : named) {
    const auto step = std::find_if(r.selection.steps.begin(), r.selection.steps.end(),
                                   [&](const SelectionStep& st) { return st.chosen == chosen; });
    if (step == r.selection.steps.end()) continue;
    std::vector<double> corr;
    const std::vector<int> tied = TiedCandidates(r.problem, *step, chosen, scope, options.tie_correlation, fit, &corr);
    CandidateTie ct{chosen, {}};
    VerdictTie& tie = ct.tie;
    tie.families.push_back(set.candidates[chosen].family);
    Proposal best;
    for (size_t q = 0; q < tied.size(); ++q) {
      const int o = tied[q];
      const KnobCandidate& c = set.candidates[o];
      // Its own family at another scope is named by its knob: "actuator_gain (actuators.left_side.gain)".
      const std::string label = c.family == tie.families[0] ? c.family + " (" + c.knob + ")" : c.family;
      if (std::find(tie.families.begin(), tie.families.end(), label) != tie.families.end()) continue;
      tie.families.push_back(label);
      double gain_o = 0;
      for (const auto& c : step->candidates) gain_o = c.effect == o ? c.gain : gain_o;
      if (tie.why.empty()) {
        tie.why = Fmt("signature correlation %.2f on the observed samples; held-out gains %.3f vs %.3f", corr[q],
                      step->candidates.front().gain, gain_o) + Fmt(" nats per sample (SE %.3f)", step->candidates.front().se);
      }
      if (!set.library[chosen].is_noise && !set.library[o].is_noise) ProposeCell(in, base, set, r.problem, chosen, o, fit, &best);
    }
    if (tie.families.size() < 2) continue;
    VerdictExperiment& ex = tie.experiment;
    if (best.other >= 0) {
      ex.separation = best.separation;
      ex.commands = {in.command_labels[best.command]};
      ex.terrain = {best.terrain < static_cast<int>(base.terrain_labels.size()) ? base.terrain_labels[best.terrain] : "all terrain"};
      ex.executions = ExecutionsToSeparate(std::max(best.separation, 1e-4));
    }
    CheckProposal(simulator, in, base, set, r, chosen, best, options, &out, &ex);
    out.ties.push_back(ct);
  }
  out.experiment_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace dgmm::sim2real
