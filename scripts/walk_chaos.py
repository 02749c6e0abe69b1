#!/usr/bin/env python3
"""Is a simulated robot's walk chaotic? Records the paper protocol twice with one seed, once as the
config is and once with its payload heavier by a small share of the robot's mass (at the payload's
position, the torso's origin when it has none; by default 0.03%, 1 g on a 3.2 kg robot: a change
no measurement of the real robot could see), and prints per pose axis the RMS of the two
recordings' paired difference of x over the executions' spread about their command's mean:
    ratio_j = sqrt(mean_i (x_ij - x'_ij)^2) / sd_j(x_i - mean of x over i's command).
Near 0, the two recordings pair execution by execution: dgmm sim2real's signatures (a knob's
recording less the nominal's, same seed) cancel the walk's own variation. Near sqrt(2) = 1.41,
every execution decorrelated by the change: a knob's recording then differs from the nominal's by
chance as much as by its physics, and no knob value is read from one recording
(docs/sim2real.md, "A chaotic walk"). After a fall dgmm simulate draws every later placement's
sensor noise afresh (its retries draw from the recording's stream), so when either recording fell
the script says so and the ratio may overstate the walk's chaos (not when both fell at the same
placements alike).

Usage: scripts/walk_chaos.py --config datasets/robots/planar_quadruped.json [--build build]
                             [--seed 5] [--share 0.0003]
Prints one line per config; exit 1 with one line when dgmm refuses the config or is not built.
"""
import argparse
import copy
import json
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sim2real_robots import with_absolute_paths  # noqa: E402

AXES = ("dx", "dy", "dz", "droll", "dpitch", "dyaw")


def heavier(cfg, kg):
    """A copy of `cfg` whose payload weighs `kg` more (added at the torso's origin without one)."""
    out = copy.deepcopy(cfg)
    payload = out.setdefault("payload", {"mass_kg": 0.0, "position_body_m": [0.0, 0.0, 0.0]})
    payload["mass_kg"] = payload.get("mass_kg", 0.0) + kg
    payload.setdefault("position_body_m", [0.0, 0.0, 0.0])
    return out


def paired_ratio(x, x_changed, command):
    """Per axis: RMS of x - x_changed over the spread of x about its command's mean."""
    if x.shape != x_changed.shape or len(x) < 2:
        raise ValueError(f"expected two recordings of the same executions ({len(x)} and {len(x_changed)} samples)")
    about = np.concatenate([x[command == c] - x[command == c].mean(axis=0) for c in np.unique(command)])
    return np.sqrt(((x - x_changed) ** 2).mean(axis=0)) / about.std(axis=0)


def record(dgmm, cfg, seed, where):
    path = where + ".json"
    json.dump(cfg, open(path, "w"))
    run = subprocess.run([dgmm, "--quiet", "simulate", "--config", path, "--protocol", "paper", "--seed", str(seed),
                          "-o", where + ".h5"], capture_output=True, text=True)
    if run.returncode != 0:
        raise RuntimeError((run.stderr.strip().splitlines() or ["dgmm simulate failed"])[-1])
    with h5py.File(where + ".h5", "r") as f:
        keys = list(zip(f["episode"][()], f["step"][()]))
        meta = f["metadata"].attrs
        return (dict(zip(keys, f["x"][()])), dict(zip(keys, f["command"][()])), float(meta["robot_mass_kg"]),
                int(meta["falls"]))


def in_both(x, x_changed, command):
    """The executions both recordings kept (a placement where either robot fell is left out)."""
    both = [k for k in x if k in x_changed]
    return (np.array([x[k] for k in both]), np.array([x_changed[k] for k in both]),
            np.array([command[k] for k in both]), len(x) + len(x_changed) - 2 * len(both))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", required=True)
    ap.add_argument("--build", default="build")
    ap.add_argument("--seed", type=int, default=5)
    ap.add_argument("--share", type=float, default=0.0003, help="the added mass over the robot's")
    a = ap.parse_args()
    dgmm = os.path.join(a.build, "app", "dgmm")
    try:
        if not os.access(dgmm, os.X_OK):
            raise RuntimeError(f"{dgmm} is not built")
        cfg = with_absolute_paths(json.load(open(a.config)), a.config)
        with tempfile.TemporaryDirectory() as tmp:
            x, command, mass_kg, falls = record(dgmm, cfg, a.seed, os.path.join(tmp, "as_is"))
            added_kg = a.share * mass_kg
            x_changed, _, _, falls_changed = record(dgmm, heavier(cfg, added_kg), a.seed, os.path.join(tmp, "heavier"))
        x, x_changed, command, unpaired = in_both(x, x_changed, command)
        ratio = paired_ratio(x, x_changed, command)
    except (OSError, ValueError, RuntimeError) as e:
        print(f"walk_chaos: {a.config}: {e}", file=sys.stderr)
        return 1
    cells = ", ".join(f"{name} {r:.3f}" for name, r in zip(AXES, ratio))
    print(f"{a.config}: {1000 * added_kg:.3g} g more ({a.share:g} of {mass_kg:.3g} kg), seed {a.seed}: "
          f"paired difference / spread: {cells}; "
          f"largest {ratio.max():.3f} (0: recordings pair; 1.41: every execution decorrelated)" +
          (f"; {unpaired} executions of placements where either fell left out" if unpaired else "") +
          (f"; falls {falls} and {falls_changed}: after a fall dgmm simulate draws later placements' sensor noise "
           "afresh, so the ratio may overstate the walk's chaos" if falls or falls_changed else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
