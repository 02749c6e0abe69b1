#!/usr/bin/env python3
"""Writes the replayed controller of the mammal-shaped test quadruped
(datasets/robots/mammal_quadruped): a trot of its own (not dgmm's gait), foot paths turned into
joint targets by the leg's closed-form inverse kinematics, one CSV per command of the paper
protocol ({-0.5, 0, 0.5}^3 without the no-op) plus the standing recording (command 0, 0, 0),
and the config that lists them. It stands in for a user's own controller logs: "what my robot's
controller sent for each command", replayed by `dgmm simulate` (docs/simulation.md).

The trot, as a roboticist would write it for this robot:
- a wide stance: paws WIDTH outside the shoulders (abduction) and STANCE_X ahead, centring the
  support under the centre of mass (the neck puts it COM_X ahead of the trunk centre). With the
  paws under the shoulders (0.2 m apart, the trunk centre 0.33 m up) the soft servos let the
  robot topple sideways while merely standing across a 10 degree slope;
- a walking trot (duty DUTY = 0.75): each diagonal pair is alone on the ground half of the cycle,
  not 70% of it as at duty 0.65, where the robot tipped about the diagonal on the slope;
- each paw's stance path is the arc the commanded body motion (forward, sideways and turn per
  cycle) draws about its centre of rotation, so a turn turns every paw about the same point;
- a swing lifted STEP_HEIGHT with a minimum-jerk (at rest at both ends) fore-aft path;
- load feed-forward: the servos (KP) give under the paw's share of the weight, and a loaded paw
  of this knee-forward leg slides back under the body, an unloaded one forward: each step moved
  the robot about 6 mm forward, commanded or not (stepping in place crept 5 cm per 2 s). The hip
  and knee targets add that deflection back (q - J^T f / kp for the paw's share f of the weight);
- the pattern fades in and out over RAMP periods (smoothstep) and the robot stands still for
  the last REST s of a command, so the next command starts from rest.
Forward and backward, left and right are the same trot mirrored.

Usage: scripts/make_mammal_replay.py [--out datasets/robots/mammal_quadruped]
"""
import argparse, itertools, json, math, os

THIGH, SHANK = 0.2, 0.2                                  # m, as in mammal_quadruped.xml
HIPS = {"front_left": (0.2, 0.1), "front_right": (0.2, -0.1),
        "hind_left": (-0.2, 0.1), "hind_right": (-0.2, -0.1)}
HIP_Z = -0.04                                            # shoulder below the trunk centre
PHASE = {"front_left": 0.0, "hind_right": 0.0, "front_right": 0.5, "hind_left": 0.5}  # trot
PERIOD, DUTY, DURATION, RATE = 0.5, 0.75, 2.0, 100       # s, share, s, rows per s
STRIDE, TURN = 0.12, 0.4                                 # m and rad per cycle at |command| = 1
HEIGHT = 0.33                                            # trunk centre above the ground, m
WIDTH = 0.06                                             # paw outside the shoulder, m
COM_X = 0.0138                                           # centre of mass ahead of the trunk centre (the neck), m
STANCE_X = COM_X                                         # paw ahead of the shoulder, m
STEP_HEIGHT = 0.05                                       # m
RAMP = 0.5                                               # fade in / out, periods
REST = 0.1                                               # s standing still at the end of a command
KP, WEIGHT = 120.0, 8.4 * 9.81                           # servo gain (N m/rad) and robot weight (N), as in the MJCF
LOAD_RAMP = 0.2                                          # share of the stance over which a paw takes or sheds its load
LIMITS = [(-30, 30), (-60, 60), (-150, -5)]              # abduction, hip, knee range (degrees), as in the MJCF


def leg_angles(x, y, z):
    """Abduction, hip, knee (rad) placing the paw at (x, y, z) from the shoulder (z < 0)."""
    abduction = math.atan2(y, -z)
    d = math.hypot(y, z)                                 # shoulder to paw in the leg's plane
    r2 = x * x + d * d
    c = max(-1.0, min(1.0, (r2 - THIGH ** 2 - SHANK ** 2) / (2 * THIGH * SHANK)))
    knee = -math.acos(c)                                 # the knee points forward
    hip = math.atan2(x, d) - math.atan2(SHANK * math.sin(knee), THIGH + SHANK * math.cos(knee))
    return abduction, hip, knee


def paw(abduction, hip, knee):
    """Forward kinematics: the paw from the shoulder (MJCF axes: abduction about x, hip and knee about -y)."""
    x = THIGH * math.sin(hip) + SHANK * math.sin(hip + knee)
    d = THIGH * math.cos(hip) + SHANK * math.cos(hip + knee)
    return x, d * math.sin(abduction), -d * math.cos(abduction)


def loaded(q, force):
    """Servo targets that hold the hip and knee at q while the ground pushes the paw with `force`
    (N, shoulder frame): q - J^T f / kp, the deflection the servos would otherwise give under load.
    The abduction is left as it is: its give only narrows the stance a little, and pre-compensating
    it pushed each diagonal pair's paws outwards, a yaw couple that turned the robot."""
    h = 1e-6
    p0 = paw(*q)
    out = []
    for j in range(3):
        dq = list(q)
        dq[j] += h
        col = [(a - b) / h for a, b in zip(paw(*dq), p0)]
        out.append(q[j] - (j > 0) * sum(c * f for c, f in zip(col, force)) / KP)
    return out


