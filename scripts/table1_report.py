#!/usr/bin/env python3
"""The table1 section of docs/reproduction.md from the JSON files scripts/table1.sh writes.

Usage: table1_report.py WORK OUT REAL SIM FOLDS REPEATS SEED ROOT REPORT_SEED (prints Markdown,
writes OUT/bars.csv)."""
import json
import os
import sys

work, out, real, sim, folds, repeats, seed, root, report_seed = sys.argv[1:10]
shown = lambda p: os.path.relpath(p, root) if os.path.abspath(p).startswith(root + "/") else p
paper = {"real": ((-371.9, 3.9), (-162.2, 4.0)), "sim": ((308.5, 7.5), (402.5, 7.9))}
paper_n = {"real": 390, "sim": 830}
role_name = {"real": "real (our 390-sample set)", "sim": "simulated (our 830-sample set)"}
load = lambda name, r: json.load(open(os.path.join(work, f"{name}_{r}.json")))
roles = ("real", "sim")
cv = {r: load("cv", r) for r in roles}
cv_without = {r: load("cv_without", r) for r in roles}
default = {r: load("cv_default", r) for r in roles}
v1 = {r: load("cv_v1", r) for r in roles}
literal = {r: load("cv_literal", r) for r in roles}
planar = {r: load("cv_planar", r) for r in roles}
vertical = {r: load("cv_vertical", r) for r in roles}
def flat_tune(t):
    """A `dgmm tune --json` with the recommended settings and the k plateau at the top level."""
    rec = t["recommended"]
    t.update({key: rec[key] for key in ("k", "init_scale", "prior_count", "log_likelihood",
                                        "standard_error")})
    t["components"] = rec["components_per_command"]
    t["plateau"] = t["k_search"]["plateau"]
    return t


tune = {r: flat_tune(load("tune", r)) for r in roles}
tune_without = {r: flat_tune(load("tune_without", r)) for r in roles}
fmt = lambda m, s: f"{m:.1f} ± {s:.1f}"


def joint_moved(t):
    j = t.get("joint")
    return j is not None and (j["start"]["k"], j["start"]["init_scale"], j["start"]["prior_count"]) \
        != (t["k"], t.get("init_scale") or j["start"]["init_scale"],
            t.get("prior_count") or j["start"]["prior_count"])


def settings(t):
    s = f"k = {t['k']:.3g}"
    if t.get("init_scale") is not None:
        s += f", f = {t['init_scale']:.3g}"
    if t.get("prior_count") is not None:
        s += f", ν0 = {t['prior_count']:.3g}"
    j = t.get("joint")
    if joint_moved(t):
        s += " (from the joint step" + (", simplest model of its plateau" if j["plateau"]["flat"] else "") + ")"
    elif t["plateau"]["flat"]:
        lo, hi = t["plateau"]["k_range"]
        s += f" (k from a plateau, {lo:.3g}–{hi:.3g}: simplest model)"
    return s


def joint_status(t):
    """accepted (an evaluation beat the cyclic choice by more than the tolerance), a strictly
    simpler equivalent model (plateau rule), or kept."""
    if t["joint"]["accepted"]:
        return "**moved** (an evaluation beat it)"
    return "simpler equivalent (plateau rule)" if joint_moved(t) else "kept"


