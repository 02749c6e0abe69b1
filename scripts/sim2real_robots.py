#!/usr/bin/env python3
"""sim2real on a robot described by a robot block: pairs with a planted knob the shipped octopod
never had, drawn at random from a seed range. For each seed s: the kind of planted physics is
s mod 3 (0: one leg's servo gain, named by leg name, drawn in [0.3, 0.6]; 1: a friction factor on
every geom in [0.35, 0.6]; 2: a payload of 15-30% of the robot's mass on the torso, offset
forward by up to 15% of the leg reach), the values from random.Random(s). Friction and payload are planted through the
config (robot.overwrite_physics with friction.sliding; payload). The sim set is the
nominal robot (protocol paper, seed 2 s), the real set the planted robot (seed 2 s + 1); then
`dgmm sim2real` with the sim set's own config. Prints one Markdown row per pair: what was planted,
what was named, the value and whether it lies within 25% of the truth, the values its likelihood
search found to fit the real samples as well (verdict.named[].fits_as_well), the status and wall
time.

Usage: scripts/sim2real_robots.py [--build build] [--config datasets/robots/hexapod.json]
                                  [--seeds 13000-13002] [--threads 2] [--out DIR]
                                  [--sim2real-args 'ARGS']
"""
import argparse, json, os, random, subprocess, sys, tempfile, time

import h5py

# The largest sliding friction among the geoms of the robot (the hexapod's floor: 1.0); with
# --config for another robot, pass its value with --model-friction.
MODEL_MAX_FRICTION = 1.0


def planted(seed, cfg, mass_kg, reach_m):
    """Plants the seed's physics into the config `cfg`; returns (knob that should be named, truth)."""
    r = random.Random(seed)
    kind = seed % 3
    if kind == 0:
        leg = r.choice([l["name"] for l in cfg["robot"]["legs"]])
        gain = r.uniform(0.3, 0.6)
        cfg["robot"].setdefault("leg_gain", {})[leg] = gain
        return f"actuators.{leg}.gain", gain
    if kind == 1:
        # Every geom's friction overwritten (robot.overwrite_physics); MuJoCo takes the larger of
        # the two geoms' coefficients per contact, so the factor is relative to the model's largest.
        factor = r.uniform(0.35, 0.6)
        cfg["robot"]["overwrite_physics"] = True
        cfg["friction"] = {"sliding": factor * MODEL_MAX_FRICTION, "torsional": 0.01, "rolling": 0.0001}
        return "geoms.friction_scale", factor
    share = r.uniform(0.15, 0.30)
    cfg["payload"] = {"mass_kg": share * mass_kg, "position_body_m": [r.uniform(-0.15, 0.15) * reach_m, 0, 0]}
    return "payload.mass_kg", share * mass_kg


def dgmm(build, *args):
    subprocess.run([os.path.join(build, "app", "dgmm"), "--quiet", *args], check=True, stdout=subprocess.DEVNULL)


def metadata(path, key):
    v = h5py.File(path, "r")["metadata"].attrs[key]
    return float(v.decode() if isinstance(v, bytes) else v)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--config", default="datasets/robots/hexapod.json")
    ap.add_argument("--seeds", default="13000-13002")
    ap.add_argument("--threads", default="2")
    ap.add_argument("--out", default=None)
    ap.add_argument("--sim2real-args", default="", metavar="'ARGS'",
                    help="more options of every dgmm sim2real call, e.g. '--leg-search'")
    ap.add_argument("--model-friction", type=float, default=1.0,
                    help="largest sliding friction coefficient among the model's geoms")
    a = ap.parse_args()
    global MODEL_MAX_FRICTION
    MODEL_MAX_FRICTION = a.model_friction
    lo, hi = (int(v) for v in a.seeds.split("-"))
    out = a.out or tempfile.mkdtemp()
    base = json.load(open(a.config))
    here = os.path.dirname(a.config)
    base["mjcf_path"] = os.path.abspath(os.path.join(here, base["mjcf_path"]))
    for rec in base["robot"].get("controller", {}).get("recordings", []):  # a replayed controller's files
        rec["file"] = os.path.abspath(os.path.join(here, rec["file"]))
    print(f"Robot {a.config}, seeds {lo}-{hi}, sim2real with --threads {a.threads}\n")
    print("| seed | planted | truth | named | value | within 25% | fit as well | status | wall s |")
    print("|---|---|---|---|---|---|---|---|---|")
    for seed in range(lo, hi + 1):
        d = os.path.join(out, str(seed))
        os.makedirs(d, exist_ok=True)
        nominal = os.path.join(d, "nominal.json")
        json.dump(base, open(nominal, "w"))
        sim = os.path.join(d, "sim.h5")
        dgmm(a.build, "simulate", "--config", nominal, "--protocol", "paper", "--seed", str(2 * seed), "-o", sim)
        cfg = json.loads(json.dumps(base))
        knob, truth = planted(seed, cfg, metadata(sim, "robot_mass_kg"), metadata(sim, "robot_leg_reach_m"))
        real_cfg = os.path.join(d, "real.json")
        json.dump(cfg, open(real_cfg, "w"))
        real = os.path.join(d, "real.h5")
        dgmm(a.build, "simulate", "--config", real_cfg, "--protocol", "paper", "--seed", str(2 * seed + 1), "-o", real)
        start = time.time()
        dgmm(a.build, "sim2real", "--sim", sim, "--real", real, "-o", os.path.join(d, "report"), "--no-figures",
             "--threads", a.threads, *a.sim2real_args.split())
        wall = time.time() - start
        v = json.load(open(os.path.join(d, "report", "report.json")))["verdict"]
        named = [n for n in v["named"]]
        hit = next((n for n in named if n["knob"] == knob), None)
        value = hit["value"] if hit else float("nan")
        ok = hit is not None and abs(value - truth) <= 0.25 * abs(truth)
        names = ", ".join(f"{n['knob']}" for n in named) or "-"
        span = hit.get("fits_as_well") if hit else None
        as_well = f"{span['values'][0]:.3g} to {span['values'][1]:.3g}" if span else "-"
        print(f"| {seed} | {knob} | {truth:.3g} | {names} | {value:.3g} | {'yes' if ok else 'no'} | {as_well} | "
              f"{v['status']} | {wall:.0f} |",
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
