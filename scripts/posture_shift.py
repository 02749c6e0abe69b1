#!/usr/bin/env python3
"""How far the torso's posture (z: the IMU's pitch and roll at the start of each execution) of one
or more sample sets sits from a reference set's: per command the difference of mean z, averaged
over the commands both sets have (so the sets' command mixes do not matter), for every execution
and for the first of each placement (the robot standing after it was placed), with a standard
error from resampling the sets' placements (episodes; seeded). Comparable between sets of
different placements on flat ground, where z does not depend on the heading; on a slope z lies
on a circle around the posture and this mean is not the posture.

`dgmm sim2real` conditions on z and never compares z itself (docs/sim2real.md, "Evidence the
analysis does not use: the torso's posture"); this script measures what that leaves out.

Usage: scripts/posture_shift.py --reference sim.h5 SET.h5 [SET.h5 ...] [--seed 1] [--resamples 200]
"""
import argparse
import sys

import h5py
import numpy as np


def load(path):
    try:
        with h5py.File(path, "r") as f:
            labels = [l.decode() if isinstance(l, bytes) else str(l) for l in f["commands/labels"][:]]
            return {"z": f["z"][:], "step": f["step"][:], "command": f["command"][:], "episode": f["episode"][:],
                    "labels": labels}
    except (OSError, KeyError) as e:
        sys.exit(f"posture_shift: {path}: a dgmm sample set with z, step, command and episode expected ({e})")


def shift(a, b, rows_a, rows_b):
    """Mean over shared commands of mean z of a minus mean z of b, on the given rows."""
    diffs = []
    for k, label in enumerate(a["labels"]):
        if label not in b["labels"]:
            continue
        za = a["z"][rows_a][a["command"][rows_a] == k]
        zb = b["z"][rows_b][b["command"][rows_b] == b["labels"].index(label)]
        if len(za) and len(zb):
            diffs.append(za.mean(0) - zb.mean(0))
    return np.mean(diffs, 0) if diffs else np.full(2, np.nan)


def resampled_rows(s, rng):
    episodes = np.unique(s["episode"])
    pick = rng.choice(episodes, len(episodes))
    return np.concatenate([np.flatnonzero(s["episode"] == e) for e in pick])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--reference", required=True, help="the set the others are compared with (e.g. the sim set)")
    ap.add_argument("sets", nargs="+")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--resamples", type=int, default=200)
    a = ap.parse_args()
    ref = load(a.reference)
    print("| set | all executions: d pitch, d roll (mrad) | SE | first of a placement: d pitch, d roll (mrad) | SE |")
    print("|---|---|---|---|---|")
    for path in a.sets:
        s = load(path)
        rng = np.random.default_rng(a.seed)
        row = [path]
        for first in (False, True):
            keep = lambda t: (t["step"] == 0) if first else np.ones(len(t["step"]), bool)  # noqa: E731
            value = shift(s, ref, keep(s), keep(ref))
            boot = []
            for _ in range(a.resamples):
                rs, rr = resampled_rows(s, rng), resampled_rows(ref, rng)
                boot.append(shift(s, ref, rs[keep(s)[rs]], rr[keep(ref)[rr]]))
            se = np.nanstd(boot, 0)
            row += [f"{1e3 * value[0]:+.1f}, {1e3 * value[1]:+.1f}", f"{1e3 * se[0]:.1f}, {1e3 * se[1]:.1f}"]
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
