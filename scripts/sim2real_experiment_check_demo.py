#!/usr/bin/env python3
"""Reruns `dgmm sim2real` on battery pairs whose verdict had a tie and prints the experiment check
of each tie as a markdown table (docs/sim2real.md, "The experiment check").

The battery's recorded sets and signature cache (scripts/sim2real_battery.py --keep) are copied
into WORK and converted to the current file format (`dgmm upgrade`, when they are version 1), so
the battery's folder is only read; the analyses then take their signatures from that cache.

  scripts/sim2real_experiment_check_demo.py --battery-out out/report --seeds 5018,5029,5032 \
      --work /tmp/s2r-demo
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def upgrade(dgmm, src, dst):
    """Copies src to dst, converting a version-1 file (a version-2 one is copied as is)."""
    if os.path.exists(dst):
        return
    tmp = dst + ".tmp.h5"
    r = subprocess.run([dgmm, "upgrade", src, "-o", tmp], capture_output=True, text=True)
    if r.returncode == 0 and os.path.exists(tmp):
        os.replace(tmp, dst)
    else:
        shutil.copyfile(src, dst)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--battery-out", required=True, help="OUT of scripts/sim2real_battery.py --keep")
    ap.add_argument("--seeds", required=True, help="comma-separated pair seeds (built-in robot)")
    ap.add_argument("--work", required=True, help="scratch folder (copies, analyses)")
    ap.add_argument("--dgmm", default=os.path.join(ROOT, "build", "app", "dgmm"))
    ap.add_argument("--config", default=os.path.join(ROOT, "datasets", "robots", "default.json"))
    args = ap.parse_args()
    os.makedirs(args.work, exist_ok=True)
    cache = os.path.join(args.work, "xdg-cache", "dgmm")
    os.makedirs(cache, exist_ok=True)
    src_cache = os.path.join(args.battery_out, "xdg-cache", "dgmm")
    for name in sorted(os.listdir(src_cache)) if os.path.isdir(src_cache) else []:
        if name.endswith(".h5"):
            upgrade(args.dgmm, os.path.join(src_cache, name), os.path.join(cache, name))
    sim = os.path.join(args.work, "scorpion_sim.h5")
    upgrade(args.dgmm, os.path.join(args.battery_out, "cache", "scorpion_sim_p166.h5"), sim)
    rows = []
    for seed in [s.strip() for s in args.seeds.split(",") if s.strip()]:
        real = os.path.join(args.work, f"real{seed}.h5")
        upgrade(args.dgmm, os.path.join(args.battery_out, "pairs", seed, "real.h5"), real)
        out = os.path.join(args.work, seed)
        shutil.rmtree(out, ignore_errors=True)
        env = dict(os.environ, XDG_CACHE_HOME=os.path.join(args.work, "xdg-cache"))
        t = time.time()
        r = subprocess.run(["nice", "-n", "5", args.dgmm, "sim2real", "--sim", sim, "--real", real,
                            "--sim-config", args.config, "-o", out, "--no-figures"],
                           env=env, capture_output=True, text=True)
        wall = time.time() - t
        if r.returncode != 0:
            print(f"pair {seed}: dgmm sim2real failed: {r.stderr.strip()}", file=sys.stderr)
            continue
        with open(os.path.join(out, "report.json")) as f:
            rep = json.load(f)
        recordings = (rep.get("knobs") or {}).get("recordings") or {}
        for tie in rep["verdict"]["ties"]:
            e = tie["experiment"]
            sim_ = e.get("simulation") or {}
            vals = ", ".join(f"{k} {v:.3g}" for k, v in zip(sim_.get("knobs", []), sim_.get("values", [])))
            rows.append([seed, " / ".join(tie["families"]), (e["commands"] or ["-"])[0],
                         (e["terrain"] or ["-"])[0].split(":")[0], str(e["executions"]),
                         f"{e['separation_per_execution']:.2f}",
                         vals or "-",
                         str(sim_.get("executions", "-")),
                         f"{sim_['spread_scale']:.2f}" if sim_ else "-",
                         f"{sim_['separation_per_execution']:.2f}" if sim_ else "-",
                         f"{sim_['z']:.1f}" if sim_ else "-",
                         f"{sim_['p_value']:.4f}" if sim_ else "-",
                         str(sim_.get("executions_needed", "-")),
                         {True: "yes", False: "no", None: "not checked"}[e.get("confirmed")]
                         + ("" if e.get("checked_by_simulation") else f" ({e.get('not_checked_because')})"),
                         f"{sim_['seconds']:.1f} s" if sim_ else "-",
                         f"{recordings.get('signatures', '?')}", f"{wall:.0f} s"])
    head = ["pair", "tie", "command", "terrain", "proposed executions", "proposed d2", "simulated values",
            "executions simulated", "spread scale", "simulated d2", "z at proposed", "p", "needed by sim",
            "confirmed", "check wall", "signature sims", "analysis wall"]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for r in rows:
        print("| " + " | ".join(r) + " |")


if __name__ == "__main__":
    main()
