#!/usr/bin/env python3
"""The spread of the torso's tilt, standing and walking, of sample sets on a slope (issue #23,
docs/sim2real.md "The ground's own knobs"): why the ground stage of `dgmm sim2real` reads the
standing tilt.

For each set, t_i = |z_i - c| - R, z = (pitch, roll), with the circle (c, R) fitted to the first
set's z (algebraic least squares; the stage fits the radius's harmonics too, so its values differ
slightly), and the spread s = mean |t_i - median t| over the first execution of each placement
(standing) and over every execution (walking), each with its SE from 200 placement resamples
(numpy seed 1). Prints s in mrad and its ratio to the first set's.

Usage: scripts/standing_tilt.py SIM.h5 REAL.h5 [REAL2.h5 ...]
"""
import sys

import h5py
import numpy as np


def load(path):
    with h5py.File(path, "r") as f:
        return f["z"][:], f["episode"][:], f["step"][:]


def circle(z):
    a = np.c_[2 * z, np.ones(len(z))]
    sol = np.linalg.lstsq(a, (z ** 2).sum(1), rcond=None)[0]
    return sol[:2], np.sqrt(sol[2] + sol[:2] @ sol[:2])


def spread(t):
    return np.mean(np.abs(t - np.median(t)))


def measure(path, centre, radius, rng, standing):
    z, episode, step = load(path)
    keep = step == 0 if standing else np.ones(len(step), bool)
    t, ep = np.linalg.norm(z[keep] - centre, axis=1) - radius, episode[keep]
    units = [np.flatnonzero(ep == e) for e in np.unique(ep)]
    draws = [spread(t[np.concatenate([units[u] for u in rng.integers(0, len(units), len(units))])]) for _ in range(200)]
    return spread(t), np.std(draws)


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    centre, radius = circle(load(sys.argv[1])[0])
    rng = np.random.default_rng(1)
    base = {s: measure(sys.argv[1], centre, radius, rng, s) for s in (True, False)}
    print(f"circle: centre ({centre[0]:.4f}, {centre[1]:.4f}) rad, radius {radius:.4f} rad\n")
    print("| set | standing s (mrad) | ratio | walking s (mrad) | ratio |\n|---|---|---|---|---|")
    for path in sys.argv[1:]:
        cells = []
        for standing in (True, False):
            s, se = measure(path, centre, radius, rng, standing)
            b, bse = base[standing]
            z = (s - b) / np.hypot(se, bse) if path != sys.argv[1] else 0.0
            cells.append(f"{1e3 * s:.1f} ± {1e3 * se:.1f} | {s / b:.2f} ({z:+.1f} SE)")
        print(f"| {path} | " + " | ".join(cells) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