def joint_rows():
    """The joint step of every tune run: a Markdown table (lines)."""
    lines = ["| set, terrain | cyclic choice: k, f, ν0 → L ± s.e. (Gaussians) | surrogate's maximum: k, f, ν0 → predicted / cross-validated | joint step | equivalent evaluations (within tolerance): k, f, ν0 | cross-validations (cyclic + joint), wall time |",
             "|---|---|---|---|---|---|"]
    for r in roles:
        for terrain, t in (("without", tune_without[r]), ("with", tune[r])):
            j = t.get("joint")
            if j is None:
                continue
            st, sg, pl = j["start"], j["surrogate"], j["plateau"]
            lines.append(
                f"| {paper_n[r]}, {terrain} | {st['k']:.3g}, {st['init_scale']:.3g}, {st['prior_count']:.3g} → "
                f"{st['log_likelihood']:.1f} ± {st['standard_error']:.1f} ({st['components']:.2f}) | "
                f"{sg['k']:.3g}, {sg['init_scale']:.3g}, {sg['prior_count']:.3g} → {sg['maximum']:.1f} / "
                f"{sg['evaluated_log_likelihood']:.1f} ± {sg['evaluated_standard_error']:.1f} | "
                f"{joint_status(t)}: k = {t['k']:.3g}, f = {t['init_scale']:.3g}, "
                f"ν0 = {t['prior_count']:.3g} → {t['log_likelihood']:.1f} ({t['components']:.2f}) | "
                f"{pl['points']} of {len(j['points'])} within {j['tolerance']:.1f}: k {pl['k_range'][0]:.3g}–"
                f"{pl['k_range'][1]:.3g}, f {pl['init_scale_range'][0]:.3g}–{pl['init_scale_range'][1]:.3g}, "
                f"ν0 {pl['prior_count_range'][0]:.3g}–{pl['prior_count_range'][1]:.3g} | "
                f"{t['evaluations'] - j['evaluations']} + {j['evaluations']}, {t['seconds']:.0f} s |")
    return lines


# EM-BIC rows are omitted by `dgmm cv` when a command has fewer training samples in a fold than
# one full-covariance Gaussian has parameters; then the bars show the DGMM and the paper only.
em_scored = all("em_bic_" + key in cv[r]["rows"] for r in roles
                for key in ("without_terrain", "with_terrain"))
with open(os.path.join(out, "bars.csv"), "w") as f:
    f.write("setting,ours_dgmm,ours_dgmm_sd," + ("ours_em,ours_em_sd," if em_scored else "") +
            "paper,paper_sd\n")
    for r in roles:
        n = cv[r]["scored_per_repeat"]
        for t, key in ((0, "without_terrain"), (1, "with_terrain")):
            d = (cv_without[r] if t == 0 else cv[r])["rows"]["dgmm_" + key]
            pm, ps = paper[r][t]
            label = f"{cv[r]['samples']} ({r}) {'with' if t else 'without'} terrain"
            em = ""
            if em_scored:
                e = cv[r]["rows"]["em_bic_" + key]
                em = f"{e['mean']/n:.6g},{e['sd']/n:.6g},"
            f.write(f"{label},{d['mean']/n:.6g},{d['sd']/n:.6g},{em}"
                    f"{pm/paper_n[r]:.6g},{ps/paper_n[r]:.6g}\n")

print("Written by `scripts/table1.sh` (rerun it to regenerate; figures and JSON in "
      "`docs/figures/table1/`).")
print(f"Repeated {folds}-fold cross-validation, {repeats} repeats; folds: "
      f"{cv['real']['folds_by']} (390 set), {cv['sim']['folds_by']} (830 set): no placement is "
      "split between training and test. The held-out log-likelihood is summed over all "
      "validation folds of a repeat (the paper's measure), mean ± sd over repeats, with the "
      "standard error (s.e.) of a total. **Tuned** rows: `dgmm tune` chose k, the S0 scale f and "
      f"the prior pseudo-count ν0 on folds and merges of seed {seed}, separately with and "
      f"without terrain; every row is then scored on seed {report_seed} (other folds, other "
      "random numbers), so the tuned settings are not scored on the folds that chose them. "
      "EM-BIC: per command a full-covariance EM whose number of components minimises BIC on the "
      "training fold (at most as many parameters as samples).")
