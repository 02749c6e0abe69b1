#!/usr/bin/env python3
"""Writes the replayed controller of the mammal-shaped test quadruped
(datasets/robots/mammal_quadruped): a trot of its own (not dgmm's gait), foot paths turned into
joint targets by the leg's closed-form inverse kinematics, one CSV per command of the paper
protocol ({-0.5, 0, 0.5}^3 without the no-op) plus the standing recording (command 0, 0, 0),
and the config that lists them. It stands in for a user's own controller logs: "what my robot's
controller sent for each command", replayed by `dgmm simulate` (docs/simulation.md).

Usage: scripts/make_mammal_replay.py [--out datasets/robots/mammal_quadruped]
"""
import argparse, itertools, json, math, os

THIGH, SHANK = 0.2, 0.2                                  # m, as in mammal_quadruped.xml
HIPS = {"front_left": (0.2, 0.1), "front_right": (0.2, -0.1),
        "hind_left": (-0.2, 0.1), "hind_right": (-0.2, -0.1)}
HIP_Z = -0.04                                            # shoulder below the trunk centre
PHASE = {"front_left": 0.0, "hind_right": 0.0, "front_right": 0.5, "hind_left": 0.5}  # trot
PERIOD, DUTY, DURATION, RATE = 0.5, 0.65, 2.0, 100       # s, share, s, rows per s
STRIDE, TURN, LIFT, HEIGHT = 0.12, 0.4, 0.035, 0.33      # m and rad per cycle at |command| = 1; m; m


def leg_angles(x, y, z):
    """Abduction, hip, knee (rad) placing the paw at (x, y, z) from the shoulder (z < 0)."""
    abduction = math.atan2(y, -z)
    d = math.hypot(y, z)                                 # shoulder to paw in the leg's plane
    r2 = x * x + d * d
    c = max(-1.0, min(1.0, (r2 - THIGH ** 2 - SHANK ** 2) / (2 * THIGH * SHANK)))
    knee = -math.acos(c)                                 # the knee points forward
    hip = math.atan2(x, d) - math.atan2(SHANK * math.sin(knee), THIGH + SHANK * math.cos(knee))
    return abduction, hip, knee


def foot_offset(u, d):
    """Paw offset at share u of its own cycle: stance +d/2 -> -d/2, then a lifted return."""
    u -= math.floor(u)
    if u < DUTY:
        s = u / DUTY
        return 0.5 * d[0] * (1 - 2 * s), 0.5 * d[1] * (1 - 2 * s), 0.0
    s = (u - DUTY) / (1 - DUTY)
    k = -math.cos(math.pi * s)
    return 0.5 * d[0] * k, 0.5 * d[1] * k, LIFT * math.sin(math.pi * s)


def targets(command, t):
    ramp = 0.1 * PERIOD
    envelope = max(0.0, min(1.0, min(t, DURATION - t) / ramp)) if any(command) else 0.0
    row = []
    for leg, (hx, hy) in HIPS.items():
        px, py = hx, hy                                  # stance paw under the shoulder
        d = (DUTY * (STRIDE * command[0] - TURN * command[2] * py), DUTY * (STRIDE * command[1] + TURN * command[2] * px))
        ox, oy, oz = foot_offset(t / PERIOD - PHASE[leg], d)
        row += leg_angles(envelope * ox, envelope * oy, -HEIGHT - HIP_Z + envelope * oz)
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="datasets/robots/mammal_quadruped")
    a = ap.parse_args()
    os.makedirs(os.path.join(a.out, "replay"), exist_ok=True)
    header = ["t"] + [f"{leg}_{j}_servo" for leg in HIPS for j in ("abduction", "hip", "knee")]
    recordings = []
    levels = (-0.5, 0.0, 0.5)
    for c in [(0.0, 0.0, 0.0)] + [c for c in itertools.product(levels, repeat=3) if any(c)]:
        name = "stand" if not any(c) else "_".join(f"{v:+.1f}".replace("+", "p").replace("-", "m").replace(".", "") for v in c)
        rows = [header]
        n = int(round(DURATION * RATE)) if any(c) else 1
        for i in range(n + 1):
            t = i / RATE if any(c) else i * PERIOD
            rows.append([f"{t:.3f}"] + [f"{v:.6f}" for v in targets(c, t)])
        path = os.path.join("replay", name + ".csv")
        with open(os.path.join(a.out, path), "w") as f:
            f.write("\n".join(",".join(r) for r in rows) + "\n")
        recordings.append({"command": list(c), "file": path})
    legs = [{"name": leg, "joints": [f"{leg}_abduction", f"{leg}_hip", f"{leg}_knee"], "foot": {"geom": f"{leg}_paw"},
             "side": "left" if hy > 0 else "right"} for leg, (hx, hy) in HIPS.items()]
    config = {"slope_deg": 0.0, "mjcf_path": "mammal_quadruped.xml", "timestep_s": 0.002,
              "command_duration_s": DURATION, "settle_duration_s": 0.5,
              "robot": {"torso_body": "trunk", "floor_geom": "ground", "forward_axis": [1, 0, 0], "legs": legs,
                        # The gait block only sets what a replay still needs: the standing height
                        # the robot is placed at, and the period, stride and turn that
                        # scripts/walk_table.py compares the walk with.
                        "gait": {"pattern": "trot", "period_s": PERIOD, "stride_m": STRIDE, "turn_rad": TURN,
                                 "stance_height_m": HEIGHT},
                        "controller": {"type": "replay", "signal": "position", "recordings": recordings}}}
    with open(os.path.join(a.out, "mammal_quadruped.json"), "w") as f:
        json.dump(config, f, indent=2)
        f.write("\n")
    print(f"wrote {len(recordings)} recordings and mammal_quadruped.json to {a.out}")


if __name__ == "__main__":
    main()
