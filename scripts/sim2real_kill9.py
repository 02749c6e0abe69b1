#!/usr/bin/python3
"""kill -9 at random moments of `dgmm sim2real` (issue #13): the output folder must hold either
the complete older result or the complete new one after every kill, and temporary folders left by
a kill must be removed by the next run.

Usage: /usr/bin/python3 scripts/sim2real_kill9.py DGMM WORKDIR [--seed N] [--kills N]
                                                   [--markdown FILE]

A small run (datasets/sim2real/sim.h5 vs slip/real.h5, figures on, --locate-only so that no
re-simulation makes it minutes long, 100 permutations) is first made twice without interruption: its duration T sets the
spread of the kill moments and its files are the "complete new" reference. The "older" result is
the null pair's report (other files, other bytes). Each trial starts from an output folder
holding the older result (even trials) or no folder (odd trials), kills the run with SIGKILL
after a delay drawn (seeded) uniformly from [0, 1.1 T] for half the trials and within 0.3 s of
the moment S the reference run's folder appeared (the swap) for the other half, and classifies
the folder:
  old     byte-identical to the older result (same file list, same SHA-256 per file)
  new     the reference's file list; identical files except the run time recorded in
          report.json ("seconds") and report.html ("Analysis took")
  absent  no folder (only allowed when the trial started without one)
  BROKEN  anything else
Temporary folders (`<out>.tmp-<pid>-<n>`) left by a kill are counted; they are left in place so
that the next trial's run must remove them, and a final uninterrupted run must leave none.
Renders need an X display: a private Xvfb is started when DISPLAY is unset.
"""
import argparse
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bad_input_battery import sha, start_xvfb  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "datasets", "sim2real")


def command(dgmm, real, out, seed):
    return [dgmm, "--quiet", "sim2real", "--sim", os.path.join(DATA, "sim.h5"), "--real",
            os.path.join(DATA, real, "real.h5"), "-o", out, "--seed", str(seed), "--locate-only",
            "--permutations", "100"]


def digest(folder):
    """file name -> comparable content (run times removed from the report)."""
    out = {}
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name)
        if name == "report.json":
            def strip(v):
                if isinstance(v, dict):
                    return {k: strip(x) for k, x in v.items() if k != "seconds"}
                if isinstance(v, list):
                    return [strip(x) for x in v]
                return v
            try:
                out[name] = json.dumps(strip(json.load(open(path))), sort_keys=True)
            except ValueError:
                out[name] = "unreadable"
        elif name == "report.html":
            out[name] = re.sub(r"Analysis took [0-9.]+ s", "", open(path, errors="replace").read())
        else:
            out[name] = sha(path)
    return out


def exact(folder):
    return {name: sha(os.path.join(folder, name)) for name in sorted(os.listdir(folder))}


