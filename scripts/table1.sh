#!/usr/bin/env bash
# Table I of Edgington et al. (IROS 2009) on our data: cross-validated held-out log-likelihood
# with and without terrain, for the 390-sample set (the paper's "real" role) and the 830-sample
# set ("simulated" role), beside the paper's figures. Writes the `table1` section of
# docs/reproduction.md and the figures under docs/figures/table1/.
#
# Usage: scripts/table1.sh [real.h5] [simulated.h5]
# Environment: DGMM_EXE (default build/app/dgmm), FOLDS (10), REPEATS (10), SEED (1).
# Rendering needs X: the script runs the plots under xvfb-run -a when DISPLAY is unset.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
dgmm=${DGMM_EXE:-$root/build/app/dgmm}
real=${1:-$root/datasets/scorpion_sim_390.h5}
sim=${2:-$root/datasets/scorpion_sim_830.h5}
folds=${FOLDS:-10}
repeats=${REPEATS:-10}
seed=${SEED:-1}
out=$root/docs/figures/table1
[ -x "$dgmm" ] || { echo "table1: no dgmm binary at $dgmm (build first or set DGMM_EXE)" >&2; exit 2; }
for f in "$real" "$sim"; do
  [ -f "$f" ] || { echo "table1: no sample set at $f (scripts/simulate_datasets.sh makes it)" >&2; exit 2; }
done
x=()
[ -z "${DISPLAY:-}" ] && x=(xvfb-run -a -s "-screen 0 1280x1024x24")
mkdir -p "$out"
# Runs a command that renders (under xvfb-run when there is no display); a run killed by a signal
# (rare crashes seen inside VTK/Xvfb on this shared machine) is retried up to twice.
render() {
  local attempt status
  for attempt in 1 2 3; do
    status=0
    "${x[@]}" "$@" || status=$?
    [ "$status" -lt 128 ] && return "$status"
    echo "table1: '$1 $2' killed by signal $((status - 128)), retrying" >&2
  done
  return "$status"
}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
common=(--folds "$folds" --repeats "$repeats" --seed "$seed")

for role in real sim; do
  set_path=$real
  [ "$role" = sim ] && set_path=$sim
  echo "table1: $role role: $set_path"
  # k by cross-validation with terrain (the same folds and seeds as the table below).
  render "$dgmm" tune-k "$set_path" "${common[@]}" --with-terrain --json \
    --plot "$out/tune_k_$role.png" --curve-csv "$out/tune_k_$role.csv" > "$work/tune_$role.json"
  k=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["k"])' "$work/tune_$role.json")
  echo "table1: $role: k = $k"
  "$dgmm" cv "$set_path" "${common[@]}" --k "$k" --json > "$work/cv_$role.json"
  # Diagnostic: the planar motion alone (dx, dy, dyaw), where the slope acts most.
  "$dgmm" cv "$set_path" "${common[@]}" --k "$k" --pose-dims dx,dy,dyaw --json \
    > "$work/cv_planar_$role.json"
  # ... and the small, noise-dominated dimensions alone (dz, droll, dpitch).
  "$dgmm" cv "$set_path" "${common[@]}" --k "$k" --pose-dims dz,droll,dpitch --json --no-em \
    > "$work/cv_vertical_$role.json"
  cp "$work/cv_vertical_$role.json" "$out/cv_vertical_$role.json"
  cp "$work/cv_$role.json" "$out/cv_$role.json"
  cp "$work/cv_planar_$role.json" "$out/cv_planar_$role.json"
  cp "$work/tune_$role.json" "$out/tune_k_$role.json"
done

