#!/usr/bin/env python3
"""Does a robot described by a config's robot block walk as commanded? For each (slope, gait
pattern) it records the paper protocol with `dgmm simulate` and compares the mean pose change of
the pure commands (forward, lateral, turn at +-0.5) with what the gait commands: torso travel per
cycle = stride, yaw per cycle = turn_rad (docs/simulation.md, "Bring your own robot"). Prints a
Markdown table; a ratio is measured / commanded (1 = as commanded), cross-talk is the largest
off-axis travel relative to the commanded travel.

Usage: scripts/walk_table.py [--build build] [--config datasets/robots/hexapod.json]
                             [--patterns tripod,tetrapod,wave] [--slopes 0,10] [--seed 1] [--mirrored]
"""
import argparse, json, os, subprocess, sys, tempfile

import h5py
import numpy as np


class Refused(Exception):
    """dgmm refused a config (e.g. a gait pattern for another number of legs): its one-line error."""


def record(dgmm, config, out, seed):
    r = subprocess.run([dgmm, "--quiet", "simulate", "--config", config, "--protocol", "paper", "--seed", str(seed),
                        "-o", out], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        lines = [l for l in r.stderr.splitlines() if l.strip()]
        raise Refused(lines[-1] if lines else f"dgmm simulate exited with status {r.returncode}")


def load(path):
    f = h5py.File(path, "r")
    return f["commands/values"][:], f["command"][:], f["x"][:]


def text(attr):
    return attr.decode() if isinstance(attr, bytes) else attr


def pooled(a, b):
    """The samples of two recordings with the same command table."""
    return a[0], np.concatenate([a[1], b[1]]), np.concatenate([a[2], b[2]])


def rows_of(data, stride, turn, cycles):
    values, command, x = data
    out = {}
    for c, v in enumerate(values):
        m = command == c
        if not m.any() or np.count_nonzero(v) != 1:
            continue
        k = int(np.flatnonzero(v)[0])
        mean = x[m].mean(0)
        if k < 2:
            want = v[k] * stride * cycles
            ratio = mean[k] / want
            cross = abs(mean[1 - k]) / abs(want)
        else:
            want = v[2] * turn * cycles
            ratio = mean[5] / want
            cross = max(abs(mean[0]), abs(mean[1])) / (stride * cycles * abs(v[2]))
        out[("forward", "lateral", "turn")[k] + (" +" if v[k] > 0 else " -")] = (ratio, cross)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--config", default="datasets/robots/hexapod.json")
    ap.add_argument("--patterns", default="tripod,tetrapod,wave")
    ap.add_argument("--slopes", default="0,10")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--mirrored", action="store_true",
                    help="on a slope, pool the recordings at +slope and -slope: the paper protocol faces "
                         "across the slope one way only, so without this a slide downhill shows as cross-talk")
    a = ap.parse_args()
    dgmm = os.path.join(a.build, "app", "dgmm")
    try:
        base = json.load(open(a.config))
        base["robot"]
    except (OSError, ValueError, KeyError, TypeError) as e:
        print(f"walk_table.py: error: {a.config}: a simulation config with a robot block expected ({e})",
              file=sys.stderr)
        return 2
    here = os.path.dirname(a.config)
    base["mjcf_path"] = os.path.abspath(os.path.join(here, base["mjcf_path"]))
    for rec in base["robot"].get("controller", {}).get("recordings", []):  # a replayed controller's files
        rec["file"] = os.path.abspath(os.path.join(here, rec["file"]))
    tmp = tempfile.mkdtemp()
    print(f"Robot: {a.config}; paper protocol, seed {a.seed}; ratio = measured / commanded, cross = off-axis share\n")
    header = None
    refused = []  # (slope, pattern, dgmm's error): listed under the table
    for slope in [float(s) for s in a.slopes.split(",")]:
        for pattern in a.patterns.split(","):
            cfg = json.loads(json.dumps(base))
            cfg["slope_deg"] = slope
            cfg["robot"].setdefault("gait", {})["pattern"] = pattern
            path = os.path.join(tmp, f"{pattern}_{slope:g}.json")
            json.dump(cfg, open(path, "w"))
            out = os.path.join(tmp, f"{pattern}_{slope:g}.h5")
            try:
                record(dgmm, path, out, a.seed)
                data = load(out)
                if a.mirrored and slope != 0:  # the same placements with the plane tilted the other way
                    cfg["slope_deg"] = -slope
                    json.dump(cfg, open(path, "w"))
                    record(dgmm, path, out, a.seed)
                    data = pooled(data, load(out))
            except Refused as e:
                refused.append((slope, pattern, str(e)))
                continue
            # The leg reach the simulator derived from the model and the gait as it ran, defaults
            # filled in (set metadata): a config may leave out any gait length.
            meta = h5py.File(out, "r")["metadata"].attrs
            reach = float(text(meta["robot_leg_reach_m"]))
            ran = json.loads(text(meta["sim_config"]))
            g = ran["robot"]["gait"]
            stride = g["stride_m"] or g["stride_reach"] * reach
            cycles = ran["command_duration_s"] / g["period_s"]
            rows = rows_of(data, stride, g["turn_rad"], cycles)
            if header is None:
                header = sorted(rows)
                print("| slope | gait | " + " | ".join(header) + " | worst cross-talk |")
                print("|---|---|" + "---|" * (len(header) + 1))
            # A command with no kept execution (every placement fell) shows as "fell".
            cells = " | ".join(f"{rows[k][0]:.2f}" if k in rows else "fell" for k in header)
            where = f"+-{slope:g}" if a.mirrored and slope != 0 else f"{slope:g}"
            print(f"| {where} deg | {pattern} | {cells} | {max(r[1] for r in rows.values()):.2f} |")
    for slope, pattern, error in refused:
        print(f"\nrefused: {slope:g} deg, {pattern}: {error}")
    return 0 if header is not None else 2  # nothing walked: a failure


if __name__ == "__main__":
    sys.exit(main())