def temps(work):
    return sorted(n for n in os.listdir(work) if n.startswith("out.tmp-"))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dgmm")
    ap.add_argument("workdir")
    ap.add_argument("--seed", type=int, default=9)
    ap.add_argument("--kills", type=int, default=48)
    ap.add_argument("--markdown", default="")
    a = ap.parse_args()
    dgmm, work = os.path.abspath(a.dgmm), os.path.abspath(a.workdir)
    if os.path.exists(work):
        shutil.rmtree(work)
    os.makedirs(work)
    display, xvfb = start_xvfb()
    env = dict(os.environ, DISPLAY=display)
    try:
        older = os.path.join(work, "older")
        subprocess.run(command(dgmm, "null", older, 2), env=env, check=True)
        old_exact = exact(older)
        refs, times = [], []
        swaps = []
        for i in range(2):
            ref = os.path.join(work, f"new{i}")
            t0 = time.monotonic()
            p = subprocess.Popen(command(dgmm, "slip", ref, 1), env=env,
                                 stdout=subprocess.DEVNULL)
            while p.poll() is None:  # the moment the folder is swapped in
                if not swaps[i:] and os.path.exists(ref):
                    swaps.append(time.monotonic() - t0)
                time.sleep(0.002)
            if p.returncode != 0:
                sys.exit("the uninterrupted run failed")
            times.append(time.monotonic() - t0)
            swaps[i:] = swaps[i:] or [times[-1]]
            refs.append(digest(ref))
        if refs[0] != refs[1]:
            diff = [k for k in refs[0] if refs[0].get(k) != refs[1].get(k)]
            sys.exit(f"two uninterrupted runs differ in {diff}: cannot tell a complete result")
        new_ref = refs[0]
        duration, swap = min(times), min(swaps)
        rng = random.Random(a.seed)
        out = os.path.join(work, "out")
        counts = {"old": 0, "new": 0, "absent": 0, "BROKEN": 0}
        rows, left_temps, stale_survived = [], 0, 0
        for trial in range(a.kills):
            if os.path.exists(out):
                shutil.rmtree(out)
            with_old = trial % 2 == 0
            if with_old:
                shutil.copytree(older, out)
            before = set(temps(work))
            # Half the moments anywhere in the run, half within 0.3 s of the swap.
            near_swap = (trial // 2) % 2 == 1
            delay = (rng.uniform(max(0.0, swap - 0.3), swap + 0.3) if near_swap
                     else rng.uniform(0, 1.1 * duration))
            p = subprocess.Popen(command(dgmm, "slip", out, 1), env=env,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(delay)
            killed = p.poll() is None
            if killed:
                p.send_signal(signal.SIGKILL)
            p.wait()
            if not os.path.exists(out):
                state = "absent" if not with_old else "BROKEN"
            elif with_old and exact(out) == old_exact:
                state = "old"
            elif digest(out) == new_ref:
                state = "new"
            else:
                state = "BROKEN"
            counts[state] += 1
            after = set(temps(work))
            new_temps = sorted(after - before)
            left_temps += bool(new_temps)
            # Temporaries of earlier kills must be gone once a run got as far as its output.
            survived = sorted(before & after) if state == "new" else []
            stale_survived += len(survived)
            rows.append((trial, "older result" if with_old else "no folder", delay,
                         "SIGKILL" if killed else "finished", state, ", ".join(new_temps)))
            print(f"trial {trial:2d}: start with {rows[-1][1]}, kill at {delay:.2f} s "
                  f"({rows[-1][3]}): {state}; new temporaries: {new_temps or 'none'}", flush=True)
        # A final uninterrupted run removes whatever the kills left.
        subprocess.run(command(dgmm, "slip", out, 1), env=env, check=True)
        final_ok = digest(out) == new_ref
        final_temps = temps(work)
    finally:
        if xvfb:
            xvfb.terminate()
            xvfb.wait()
    ok = counts["old"] + counts["new"] + counts["absent"]
    cmd = (f"/usr/bin/python3 scripts/sim2real_kill9.py build/app/dgmm <workdir> --seed {a.seed} "
           f"--kills {a.kills}")
    md = [f"Command: `{cmd}`; uninterrupted run {duration:.2f} s (wall), folder swapped in at "
          f"{swap:.2f} s; kill moments: half uniform in [0, {1.1 * duration:.2f}] s, half "
          f"within 0.3 s of the swap.", "",
          "| kills | ok | complete old | complete new | no folder (started without) | broken |"
          " kills that left a temporary folder | stale temporaries kept by a later run |"
          " after a final run: temporaries, result complete |",
          "|---|---|---|---|---|---|---|---|---|",
          f"| {a.kills} | {ok} | {counts['old']} | {counts['new']} | {counts['absent']} | "
          f"{counts['BROKEN']} | {left_temps} | {stale_survived} | {len(final_temps)}, "
          f"{'yes' if final_ok else 'NO'} |"]
    text = "\n".join(md) + "\n"
    print()
    print(text)
    if a.markdown:
        with open(a.markdown, "w") as f:
            f.write(text)
    return 0 if counts["BROKEN"] == 0 and not final_temps and final_ok and not stale_survived else 1


if __name__ == "__main__":
    sys.exit(main())
