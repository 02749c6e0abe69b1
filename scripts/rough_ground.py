#!/usr/bin/env python3
"""Rough ground (issue #23): is the motion multimodal there, and does the DGMM earn its mixture?

Usage: rough_ground.py [--dgmm EXE] [--config C.json] [--seeds 103,104] [--placements 664]
                       [--bootstrap 1000] [--workdir DIR] [--json-out OUT.json]
                       [--from-json IN.json[,IN2.json...] [--add-terrain-change]] [--write-doc]
About 35 minutes per seed at --placements 664 on one core (the bootstrap test dominates); seeds
can run as separate processes and be merged with --from-json A.json,B.json --write-doc.

Per report seed s (default 103 and 104, fresh after the grid change of 2026-11-27; 101 and 102
were reported on the 0.05 m grid; seed 1 and the config's terrain seed 3 were the only ones looked
at while the ground was chosen), the octopod records `paper-830` with --placements on the
config's ground with its terrain seed set to s as well (a new ground and new placements):

  dgmm simulate --config C --protocol paper-830 --placements P --seed s   (terrain.seed = s)

then
  1. the multimodality test of scripts/multimodality.py per command, given terrain (residuals of
     the affine regression of x on z), on the planar dimensions (dx, dy, dyaw), parametric
     bootstrap with --bootstrap draws, Holm over the 26 commands at 0.05;
  2. `dgmm tune --with-terrain` (folds by episode) and `dgmm cv` at its settings: the tuned DGMM,
     the same DGMM with k = 1000 (every sample merged: one Gaussian per command), EM-BIC with
     K <= 1 (the one-Gaussian maximum likelihood fit) and K <= 5; with and without terrain (Table I
     on rough ground).
The doc section (docs/reproduction.md, "rough-ground") is written from the JSON.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import multimodality as mm  # noqa: E402


def run_json(cmd):
  out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
  return json.loads(out)


def simulate(a, seed, workdir):
  config = json.load(open(a.config))
  config["terrain"]["seed"] = seed
  path = os.path.join(workdir, f"rough_{seed}.json")
  json.dump(config, open(path, "w"), indent=1)
  out = os.path.join(workdir, f"rough_{seed}.h5")
  summary = run_json([a.dgmm, "--quiet", "simulate", "--config", path, "--protocol", "paper-830",
                      "--placements", str(a.placements), "--seed", str(seed), "-o", out, "--json"])
  return out, summary


def multimodal_given_z(path, bootstrap, seed):
  rng = np.random.default_rng(seed)
  with h5py.File(path, "r") as f:
    x, z, command = f["x"][:], f["z"][:], f["command"][:]
    names = [v.decode() for v in f["x"].attrs["names"]]
    labels = [s.decode() if isinstance(s, bytes) else str(s) for s in f["commands/labels"][:]]
  dims = [names.index(v) for v in ("dx", "dy", "dyaw")]
  p = []
  for c in range(len(labels)):
    idx = np.flatnonzero(command == c)
    data = mm.residuals(x[idx][None][:, :, dims], z[idx])
    t_obs = mm.statistic(data, 5, rng)[0][0]
    noise = rng.standard_normal((bootstrap, len(idx), len(dims)))
    t_null = mm.statistic(mm.residuals(noise, z[idx]), 5, rng)[0]
    p.append((1 + int(np.count_nonzero(t_null >= t_obs))) / (bootstrap + 1))
  reject = mm.holm(np.array(p), 0.05)
  return {"labels": labels, "p": p, "multimodal": [bool(r) for r in reject]}


def cv_rows(a, path, flags, extra, change=None):
  """The cv rows by key and the omitted ones; `change` (a dict) receives the paired terrain changes."""
  cv = run_json([a.dgmm, "--quiet", "cv", path, "--json", "--seed", "1"] + flags + extra)
  if change is not None:
    change.update(cv.get("terrain_change", {}))
  return {k: {"mean": v["mean"], "se": v["standard_error"], "components": v["mean_components"],
              "per_repeat": v["per_repeat"]} for k, v in cv["rows"].items()}, cv.get("omitted_rows", {})


def per_command_components(a, path, flags, labels):
  model = path[:-3] + "_model.h5"
  fit = run_json([a.dgmm, "--quiet", "fit", path, "--json", "--seed", "1"] + flags + ["-o", model])
  os.remove(model)
  counts = {c["label"]: c["components"] for c in fit["commands"]}
  return [counts.get(lab, 0) for lab in labels]


def one_seed(a, seed, workdir):
  path, summary = simulate(a, seed, workdir)
  test = multimodal_given_z(path, a.bootstrap, seed)
  tune = run_json([a.dgmm, "--quiet", "tune", path, "--with-terrain", "--json"])["recommended"]
  flags = ["--k", repr(tune["k"]), "--init-scale", repr(tune["init_scale"]), "--prior-count", repr(tune["prior_count"])]
  one = ["--k", "1000", "--init-scale", repr(tune["init_scale"]), "--prior-count", repr(tune["prior_count"])]
  res = {"seed": seed, "samples": summary["samples"], "falls": summary["falls"], "test": test, "tune": tune}
  res["terrain_change"] = {}
  res["tuned"], omitted = cv_rows(a, path, flags, ["--em-max-components", "5"], res["terrain_change"])
  res["one_gaussian"], _ = cv_rows(a, path, one, ["--no-em"])
  res["em_k1"], _ = cv_rows(a, path, flags, ["--em-max-components", "1"])
  res["omitted"] = omitted
  res["components"] = per_command_components(a, path, flags, test["labels"])
  return res


def add_terrain_change(a, r, workdir):
  """Table I's paired terrain change for a seed of an earlier run: its set recorded again, `dgmm cv`
  at the recorded tuned settings; the rows must come out as recorded (the same set, the same folds)."""
  path, _ = simulate(a, r["seed"], workdir)
  r["terrain_change"] = {}
  rows, _ = cv_rows(a, path, r["tune"]["flags"], ["--em-max-components", "5"], r["terrain_change"])
  for key, row in rows.items():
    if abs(row["mean"] - r["tuned"][key]["mean"]) > 1e-6 * abs(row["mean"]):
      sys.exit(f"seed {r['seed']}: {key} is {row['mean']} now, {r['tuned'][key]['mean']} when recorded: not the same set")
  return r


def paired(x, y):
  """Mean and standard error of the per-repeat difference x - y (the same folds)."""
  d = np.array(x) - np.array(y)
  return float(d.mean()), float(d.std(ddof=1) / np.sqrt(len(d))) if len(d) > 1 else 0.0


def cell(rows, key):
  v = rows.get(key)
  return f"{v['mean']:.0f} ± {v['se']:.0f}" if v else "omitted"


def mean_or_dash(values):
  return f"{values.mean():.2f}" if len(values) else "—"


def report(res):
  lines = ["Per seed, with terrain (p(x | c, z)); held-out log-likelihood (nats, total over the held-out "
           "samples, 10 folds of whole placements, 10 repeats) ± standard error:", "",
           "| seed | samples | multimodal given z (Holm) | DGMM Gaussians: those / others | tuned DGMM | "
           "one Gaussian per command (DGMM, k = 1000) | EM K = 1 | EM-BIC K ≤ 5 |",
           "|---|---|---|---|---|---|---|---|"]
  verdicts = []
  for r in res["seeds"]:
    mult = np.array(r["test"]["multimodal"])
    comps = np.array(r["components"], dtype=float)
    lines.append(f"| {r['seed']} | {r['samples']} | {int(mult.sum())} of {len(mult)} | "
                 f"{mean_or_dash(comps[mult])} / {mean_or_dash(comps[~mult])} | "
                 f"{cell(r['tuned'], 'dgmm_with_terrain')} | {cell(r['one_gaussian'], 'dgmm_with_terrain')} | "
                 f"{cell(r['em_k1'], 'em_bic_with_terrain')} | {cell(r['tuned'], 'em_bic_with_terrain')} |")
    t, o = r["tuned"]["dgmm_with_terrain"], r["one_gaussian"]["dgmm_with_terrain"]
    gain = t["mean"] - o["mean"]
    text = (f"seed {r['seed']}: the tuned DGMM (k = {r['tune']['k']:.3g}, "
            f"{r['tune']['components_per_command']:.2f} Gaussians per command) is {gain:+.0f} nats from one "
            f"Gaussian per command, {gain / max(t['se'], o['se']):+.1f} standard errors (the larger of the two)")
    ems = [v for v in (r["em_k1"].get("em_bic_with_terrain"), r["tuned"].get("em_bic_with_terrain")) if v]
    if ems:
      best = max(ems, key=lambda v: v["mean"])
      text += (f"; {t['mean'] - best['mean']:+.0f} nats, {(t['mean'] - best['mean']) / max(t['se'], best['se']):+.1f} "
               "standard errors from the better EM (K = 1 or BIC's K ≤ 5)")
    else:
      text += "; EM omitted (too few samples per command in a training fold for a full covariance)"
    verdicts.append(text)
  lines += ["", *["- " + v for v in verdicts], "",
            "Table I on rough ground (the same cross-validation, the tuned DGMM settings, EM-BIC K ≤ 5):", "",
            "| seed | DGMM with terrain | DGMM without | EM-BIC with | EM-BIC without |",
            "|---|---|---|---|---|"]
  for r in res["seeds"]:
    rows = r["tuned"]
    lines.append(f"| {r['seed']} | {cell(rows, 'dgmm_with_terrain')} | {cell(rows, 'dgmm_without_terrain')} | "
                 f"{cell(rows, 'em_bic_with_terrain')} | {cell(rows, 'em_bic_without_terrain')} |")
  lines.append("")
  for r in res["seeds"]:
    rows = r["tuned"]
    for family in ("dgmm", "em_bic"):
      w, wo = rows.get(f"{family}_with_terrain"), rows.get(f"{family}_without_terrain")
      if w and wo:
        change = r.get("terrain_change", {}).get(family)
        paired_text = (f", {change['mean'] / change['paired_standard_error']:+.1f} paired standard errors "
                       f"({change['paired_standard_error']:.0f} nats)" if change else "")
        lines.append(f"- seed {r['seed']}, {family.replace('_', '-').upper()}: conditioning on terrain changes the "
                     f"held-out log-likelihood by {w['mean'] - wo['mean']:+.0f} nats, "
                     f"{(w['mean'] - wo['mean']) / max(w['se'], wo['se']):+.1f} standard errors of the rows"
                     f"{paired_text}")
  return "\n".join(lines) + "\n"


def parse_args():
  p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
  p.add_argument("--dgmm", default=os.path.join(ROOT, "build/app/dgmm"))
  p.add_argument("--config", default=os.path.join(ROOT, "datasets/robots/rough_ground.json"))
  p.add_argument("--seeds", default="103,104")
  p.add_argument("--placements", type=int, default=664)
  p.add_argument("--bootstrap", type=int, default=1000)
  p.add_argument("--workdir")
  p.add_argument("--json-out")
  p.add_argument("--from-json")
  p.add_argument("--write-doc", action="store_true")
  p.add_argument("--add-terrain-change", action="store_true",
                 help="with --from-json: record each seed's set again and add Table I's paired terrain change")
  return p.parse_args()


def main():
  a = parse_args()
  if a.from_json:  # one JSON, or several (one per seed run) merged in order
    parts = [json.load(open(p)) for p in a.from_json.split(",")]
    res = dict(parts[0], seeds=[r for p in parts for r in p["seeds"]])
    if a.add_terrain_change:
      a.placements, a.config = res["placements"], os.path.join(ROOT, res["config"])
      workdir = a.workdir or tempfile.mkdtemp(prefix="dgmm-rough-")
      os.makedirs(workdir, exist_ok=True)
      res["seeds"] = [add_terrain_change(a, r, workdir) for r in res["seeds"]]
  else:
    workdir = a.workdir or tempfile.mkdtemp(prefix="dgmm-rough-")
    os.makedirs(workdir, exist_ok=True)
    res = {"config": os.path.relpath(os.path.abspath(a.config), ROOT), "placements": a.placements,
           "bootstrap": a.bootstrap, "seeds": [one_seed(a, int(s), workdir) for s in a.seeds.split(",")]}
  if a.json_out:  # also the merge of several --from-json runs
    mm.write(a.json_out, json.dumps(res, indent=1))
  text = report(res)
  print(text)
  if a.write_doc:
    doc = ("## Rough ground: the mixture earning its place\n\n"
           "Written by `scripts/rough_ground.py --placements 664 --write-doc --json-out docs/figures/rough_ground.json` "
           f"(seeds {', '.join(str(r['seed']) for r in res['seeds'])}, {res['placements']} placements of "
           f"`paper-830` each on `{res['config']}` with the terrain seed set to the same seed; bootstrap "
           f"{res['bootstrap']}). Seed 1 with terrain seed 3 was the only draw looked at while the ground "
           "was chosen (a first ground of 3 cm terraces and stones gave a multimodality test that rejected "
           "17 of 26 commands but a tuned DGMM of one Gaussian per command: the heavy tails were not modes "
           "that carry over to new placements; boulders the torso can hang up on make the robot either "
           "walk on or stall). Standard errors of the rows are `dgmm cv`'s (sqrt(n) × sd of the per-sample "
           "held-out log-likelihood); a change from conditioning on terrain is also given in paired standard "
           "errors (sqrt(n) × sd of the per-sample differences with and without terrain: both rows score the "
           "same held-out samples with the same folds). EM here is unregularised maximum likelihood with K "
           "chosen by BIC (or fixed at 1); the DGMM's covariances carry its prior, which is what held-out data "
           "reward when a command's outcomes split into a wide walking mode and a tight stalled one.\n\n"
           "**History of the report seeds.** Seeds 101 and 102 were reported on the ground's first grid "
           "(0.05 m; first at 332 placements, where EM's full covariance in d = 8 could not be fitted in some "
           "training folds, then at 664): all 26 and 25 of 26 commands were multimodal given z, the tuned DGMM "
           "gained 9.1 and 8.9 standard errors over one Gaussian per command, and conditioning on terrain "
           "changed the DGMM by +10.6 and +16.4 and EM-BIC by +2.4 and +1.8 paired standard errors (the last "
           "short of 2). The simulation there ran at 0.46 of the plane's speed, short of the issue's \"within "
           "2x\"; on 2026-11-27 the grid went to 0.07 m for speed alone (docs/simulation.md, \"Grid spacing and "
           "speed\"). A new grid is a new ground, so the report seeds moved to "
           f"{' and '.join(str(r['seed']) for r in res['seeds'])}, run once, with nothing else changed.\n\n" + text)
    tmp = os.path.join(ROOT, f"rough-ground-{os.getpid()}.md")
    mm.write(tmp, doc)
    subprocess.run([sys.executable, os.path.join(ROOT, "scripts/replace_section.py"),
                    os.path.join(ROOT, "docs/reproduction.md"), "rough-ground", tmp], check=True)
    os.remove(tmp)
  return 0


if __name__ == "__main__":
  sys.exit(main())