print()
print("| role (file) | model | settings | without terrain | with terrain | terrain gain (s.e.) | Gaussians per command (w/o, with) |")
print("|---|---|---|---|---|---|---|")
for r in roles:
    name = f"{role_name[r]}<br>`{shown(real if r == 'real' else sim)}`"
    def row(label, sett, w_json, t_json, model="dgmm"):
        if model + "_with_terrain" not in t_json["rows"] or model + "_without_terrain" not in w_json["rows"]:
            why = (t_json.get("omitted_rows", {}).get(model + "_with_terrain") or
                   w_json.get("omitted_rows", {}).get(model + "_without_terrain", "not scored"))
            print(f"| {name} | {label} | {sett} | omitted: {why} | | | |")
            return
        w = w_json["rows"][model + "_without_terrain"]
        t = t_json["rows"][model + "_with_terrain"]
        gain = t["mean"] - w["mean"]
        se = max(w["standard_error"], t["standard_error"])
        print(f"| {name} | {label} | {sett} | {fmt(w['mean'], w['sd'])} | {fmt(t['mean'], t['sd'])} "
              f"| {gain:+.0f} ({se:.0f}) | {w['mean_components']:.2f}, {t['mean_components']:.2f} |")
    row("DGMM, tuned", f"without: {settings(tune_without[r])}<br>with: {settings(tune[r])}",
        cv_without[r], cv[r])
    row("DGMM, new defaults", "k = 0.7, S0 = 0.3 v, prior ν0 = 4", default[r], default[r])
    row("DGMM, version 1", "k = 0.7, S0 = I, blend, floor 1e-6", v1[r], v1[r])
    row("DGMM, literal eq. 13", "k = 0.7, S0 = I, literal, floor 1e-6", literal[r], literal[r])
    row("EM-BIC", "—", cv[r], cv[r], model="em_bic")
    row("DGMM, x = (dx, dy, dyaw) only", "tuned with terrain", planar[r], planar[r])
    row("DGMM, x = (dz, droll, dpitch) only", "tuned with terrain", vertical[r], vertical[r])
    (pw, pws), (pt, pts) = paper[r]
    print(f"| {r} (paper, SCORPION, {paper_n[r]} samples) | DGMM (paper) | – | {fmt(pw, pws)} | "
          f"{fmt(pt, pts)} | {pt - pw:+.0f} | – |")
print()
check = json.load(open(os.path.join(work, "check_real.json")))
print(f"Check of `dgmm tune` (`scripts/check_tune_k.sh`, 390-sample set, with terrain, seed {seed}): "
      f"tune's k = {check['tune_k']['k']:.3g} scores {check['tune_k']['log_likelihood']:.1f}; a dense "
      f"grid of {check['grid_points']} `dgmm cv` runs over k (at tune's f and ν0, same folds and "
      f"seeds) peaks at k = {check['grid_best']['k']:.3g} with "
      f"{check['grid_best']['log_likelihood']:.1f} ± {check['grid_best']['standard_error']:.1f}: gap "
      f"{check['gap']:.1f} nats, {'within' if check['pass'] else 'NOT within'} one standard error"
      + (f"; tune reported a plateau over k = {check['plateau']['k_range'][0]:.3g}–"
         f"{check['plateau']['k_range'][1]:.3g}." if check["plateau"]["flat"] else "."))
print()
print("Joint step of `dgmm tune` (lib/tune/tune_k.h, step 3; seed " + seed + "): after the cyclic "
      "coordinate steps, a design around the cyclic choice in (log k, log f, log ν0) (centre, star, "
      "2-level factorial; one grid step, then half a step around the choice), a concave quadratic "
      "fitted by Ceres to every evaluation in the design's box and maximised inside it, and the "
      "cross-validated L at that maximum. The choice moves only when an evaluation beats it by more "
      "than the tolerance (one s.e. of the best); the equivalent evaluations are those within the "
      "tolerance of the best, and the simplest of them is chosen when it moves.")
print()
for line in joint_rows():
    print(line)
print()
print("![Table I as bars](figures/table1/table1_bars.png)")
print()
print("Last k step of `dgmm tune` with terrain (held-out log-likelihood ± s.e. against k at the "
      "final f and ν0, the Ceres quadratic fit and the chosen k):")
print()
print("![tune, 390](figures/table1/tune_k_real.png) ![tune, 830](figures/table1/tune_k_sim.png)")
print()
print("Conditional densities p(dx, dy | c = ⟨+0.5, 0, 0⟩, z) of the 390-sample model (tuned, with "
      "terrain) at two terrain values (pitch ±0.314 rad = ±18°, roll 0):")
print()
print("![pitch +18°](figures/table1/density_forward_pitch_down.png) "
      "![pitch -18°](figures/table1/density_forward_pitch_up.png)")
