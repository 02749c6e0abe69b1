#!/usr/bin/env python3
"""How well a real set can tell higher boulders from the simulated ones (issue #23): the robot's
hang-up share on rough ground, real against simulated, with placements as units.

The ground's own knobs (terrain.stones.height_scale) are not named by `dgmm sim2real`: higher
boulders change how often the robot hangs up more than where it goes on average
(docs/sim2real.md, "Rough ground"). This script measures how much evidence a real set holds about
that: it records a "sim" set of the nominal ground and "real" sets at boulder heights scaled by
the given factors (each at its own seed: its own places), and for each real set prints

    hang-up share = share of the samples of moving commands (the command's median planar travel in
                    the sim set above a quarter of the largest command's: turns on the spot are
                    left out whatever the robot's size) that travel less than half that median,
    z = (share_real - share_sim) / SE,  SE from the per-placement shares of both sets,

so the placements, not the samples, are the units (a placement on a boulder hangs up in most of
its executions).

Usage: scripts/rough_ground_hangups.py [--build build] [--config datasets/robots/rough_ground.json]
          [--sim-seed 100] [--placements 78] [--real 1.0:611,1.5:610] [--real-placements 78]
          [--out DIR]
Sets already in --out (same factor, seed and placements) are read back, not recorded again.
"""
import argparse, copy, json, os, subprocess

import h5py
import numpy as np


def record(build, base_cfg, factor, seed, placements, out):
    path = os.path.join(out, f"stones{factor:g}_seed{seed}_p{placements}.h5")
    if os.path.exists(path):
        return path
    cfg = copy.deepcopy(base_cfg)
    cfg["terrain"]["stones"]["height_m"] *= factor
    cfg_path = path[:-3] + ".json"
    with open(cfg_path, "w") as f:
        json.dump(cfg, f)
    subprocess.run([os.path.join(build, "app", "dgmm"), "--quiet", "simulate", "--config", cfg_path, "--protocol",
                    "paper", "--placements", str(placements), "--seed", str(seed), "-o", path], check=True,
                   stdout=subprocess.DEVNULL)
    return path


def load(path):
    with h5py.File(path, "r") as f:
        labels = [s.decode() for s in f["commands/labels"][:]]
        return f["x"][:], [labels[c] for c in f["command"][:]], f["episode"][:]


def median_travel(data):
    x, cmd, _ = data
    travel = np.hypot(x[:, 0], x[:, 1])
    return {c: float(np.median(travel[[i for i, ci in enumerate(cmd) if ci == c]])) for c in set(cmd)}


def per_placement_hangups(data, reach):
    x, cmd, ep = data
    r = np.array([reach.get(c, 0.0) for c in cmd])
    moving = r > 0.25 * max(reach.values())
    hung = (np.hypot(x[:, 0], x[:, 1]) < 0.5 * r)[moving]
    ep = ep[moving]
    return np.array([hung[ep == u].mean() for u in np.unique(ep)])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--config", default="datasets/robots/rough_ground.json")
    ap.add_argument("--sim-seed", type=int, default=100)
    ap.add_argument("--placements", type=int, default=78)
    ap.add_argument("--real", default="1.0:611,1.5:610", help="factor:seed,... (boulder height factor, real seed)")
    ap.add_argument("--real-placements", type=int, default=78)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    with open(a.config) as f:
        base = json.load(f)
    if "stones" not in base.get("terrain", {}):
        raise SystemExit(f"{a.config}: terrain.stones expected (the boulders whose height is scaled)")
    sim = load(record(a.build, base, 1.0, a.sim_seed, a.placements, a.out))
    reach = median_travel(sim)
    s = per_placement_hangups(sim, reach)
    print(f"sim set: nominal boulders, seed {a.sim_seed}, {a.placements} placements: "
          f"hang-up share {s.mean():.3f} ± {s.std(ddof=1) / np.sqrt(len(s)):.3f}\n")
    print("| real boulders | seed | placements | hang-up share ± SE | minus sim | z |")
    print("|---|---|---|---|---|---|")
    for item in a.real.split(","):
        factor, seed = item.split(":")
        path = record(a.build, base, float(factor), int(seed), a.real_placements, a.out)
        r = per_placement_hangups(load(path), reach)
        se_r = r.std(ddof=1) / np.sqrt(len(r))
        se = np.sqrt(se_r ** 2 + s.var(ddof=1) / len(s))
        d = r.mean() - s.mean()
        print(f"| x{float(factor):g} | {seed} | {a.real_placements} | {r.mean():.3f} ± {se_r:.3f} | {d:+.3f} | "
              f"{d / se:+.2f} |")


if __name__ == "__main__":
    main()
