#!/usr/bin/python3
"""Continuous commands against binned ones (issue #25), on simulated data.

For each seed: `dgmm simulate --protocol continuous` (166 random placements x 5 executions, each
command drawn uniformly from [-0.5, 0.5]^3 for long, lat and turn), then the same samples three
ways, every one through `dgmm import` from one CSV so that nothing else differs:
  * continuous: the command values kept as conditioning dimensions (`--continuous-cols`), plus
    pitch and roll; the model is p(x | c, z) for any c;
  * binned into B equal-count bins per command dimension (B^3 discrete commands; B = 2, 3, 4), z =
    pitch and roll; the model is p(x | bin, z);
  * no command at all (B = 1).
Each is scored by `dgmm cv --with-terrain --no-em` with its defaults (whole episodes per fold,
10 repeats, seed 1): held-out mean log-likelihood per sample of x and its standard error. The
difference continuous - best binned is reported with the standard error of a difference of
independent estimates, sqrt(se_a^2 + se_b^2) (conservative: the two share their samples).

Usage: /usr/bin/python3 scripts/continuous_commands.py --seeds 1 [--dgmm build/app/dgmm]
       [--placements 166] [--out out/continuous] [--figure F.png]    prints a Markdown table
"""
import argparse
import csv
import json
import os
import subprocess
import sys

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(cmd):
    return subprocess.run(cmd, check=True, capture_output=True, text=True).stdout


def cv(dgmm, path):
    out = json.loads(run([dgmm, "cv", path, "--with-terrain", "--no-em", "--json", "--seed", "1"]))
    row = out["rows"]["dgmm_with_terrain"]
    n = out["scored_per_repeat"]
    return row["mean_per_sample"], row["standard_error"] / n, row["mean_components"]


def write_csv(path, x, z, episode, bins):
    """x (n x 6), z (n x 5: three command values, pitch, roll); bins: None (continuous) or B."""
    cols = ["episode", "dx", "dy", "dz", "droll", "dpitch", "dyaw", "cmd_long", "cmd_lat",
            "cmd_turn", "pitch", "roll", "bin_long", "bin_lat", "bin_turn"]
    labels = np.zeros((len(x), 3), dtype=int)
    if bins:
        for j in range(3):  # equal-count bins of each command dimension
            edges = np.quantile(z[:, j], np.linspace(0, 1, bins + 1)[1:-1])
            labels[:, j] = np.searchsorted(edges, z[:, j], side="right")
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for i in range(len(x)):
            w.writerow([episode[i], *map(repr, x[i]), *map(repr, z[i]), *labels[i]])


def import_set(dgmm, csv_path, out, how):
    cmd = [dgmm, "import", csv_path, "-o", out, "--pose-cols", "dx,dy,dz,droll,dpitch,dyaw",
           "--terrain-cols", "pitch,roll", "--episode-col", "episode", "--source", "sim"]
    if how == "continuous":
        cmd += ["--continuous-cols", "cmd_long,cmd_lat,cmd_turn"]
    elif how != 1:
        cmd += ["--command-cols", "bin_long,bin_lat,bin_turn"]
    run(cmd)


def one_seed(dgmm, seed, placements, out):
    sim = os.path.join(out, f"continuous_{seed}.h5")
    if not os.path.exists(sim):
        run([dgmm, "simulate", "--protocol", "continuous", "--seed", str(seed), "--placements",
             str(placements), "-o", sim, "--quiet"])
    with h5py.File(sim, "r") as f:
        x, z, episode = f["x"][()], f["z"][()], f["episode"][()]
    rows = {}
    for how in ["continuous", 1, 2, 3, 4]:
        path = os.path.join(out, f"seed{seed}_{how}")
        write_csv(path + ".csv", x, z, episode, None if how == "continuous" else how)
        import_set(dgmm, path + ".csv", path + ".h5", how)
        rows[how] = cv(dgmm, path + ".h5")
    return len(x), rows


def figure(dgmm, seed, out, path):
    """p(dx, dyaw | c, z) of a DGMM fitted to the continuous set of `seed`, at forward command
    0.3 and turn commands -0.4, 0, +0.4 (level ground), side by side in one PNG."""
    from PIL import Image
    model = os.path.join(out, f"seed{seed}_continuous_model.h5")
    run([dgmm, "fit", os.path.join(out, f"seed{seed}_continuous.h5"), "-o", model, "--quiet"])
    display = [] if os.environ.get("DISPLAY") else ["xvfb-run", "-a"]
    panels = []
    for turn in ["-0.4", "0", "0.4"]:
        png = os.path.join(out, f"turn_{turn}.png")
        run(display + [dgmm, "render", model, "--x-dim", "dx", "--y-dim", "dyaw", "--condition",
                       "cmd_long=0.3", "--condition", "cmd_lat=0", "--condition", f"cmd_turn={turn}",
                       "--condition", "pitch=0", "--condition", "roll=0", "--marginalise",
                       "--window=-0.05,0.4,-0.6,0.6", "--size", "420x360", "--title",
                       f"p(dx, dyaw | long 0.3, turn {turn})", "-o", png])
        panels.append(Image.open(png))
    row = Image.new("RGB", (sum(p.width for p in panels), max(p.height for p in panels)), "white")
    x = 0
    for p in panels:
        row.paste(p, (x, 0))
        x += p.width
    row.save(path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dgmm", default=os.path.join(ROOT, "build/app/dgmm"))
    ap.add_argument("--seeds", default="1", help="comma-separated simulation seeds")
    ap.add_argument("--placements", type=int, default=166)
    ap.add_argument("--out", default=os.path.join(ROOT, "out/continuous"))
    ap.add_argument("--figure", help="PNG of p(dx, dyaw | c, z) at three turn commands, from "
                    "the first seed's continuous model")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    print("| seed | samples | continuous | no command | 2 bins (8 commands) | 3 bins (27) | "
          "4 bins (64) | continuous - best binned (SE) | z |")
    print("|---|---|---|---|---|---|---|---|---|")
    for seed in [int(s) for s in args.seeds.split(",")]:
        n, rows = one_seed(args.dgmm, seed, args.placements, args.out)
        cell = {k: f"{m:.3f} ± {se:.3f} ({c:.1f} G)" for k, (m, se, c) in rows.items()}
        best = max((k for k in rows if k != "continuous"), key=lambda k: rows[k][0])
        diff = rows["continuous"][0] - rows[best][0]
        se = (rows["continuous"][1] ** 2 + rows[best][1] ** 2) ** 0.5
        print(f"| {seed} | {n} | {cell['continuous']} | {cell[1]} | {cell[2]} | {cell[3]} | "
              f"{cell[4]} | {diff:+.3f} ({se:.3f}; best: {best} bins) | {diff / se:.1f} |")
        sys.stdout.flush()
    if args.figure:
        figure(args.dgmm, int(args.seeds.split(",")[0]), args.out, args.figure)


if __name__ == "__main__":
    main()
