#!/usr/bin/env python3
"""Why sim2real misses a weak leg on the test robots: the leg's effect is a wider spread, not a
mean shift. For one pair of scripts/sim2real_robots.py (seed s: sim set seed 2s, real set seed
2s + 1, the leg's gain planted in the real set) it records the sim set's own placements (seed 2s)
again with the leg's gain at each listed value, and prints per recording
  - the spread of x about each command's mean (pooled sd per dimension),
  - the mean standing attitude z (pitch, roll),
  - the real set's mean log-likelihood under a per-command linear-Gaussian model fitted on the
    recording (x | c ~ N(B_c^T (1, pitch, roll), S_c), slopes ridged): how well a simulation at
    that value explains the real data, spread included.
The signatures of `dgmm sim2real` (lib/sim2real/signatures.h) are mean shifts; this shows what
they leave out.

With --every-leg GAINS it also records each leg in turn at each listed gain (a row per leg and
gain, named by the leg): which leg's probe, or which leg and gain of a search over every leg, a
screen of recordings at face value would pick.

Usage: scripts/sim2real_spread_probe.py [--build build] [--config datasets/robots/hexapod.json]
                                        [--seed 18000] [--leg rear_left] [--truth 0.3135]
                                        [--values 1,0.5,0.4,0.25] [--every-leg GAINS] [--out DIR]
"""
import argparse, json, os, subprocess, sys, tempfile

import h5py
import numpy as np


def record(build, cfg, seed, out):
    subprocess.run([os.path.join(build, "app", "dgmm"), "--quiet", "simulate", "--config", cfg, "--protocol",
                    "paper", "--seed", str(seed), "-o", out], check=True, stdout=subprocess.DEVNULL)


def load(path):
    f = h5py.File(path, "r")
    return f["x"][:], f["command"][:], f["z"][:]


def fit(x, c, z, ridge=5.0):
    """Per command: x ~ N(B^T (1, z), S), the slopes ridged towards 0, S with a relative floor."""
    model = {}
    for k in np.unique(c):
        X, Z = x[c == k], z[c == k]
        P = np.c_[np.ones(len(Z)), Z]
        B = np.linalg.solve(P.T @ P + np.diag([0.0] + [ridge] * Z.shape[1]), P.T @ X)
        R = X - P @ B
        S = np.cov(R.T) + 1e-6 * np.diag(np.diag(np.cov(x.T)))
        model[k] = (B, np.linalg.cholesky(S))
    return model


def loglik(model, x, c, z):
    out = []
    for xi, ci, zi in zip(x, c, z):
        B, L = model[ci]
        e = np.linalg.solve(L, xi - np.r_[1.0, zi] @ B)
        out.append(-0.5 * e @ e - np.log(np.diag(L)).sum() - 0.5 * len(xi) * np.log(2 * np.pi))
    return np.array(out)


def spread(x, c):
    return np.concatenate([x[c == k] - x[c == k].mean(0) for k in np.unique(c)]).std(0)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--config", default="datasets/robots/hexapod.json")
    ap.add_argument("--seed", type=int, default=18000)
    ap.add_argument("--leg", default="rear_left")
    ap.add_argument("--truth", type=float, default=0.3135)
    ap.add_argument("--values", default="1,0.5,0.4,0.25")
    ap.add_argument("--every-leg", default=None, metavar="GAINS",
                    help="also record every leg in turn at each of these gains (comma list; what per-leg "
                         "probes see, or a search of every leg's gain)")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    out = a.out or tempfile.mkdtemp()
    os.makedirs(out, exist_ok=True)
    base = json.load(open(a.config))
    here = os.path.dirname(a.config)
    base["mjcf_path"] = os.path.abspath(os.path.join(here, base["mjcf_path"]))

    def at(gain, seed, name, leg=a.leg):
        cfg = json.loads(json.dumps(base))
        cfg["robot"].setdefault("leg_gain", {})[leg] = gain
        path = os.path.join(out, name + ".json")
        json.dump(cfg, open(path, "w"))
        h5 = os.path.join(out, name + ".h5")
        record(a.build, path, seed, h5)
        return load(h5)

    real = at(a.truth, 2 * a.seed + 1, "real")
    values = [float(v) for v in a.values.split(",")] + [a.truth]
    print(f"{a.config}, pair seed {a.seed}: real set with {a.leg} gain {a.truth:g} (seed {2 * a.seed + 1});"
          f" recordings of seed {2 * a.seed}\n")
    print("| recording | gain | sd dx | sd dy | sd dz | sd droll | sd dpitch | sd dyaw | mean pitch | mean roll "
          "| real log-lik per sample |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    rows = [("real set", a.truth, real, None)]
    for v in values:
        rows.append(("sim" if v == 1 else ("truth" if v == a.truth else "probe"), v, at(v, 2 * a.seed, f"g{v:g}"), 1))
    for g in [float(v) for v in a.every_leg.split(",")] if a.every_leg else []:
        for leg in (l["name"] for l in base["robot"]["legs"]):
            rows.append((leg, g, at(g, 2 * a.seed, f"{leg}_g{g:g}", leg), 1))
    for name, v, (x, c, z), rec in rows:
        sd = spread(x, c)
        ll = loglik(fit(x, c, z), *real).mean() if rec else float("nan")
        print(f"| {name} | {v:.3g} | " + " | ".join(f"{s:.4f}" for s in sd) +
              f" | {z[:, 0].mean():.3f} | {z[:, 1].mean():.3f} | {ll:.1f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
