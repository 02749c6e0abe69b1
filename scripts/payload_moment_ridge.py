#!/usr/bin/env python3
"""Does the torso's posture tell a payload's mass from its offset? Records a robot with payloads of
one forward moment (mass times offset) at several masses, each as a "real" set of the paper
protocol at one seed (common random numbers), and compares each with the nominal robot's sim set
through `dgmm sim2real --locate-only`, which measures the real torso's posture against the sim set's
(on a slope by the radial part of z). Prints one Markdown row per mass: the offset, the walking
and standing posture shifts with their standard errors, and locate's status.

Usage: scripts/payload_moment_ridge.py [--build build] [--config datasets/robots/hexapod.json]
           [--moment-kg-cm 2.4] [--masses 0.6,0.8,1.2,1.6,2.4] [--sim-seed 70001] [--seed 122301]
           [--out DIR]
"""
import argparse, json, os, subprocess, sys, tempfile


def dgmm(build, *args):
    subprocess.run([os.path.join(build, "app", "dgmm"), "--quiet", *args], check=True, stdout=subprocess.DEVNULL)


def mrad(v):
    return ", ".join(f"{1e3 * x:+.1f}" for x in v)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--config", default="datasets/robots/hexapod.json")
    ap.add_argument("--moment-kg-cm", type=float, default=2.4, help="the payloads' forward moment (kg cm)")
    ap.add_argument("--masses", default="0.6,0.8,1.2,1.6,2.4", help="payload masses (kg), comma-separated")
    ap.add_argument("--sim-seed", type=int, default=70001, help="the sim set's seed (166 placements)")
    ap.add_argument("--seed", type=int, default=122301, help="every payload set's seed (78 placements)")
    ap.add_argument("--out", default=None)
    a = ap.parse_args()
    masses = [float(m) for m in a.masses.split(",")]
    if not masses or min(masses) <= 0:
        ap.error("--masses: expected positive masses in kg")
    out = a.out or tempfile.mkdtemp()
    os.makedirs(out, exist_ok=True)
    base = json.load(open(a.config))
    base["mjcf_path"] = os.path.abspath(os.path.join(os.path.dirname(a.config), base["mjcf_path"]))
    nominal = os.path.join(out, "nominal.json")
    json.dump(base, open(nominal, "w"))
    sim = os.path.join(out, "sim.h5")
    if not os.path.exists(sim):
        dgmm(a.build, "simulate", "--config", nominal, "--protocol", "paper", "--placements", "166",
             "--seed", str(a.sim_seed), "-o", sim)
    print(f"Robot {a.config}, payloads of {a.moment_kg_cm:g} kg cm ahead, sets at seed {a.seed} against the "
          f"sim set at seed {a.sim_seed}\n")
    print("| mass kg | offset cm | walking shift mrad (pitch, roll) | SE | standing shift mrad | SE | z | status |")
    print("|---|---|---|---|---|---|---|---|")
    for m in [0.0] + masses:
        cfg = json.loads(json.dumps(base))
        offset = a.moment_kg_cm / 100 / m if m > 0 else 0.0
        if m > 0:
            cfg["payload"] = {"mass_kg": m, "position_body_m": [offset, 0, 0]}
        name = f"payload_{m:g}"
        json.dump(cfg, open(os.path.join(out, name + ".json"), "w"))
        real = os.path.join(out, name + ".h5")
        dgmm(a.build, "simulate", "--config", os.path.join(out, name + ".json"), "--protocol", "paper",
             "--seed", str(a.seed), "-o", real)
        report = os.path.join(out, name)
        dgmm(a.build, "sim2real", "--sim", sim, "--real", real, "--locate-only", "--no-figures", "-o", report)
        r = json.load(open(os.path.join(report, "report.json")))
        p = r["posture"] or {}
        if not p.get("ran"):
            print(f"| {m:g} | {100 * offset:.3g} | not compared: {p.get('why_not')} | | | | | {r['verdict']['status']} |")
            continue
        w, s = p["walking"], p["standing"]
        print(f"| {m:g} | {100 * offset:.3g} | {mrad(w['shift'])} | {mrad(w['se'])} | {mrad(s['shift'])} | "
              f"{mrad(s['se'])} | {p['z_moved']:.1f} | {r['verdict']['status']} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