print()
print("### Reading the table: the estimator's point of view")
print()
for r in roles:
    w = cv_without[r]["rows"]["dgmm_without_terrain"]
    t = cv[r]["rows"]["dgmm_with_terrain"]
    gain = t["mean"] - w["mean"]
    se = max(w["standard_error"], t["standard_error"])
    em = cv[r]["rows"].get("em_bic_with_terrain")
    em_text = (f"EM-BIC chooses {em['mean_components']:.2f} components per command with terrain."
               if em else "EM-BIC is not scored (too few training samples per command in a fold).")
    print(f"- {role_name[r]}: at tuned settings terrain {'raises' if gain > 0 else 'lowers'} the "
          f"held-out log-likelihood by {abs(gain):.0f} nats, {'more' if abs(gain) > se else 'less'} "
          f"than one s.e. of a total (≈ {se:.0f}). The DGMM uses {w['mean_components']:.2f} / "
          f"{t['mean_components']:.2f} Gaussians per command (without / with terrain); {em_text}")
gains = []
for r in roles:
    for terrain, t in (("without", tune_without[r]), ("with", tune[r])):
        j = t.get("joint")
        if j is not None:
            start = j["start"]["log_likelihood"]
            gains.append((f"{paper_n[r]} {terrain}", j["surrogate"]["evaluated_log_likelihood"] - start,
                          max(p["log_likelihood"] for p in j["points"]) - start,
                          t["log_likelihood"] - start, j["tolerance"]))
if gains:
    print("- Joint step, L minus the cyclic choice's L (at the last surrogate maximum / best "
          "evaluation of the step / final choice; tolerance): "
          + "; ".join(f"{n}: {g:+.1f} / {b:+.1f} / {c:+.1f} ({tol:.1f})" for n, g, b, c, tol in gains)
          + ". " + ("No surrogate maximum beats the cyclic choice by more than the tolerance"
                    if all(g <= tol for _, g, _, _, tol in gains) else
                    "A surrogate maximum beats the cyclic choice by more than the tolerance")
          + (", and every final choice is within the tolerance of it: on these sets the joint "
             "search finds no settings clearly better than the coordinate steps'."
             if all(abs(c) <= tol for _, _, _, c, tol in gains) else "."))
print()
print("""Each command of the 390 set has 15 samples (3 placements × 5 executions); with whole placements
held out a training fold keeps about 10 from two placements, in 8 dimensions for y = x‖z (44
parameters for one full-covariance Gaussian). Whether terrain helps is then a question about the
covariance estimator, not about the robot: the conditional p(x | c, z) is a regression of six pose
dimensions on two terrain values whose residual covariance comes from ~10 points. Version 1 used
the identity S0 (1 m², 3·10⁴ times dz's variance) and a blend that drops S0 once n > d, so each
command was one plug-in Gaussian whose only regulariser was the absolute 10⁻⁶ floor — the literal
eq. 13 row shows what remains without S0. The prior rule keeps S0 = f v as ν0 pseudo-samples
(a Normal–inverse-Wishart posterior mean): a shrinkage estimator whose strength ν0 and target f v
are chosen by cross-validation. The table shows whether, with it, the estimation cost of the two
extra dimensions falls below what terrain explains (the sign the paper reports). The tuned models
use one Gaussian per command, or close to it, because `dgmm tune` reports a plateau — over k in the
coordinate steps, over k, f and ν0 in the joint step — and takes its simplest model: with 10–30
samples per command cross-validation finds no mixture better than one well-regularised Gaussian
by more than a standard error (the joint step's table above says how far its surrogate's maximum
got). EM-BIC may only try as many parameters as samples (one 6-D Gaussian has 27, a second one needs 28 more), so it can only return one component, and its unregularised plug-in
covariance is what collapses in its rows when whole placements are held out. Which commands are
multimodal, tested apart from both models, and why folds by episode reward one Gaussian there:
section multimodality below (`scripts/multimodality.py`).

**Why the absolute values differ from the paper's.** A log-likelihood of continuous data is not
unit-free: scaling one dimension by s shifts every sample's log-density by −log s. Our pose change
is in metres and radians and three of its six dimensions (dz, droll, dpitch) move by millimetres
and milliradians in the simulation, so totals are large and positive; the paper does not state its
units or scaling, so its levels cannot be matched. Our "real" set is simulated too (we have no
robot). The comparison that carries over is the sign and size of the terrain effect relative to
the spread, not the level.""")