# Conditional densities p(dx, dy | c, z) of the forward command at two terrain values (looking
# down and up the 18 degree slope), from the 390-sample model fitted with terrain at its k.
k_real=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["k"])' "$work/tune_real.json")
"$dgmm" fit "$real" -o "$work/model_real.h5" --k "$k_real" --seed "$seed" > /dev/null
command_label="+0.5,0,0"
for name in down:0.314 up:-0.314; do
  tag=${name%%:*}
  pitch=${name#*:}
  render "$dgmm" render "$work/model_real.h5" -o "$out/density_forward_pitch_$tag.png" \
    --command "$command_label" --x-dim dx --y-dim dy --condition "pitch=$pitch" \
    --condition roll=0 --marginalise \
    --title "p(dx, dy | c = <$command_label>, pitch = $pitch rad, roll = 0), k = $(printf %.3g "$k_real")" \
    > /dev/null
done

# tune-k against a dense grid of cv on the same folds and seeds (must be within one s.e.).
check_status=pass
DGMM_EXE=$dgmm FOLDS=$folds REPEATS=$repeats SEED=$seed GRID=${GRID:-17} \
  JSON_OUT="$work/check_real.json" "$root/scripts/check_tune_k.sh" "$real" > "$work/check.txt" \
  || check_status=fail
cat "$work/check.txt"

python3 - "$work" "$out" "$real" "$sim" "$folds" "$repeats" "$seed" "$root" > "$work/section.md" <<'EOF'
import json, os, sys
work, out, real, sim, folds, repeats, seed, root = sys.argv[1:9]
shown = lambda p: os.path.relpath(p, root) if os.path.abspath(p).startswith(root + "/") else p
paper = {"real": ((-371.9, 3.9), (-162.2, 4.0)), "sim": ((308.5, 7.5), (402.5, 7.9))}
paper_n = {"real": 390, "sim": 830}
role_name = {"real": "real (our 390-sample set)", "sim": "simulated (our 830-sample set)"}
cv = {r: json.load(open(os.path.join(work, f"cv_{r}.json"))) for r in ("real", "sim")}
planar = {r: json.load(open(os.path.join(work, f"cv_planar_{r}.json"))) for r in ("real", "sim")}
tune = {r: json.load(open(os.path.join(work, f"tune_{r}.json"))) for r in ("real", "sim")}
vertical = {r: json.load(open(os.path.join(work, f"cv_vertical_{r}.json"))) for r in ("real", "sim")}
rel = lambda p: os.path.relpath(p, os.path.join(os.path.dirname(out), ".."))
fmt = lambda m, s: f"{m:.1f} ± {s:.1f}"

with open(os.path.join(out, "bars.csv"), "w") as f:
    f.write("setting,ours_dgmm,ours_dgmm_sd,ours_em,ours_em_sd,paper,paper_sd\n")
    for r in ("real", "sim"):
        n = cv[r]["scored_per_repeat"]
        for t, key in ((0, "without_terrain"), (1, "with_terrain")):
            d, e = cv[r]["rows"]["dgmm_" + key], cv[r]["rows"]["em_bic_" + key]
            pm, ps = paper[r][t]
            label = f"{cv[r]['samples']} ({r}) {'with' if t else 'without'} terrain"
            f.write(f"{label},{d['mean']/n:.6g},{d['sd']/n:.6g},{e['mean']/n:.6g},{e['sd']/n:.6g},"
                    f"{pm/paper_n[r]:.6g},{ps/paper_n[r]:.6g}\n")

print("Written by `scripts/table1.sh` (rerun it to regenerate; figures in `docs/figures/table1/`).")
print(f"Repeated stratified {folds}-fold cross-validation, {repeats} repeats, seed {seed}: "
      "the held-out log-likelihood summed over all validation folds of a repeat (the paper's "
      "measure), mean ± sd over repeats. k is chosen per set by `dgmm tune-k --with-terrain` on "
      "the same folds and seeds (so the DGMM rows are slightly optimistic: k was selected on "
      "the data it is scored on). EM-BIC: per command a full-covariance EM whose number of "
      "components minimises BIC on the training fold (at most as many parameters as samples).")
print()
print("| role (file) | samples | k | model | without terrain | with terrain | per sample (w/o → with) |")
print("|---|---|---|---|---|---|---|")
for r in ("real", "sim"):
    c = cv[r]
    n = c["scored_per_repeat"]
    name = f"{role_name[r]}<br>`{shown(real if r == 'real' else sim)}`"
    for model, label in (("dgmm", "DGMM (ours)"), ("em_bic", "EM-BIC (ours)")):
        w, t = c["rows"][model + "_without_terrain"], c["rows"][model + "_with_terrain"]
        print(f"| {name} | {c['samples']} | {c['k']:.3g} | {label} | {fmt(w['mean'], w['sd'])} | "
              f"{fmt(t['mean'], t['sd'])} | {w['mean']/n:.2f} → {t['mean']/n:.2f} |")
    p = planar[r]["rows"]
    print(f"| {name} | {c['samples']} | {c['k']:.3g} | DGMM, x = (dx, dy, dyaw) only | "
          f"{fmt(p['dgmm_without_terrain']['mean'], p['dgmm_without_terrain']['sd'])} | "
          f"{fmt(p['dgmm_with_terrain']['mean'], p['dgmm_with_terrain']['sd'])} | "
          f"{p['dgmm_without_terrain']['mean']/n:.2f} → {p['dgmm_with_terrain']['mean']/n:.2f} |")
    v = vertical[r]["rows"]
    print(f"| {name} | {c['samples']} | {c['k']:.3g} | DGMM, x = (dz, droll, dpitch) only | "
          f"{fmt(v['dgmm_without_terrain']['mean'], v['dgmm_without_terrain']['sd'])} | "
          f"{fmt(v['dgmm_with_terrain']['mean'], v['dgmm_with_terrain']['sd'])} | "
          f"{v['dgmm_without_terrain']['mean']/n:.2f} → {v['dgmm_with_terrain']['mean']/n:.2f} |")
    (pw, pws), (pt, pts) = paper[r]
    print(f"| {r} (paper, SCORPION) | {paper_n[r]} | – | DGMM (paper) | {fmt(pw, pws)} | "
          f"{fmt(pt, pts)} | {pw/paper_n[r]:.2f} → {pt/paper_n[r]:.2f} |")
print()
check = json.load(open(os.path.join(work, "check_real.json")))
print(f"Check of tune-k (`scripts/check_tune_k.sh`, 390-sample set, with terrain): tune-k's k = "
      f"{check['tune_k']['k']:.3g} scores {check['tune_k']['log_likelihood']:.1f}, a dense grid of "
      f"{check['grid_points']} `dgmm cv` runs on the same folds and seeds peaks at k = "
      f"{check['grid_best']['k']:.3g} with {check['grid_best']['log_likelihood']:.1f} ± "
      f"{check['grid_best']['standard_error']:.1f}: gap {check['gap']:.1f} nats, "
      f"{'within' if check['pass'] else 'NOT within'} one standard error.")
print()
print("![Table I as bars](figures/table1/table1_bars.png)")
print()
print("Tuning curves (held-out log-likelihood ± standard error against k, the Ceres quadratic fit "
      "and the chosen k):")
print()
print("![tune-k, 390](figures/table1/tune_k_real.png) ![tune-k, 830](figures/table1/tune_k_sim.png)")
print()
print("Conditional densities p(dx, dy | c = ⟨+0.5, 0, 0⟩, z) of the 390-sample model at two "
      "terrain values (pitch ±0.314 rad = ±18°, roll 0: looking down and up the slope):")
print()
print("![pitch +18°](figures/table1/density_forward_pitch_down.png) "
      "![pitch -18°](figures/table1/density_forward_pitch_up.png)")
print()
print("### Method")
print()
print("""- **Folds** (`lib/tune/cross_validation.h`): per repeat, each command's samples are shuffled
  with a seed derived from (seed, repeat) and dealt round-robin into the folds, the deal continuing
  across commands, so every fold holds floor or ceil of each command's share. A command with fewer
  samples than folds is simply absent from some folds; a command with a single sample cannot be
  scored when it is held out (no training data) and is reported as unscored.
- **Training**: each training fold is streamed through ADDSAMPLE in the set's recorded order (the
  order the robot produced it; `--shuffle-training` shuffles per fold instead). The merge decisions
  of fold f of repeat r draw from a seed derived from (seed, r, f): the figures do not depend on the
  number of threads (folds run in parallel) and are the same for every k (common random numbers).
- **Scores**: per repeat, sum over all held-out samples of log p(x | c) (a model of x alone) or
  log p(x | c, z) (a model of x‖z, conditioned, eq. 15), in raw units; mean ± sd over repeats.
  The standard error of a total is √n × the sd of the per-sample held-out log-likelihoods
  (averaged over repeats): the spread another sample of n would show.
- **tune-k** (`lib/tune/tune_k.h`): the objective is piecewise constant in k (a merge decision
  r < t flips only when k crosses a threshold), so no derivative exists to follow. We evaluate it
  on a coarse log grid (9 points in [1e-3, 10]), bracket the best grid point by its neighbours,
  add 4 evaluations inside the bracket, let Ceres fit a concave quadratic in log k to the
  evaluations near the best (robust Cauchy loss on residuals scaled by the standard error, so a
  single step of the staircase does not drag the fit), and let Ceres' line-search solver maximise
  the quadratic over the bracket (bounded through a sigmoid). The chosen k is then
  cross-validated itself; common random numbers make the comparison with the grid fair.""")
print()
print("### Reading the table")
print()
for r in ("real", "sim"):
    c = cv[r]["rows"]
    gain = c["dgmm_with_terrain"]["mean"] - c["dgmm_without_terrain"]["mean"]
    se = max(c["dgmm_with_terrain"]["standard_error"], c["dgmm_without_terrain"]["standard_error"])
    pg = planar[r]["rows"]["dgmm_with_terrain"]["mean"] - planar[r]["rows"]["dgmm_without_terrain"]["mean"]
    verdict = "raises" if gain > 0 else "lowers"
    size = "more" if abs(gain) > se else "less"
    vg = vertical[r]["rows"]["dgmm_with_terrain"]["mean"] - vertical[r]["rows"]["dgmm_without_terrain"]["mean"]
    print(f"- {role_name[r]}: conditioning on terrain {verdict} the held-out log-likelihood by "
          f"{abs(gain):.0f} nats, {size} than one standard error of a total (≈ {se:.0f}); on the "
          f"planar motion (dx, dy, dyaw) alone it {'raises' if pg > 0 else 'lowers'} it by "
          f"{abs(pg):.0f} nats, on (dz, droll, dpitch) alone it {'raises' if vg > 0 else 'lowers'} "
          f"it by {abs(vg):.0f} nats. "
          f"tune-k: k = {tune[r]['k']:.3g} ({tune[r]['log_likelihood']:.1f} ± "
          f"{tune[r]['standard_error']:.1f}).")
print()
print("""**Why the absolute values differ from the paper's.** A log-likelihood of continuous data is
not unit-free: scaling one dimension by s shifts every sample's log-density by −log s. Our pose
change is in metres and radians and three of its six dimensions (dz, droll, dpitch) move by
millimetres and milliradians in the simulation, so their densities are far above 1 and the totals
are large and positive; the paper does not state its units, scaling or which pose dimensions
entered Table I, so its levels cannot be matched, and its real robot is surely noisier than our
simulated tracker and IMU. Our "real" set is simulated too (we have no robot). The comparison that carries
over is the sign and size of the terrain effect relative to the spread, not the level.""")
print()
r = cv["real"]["rows"]
if r["dgmm_with_terrain"]["mean"] <= r["dgmm_without_terrain"]["mean"]:
    print("""**Why terrain does not clearly help on the 390-sample set in six dimensions.** Each command has
15 samples (3 placements × 5 executions), so a training fold holds about 13 per command while the
joint y = x‖z has 8 dimensions (44 parameters for one full-covariance Gaussian): the conditional
p(x | c, z) is a regression of six pose dimensions on two terrain values whose residual covariance
is estimated from ~13 points, and a plug-in Gaussian's held-out penalty grows roughly like
n / (n − d − 1 − p) with the p regressors (about 2.1 without and 3.0 with terrain at n = 13.5,
d = 6: a cost of roughly 3 nats per held-out sample before any gain). The terrain acts on the
planar motion (dx, dy, dyaw), where it raises the likelihood strongly (row "x = (dx, dy, dyaw)
only"), but dz, droll and dpitch are dominated by tracker/IMU noise and gain little or nothing
from z (row "x = (dz, droll, dpitch) only") while paying the estimation cost in all six
dimensions; the net effect is the difference of the two. With 32 samples
per command (the 830-sample set) the cost is smaller than the gain and terrain helps in all six
dimensions, as in the paper.""")
EOF
render "$dgmm" plot --csv "$out/bars.csv" --x setting --y ours_dgmm,ours_em,paper \
  --yerr ours_dgmm_sd,ours_em_sd,paper_sd --names "DGMM (ours),EM-BIC (ours),DGMM (paper)" \
  --kind bar -o "$out/table1_bars.png" --size 1000x600 \
  --title "Table I: held-out log-likelihood per sample (mean +- sd over repeats)" \
  --y-label "nats per held-out sample"
python3 "$root/scripts/replace_section.py" "$root/docs/reproduction.md" table1 "$work/section.md"
echo "table1: wrote the table1 section of docs/reproduction.md and $out/"