def smoothstep(s):
    s = max(0.0, min(1.0, s))
    return s * s * (3 - 2 * s)


def stance_point(p, v, w, tau):
    """Where a ground point at body-frame p (mid-stance) is tau seconds later, in the body frame,
    while the body moves with body-frame velocity v (m/s) and yaw rate w (rad/s): a rotation by
    -w tau about the centre of rotation (a translation by -v tau when w = 0)."""
    if abs(w) < 1e-9:
        return p[0] - v[0] * tau, p[1] - v[1] * tau
    cx, cy = -v[1] / w, v[0] / w                         # centre of rotation, body frame
    a = -w * tau
    dx, dy = p[0] - cx, p[1] - cy
    return cx + math.cos(a) * dx - math.sin(a) * dy, cy + math.sin(a) * dx + math.cos(a) * dy


def envelope(t):
    """The pattern's strength at time t of a command: a smoothstep in, a smoothstep out, then REST s still."""
    return smoothstep(min(t, DURATION - REST - t) / (RAMP * PERIOD))


def foot(u, p, v, w, lift):
    """Paw (body frame, z from the ground) at share u of its cycle: stance for u in [0, DUTY),
    centred on p, then a lifted swing back to the stance's start."""
    u -= math.floor(u)
    ts = DUTY * PERIOD                                   # stance time
    if u < DUTY:
        x, y = stance_point(p, v, w, (u / DUTY - 0.5) * ts)
        return x, y, 0.0
    s = (u - DUTY) / (1 - DUTY)
    x0, y0 = stance_point(p, v, w, 0.5 * ts)             # lift-off
    x1, y1 = stance_point(p, v, w, -0.5 * ts)            # touch-down
    k = s * s * s * (10 - 15 * s + 6 * s * s)            # minimum jerk: at rest at both ends
    return x0 + (x1 - x0) * k, y0 + (y1 - y0) * k, lift * math.sin(math.pi * s) ** 2


def load_share(u):
    """How much of a stance share of the weight the paw carries at share u of its cycle (0 in swing,
    1 in mid-stance, smooth ramps at touch-down and lift-off)."""
    u -= math.floor(u)
    if u >= DUTY:
        return 0.0
    return smoothstep(min(u, DUTY - u) / (LOAD_RAMP * DUTY))


def targets(command, t):
    e = envelope(t) if any(command) else 0.0
    v = (e * STRIDE * command[0] / PERIOD, e * STRIDE * command[1] / PERIOD)   # body velocity, m/s
    w = e * TURN * command[2] / PERIOD                                      # yaw rate, rad/s
    # Each paw's share of the weight: the paws in stance (all four when standing), front paws a
    # little more (the centre of mass is COM_X ahead of the trunk centre).
    shares = {leg: 1 - e + e * load_share(t / PERIOD - PHASE[leg]) for leg in HIPS}
    shares = {leg: a * (1 + math.copysign(COM_X, HIPS[leg][0]) / abs(HIPS[leg][0])) for leg, a in shares.items()}
    total = sum(shares.values())
    row = []
    for leg, (hx, hy) in HIPS.items():
        p = (hx + STANCE_X, hy + math.copysign(WIDTH, hy))  # stance paw: STANCE_X ahead, WIDTH outside
        x, y, z = foot(t / PERIOD - PHASE[leg], p, v, w, e * STEP_HEIGHT)
        q = leg_angles(x - hx, y - hy, z - HEIGHT - HIP_Z)
        row += loaded(q, (0.0, 0.0, WEIGHT * shares[leg] / total))
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="datasets/robots/mammal_quadruped")
    a = ap.parse_args()
    write(a.out)


def write(out):
    os.makedirs(os.path.join(out, "replay"), exist_ok=True)
    header = ["t"] + [f"{leg}_{j}_servo" for leg in HIPS for j in ("abduction", "hip", "knee")]
    recordings = []
    levels = (-0.5, 0.0, 0.5)
    for c in [(0.0, 0.0, 0.0)] + [c for c in itertools.product(levels, repeat=3) if any(c)]:
        name = "stand" if not any(c) else "_".join(f"{v:+.1f}".replace("+", "p").replace("-", "m").replace(".", "") for v in c)
        rows = [header]
        n = int(round(DURATION * RATE)) if any(c) else 1
        for i in range(n + 1):
            t = i / RATE if any(c) else i * PERIOD
            q = targets(c, t)
            for k, v in enumerate(q):
                lo, hi = LIMITS[k % 3]
                if not lo <= math.degrees(v) <= hi:
                    raise SystemExit(f"{name} t={t:.2f}: {header[k + 1]} at {math.degrees(v):.1f} deg, outside [{lo}, {hi}]")
            rows.append([f"{t:.3f}"] + [f"{v:.6f}" for v in q])
        path = os.path.join("replay", name + ".csv")
        with open(os.path.join(out, path), "w") as f:
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
    with open(os.path.join(out, "mammal_quadruped.json"), "w") as f:
        json.dump(config, f, indent=2)
        f.write("\n")
    print(f"wrote {len(recordings)} recordings and mammal_quadruped.json to {out}")


if __name__ == "__main__":
    main()
