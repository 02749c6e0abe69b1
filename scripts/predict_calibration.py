#!/usr/bin/env python3
"""Are `dgmm predict`'s regions honest? Trains a DGMM (and a one-Gaussian-per-command baseline)
on a shipped set, records multi-command trajectories the models never saw (`dgmm simulate
--protocol trajectories`, same robot and slope), predicts each episode's command sequence from its
start, conditioning every step on the terrain (IMU pitch, roll) recorded before that step, and
counts how often the episode's true end point after k commands falls inside the predicted 50% and
90% regions, for k = 1 .. horizon. Regions: ellipses in (x, y) holding 50% / 90% of the predicted
trajectories (the Mahalanobis distance of the outcome under the predicted mean and covariance,
compared with the same quantile of the predicted trajectories' own distances), planar SE(2)
composition of (dx, dy, dyaw) in the slope plane. Prints a Markdown table.

With --persistence each model is also run with the persistence of its deviations from step to step
estimated from its own training set (`dgmm predict --persistence`, lib/predict/step_persistence.h).
With --calibrate-seed S every variant is also run with its regions calibrated on 300 held-out
trajectory episodes recorded with seed S (`dgmm predict --calibrate`, lib/predict/region_calibration.h);
a table of the 90% regions' areas shows what each variant pays for its coverage.

Usage: scripts/predict_calibration.py [--build build] [--train datasets/scorpion_sim_830.h5 | trajectories]
                                      [--train-seed 6] [--seeds 5] [--horizon 10] [--trajectories 2000]
                                      [--persistence] [--calibrate-seed 7]
--train trajectories trains on 300 trajectory episodes of its own (seed --train-seed), recorded
like the held-out ones: every step a fresh command, as a planner would send them.
Seeds: develop on --seeds 5, report once on a range not looked at before (docs/prediction.md).
"""
import argparse, os, subprocess, sys, tempfile

import numpy as np


def load_module(build):
    sys.path.insert(0, os.path.join(build, "python"))
    import dgmm
    return dgmm


def simulate(build, horizon, seed, path, placements=0):
    subprocess.run([os.path.join(build, "app", "dgmm"), "--quiet", "simulate", "--protocol", "trajectories",
                    "--executions", str(horizon), "--placements", str(placements), "--seed", str(seed), "-o", path],
                   check=True, stdout=subprocess.DEVNULL)


def compose(x, episode_rows):
    """True planar end poses after each step of an episode: SE(2) composition of (dx, dy, dyaw)."""
    px = py = yaw = 0.0
    out = []
    for dx, dy, dyaw in x[episode_rows][:, [0, 1, 5]]:
        px, py = px + np.cos(yaw) * dx - np.sin(yaw) * dy, py + np.sin(yaw) * dx + np.cos(yaw) * dy
        yaw += dyaw
        out.append((px, py))
    return np.array(out)


def coverage(dgmm, model, persistence, calibration, s, episodes, horizon, trajectories, seed):
    """Counts of outcomes inside the predicted 50% and 90% regions per horizon (predict's region_r2:
    ellipses in (x, y) about the trajectories' mean), the regions' areas (m^2) per horizon, and the
    number of episodes."""
    x, z, command, episode, step = s.x, s.z, s.command, s.episode, s.step
    inside = np.zeros((horizon, 2))
    areas = [[] for _ in range(horizon)]
    used = 0
    for e in episodes:
        rows = np.flatnonzero(episode == e)
        rows = rows[np.argsort(step[rows])][:horizon]
        if len(rows) < horizon:
            continue
        used += 1
        truth = compose(x, rows)
        p = dgmm.predict(model, [int(c) for c in command[rows]], terrain=z[rows], trajectories=trajectories,
                         seed=seed + int(e), pose_dims=["dx", "dy", "dyaw"], persistence=persistence,
                         calibration=calibration)
        assert list(p["region_levels"]) == [0.5, 0.9]
        for k in range(horizon):
            cov = p["covariance"][k][:2, :2]
            t = truth[k] - p["mean"][k][:2]
            d2_truth = t @ np.linalg.solve(cov, t)
            inside[k] += d2_truth <= p["region_r2"][k]
            areas[k].append(np.pi * p["region_r2"][k][1] * np.sqrt(np.linalg.det(cov)))
    return inside, np.array([np.median(a) for a in areas]), used


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default="build")
    ap.add_argument("--train", default="datasets/scorpion_sim_830.h5")
    ap.add_argument("--train-seed", type=int, default=6)
    ap.add_argument("--seeds", default="5", help="trajectory seeds, e.g. 5 or 200-203")
    ap.add_argument("--horizon", type=int, default=10)
    ap.add_argument("--trajectories", type=int, default=2000)
    ap.add_argument("--persistence", action="store_true",
                    help="also predict with the persistence of deviations estimated from the training set")
    ap.add_argument("--calibrate-seed", type=int, default=None,
                    help="also predict with regions calibrated (predict --calibrate) on 300 held-out trajectory "
                         "episodes recorded with this seed")
    a = ap.parse_args()
    dgmm = load_module(a.build)
    tmp = tempfile.mkdtemp()
    train_path = a.train
    if a.train == "trajectories":
        train_path = os.path.join(tmp, "train.h5")
        simulate(a.build, a.horizon, a.train_seed, train_path, placements=300)
    train = dgmm.SampleSet.read(train_path)
    fitted = {"DGMM": dgmm.DGMM(seed=1).fit(train).model_,
              "one Gaussian": dgmm.EMMixture(n_components=1, seed=1).fit(train).model_}
    models = {name: (m, None) for name, m in fitted.items()}
    if a.persistence:
        for name, m in fitted.items():
            p = dgmm.estimate_persistence(m, train)
            print(f"{name}: persistence a = {np.round(p['shared'], 2).tolist()}, phi = {np.round(p['decay'], 2).tolist()} "
                  f"({', '.join(train.x_names)})")
            models[name + " + persistence"] = (m, p)
    calibrations = {name: None for name in models}
    if a.calibrate_seed is not None:
        path = os.path.join(tmp, "calibration.h5")
        simulate(a.build, a.horizon, a.calibrate_seed, path, placements=300)
        held_out = dgmm.SampleSet.read(path)
        for name, (m, p) in list(models.items()):
            calibrations[name + " + calibration"] = dgmm.calibrate_regions(
                m, held_out, trajectories=a.trajectories, seed=1, pose_dims=["dx", "dy", "dyaw"], persistence=p)
            models[name + " + calibration"] = (m, p)
    lo, _, hi = a.seeds.partition("-")
    seeds = range(int(lo), int(hi or lo) + 1)
    totals = {name: np.zeros((a.horizon, 2)) for name in models}
    areas = {name: [] for name in models}
    episodes_used = 0
    for seed in seeds:
        if seed in (a.train_seed if a.train == "trajectories" else None, a.calibrate_seed):
            sys.exit("--seeds must not include --train-seed or --calibrate-seed")
        path = os.path.join(tmp, f"trajectories_{seed}.h5")
        simulate(a.build, a.horizon, seed, path)
        s = dgmm.SampleSet.read(path)
        for name, (model, persistence) in models.items():
            inside, area, used = coverage(dgmm, model, persistence, calibrations[name], s, np.unique(s.episode), a.horizon,
                                          a.trajectories, 1000 * seed)
            totals[name] += inside
            areas[name].append(area)
        episodes_used += used
    trained_on = f"300 trajectory episodes (seed {a.train_seed})" if a.train == "trajectories" else a.train
    print(f"Trained on {trained_on}; {episodes_used} held-out episodes of {a.horizon} commands (trajectory seeds "
          f"{a.seeds}), {a.trajectories} predicted trajectories each; share of true end points inside the "
          f"predicted region after k commands" +
          (f"; calibration: 300 held-out episodes (seed {a.calibrate_seed})" if a.calibrate_seed is not None else "") + "\n")
    names = list(models)
    for level, column in (("90%", 1), ("50%", 0)):
        print(f"Share of outcomes inside the {level} regions:\n")
        print("| k | " + " | ".join(names) + " |")
        print("|---|" + "---|" * len(names))
        for k in range(a.horizon):
            print(f"| {k + 1} | " + " | ".join(f"{totals[n][k, column] / episodes_used:.2f}" for n in names) + " |")
        print()
    print("Median area of the 90% regions (m^2; each held-out seed's median, averaged over the seeds):\n")
    print("| k | " + " | ".join(names) + " |")
    print("|---|" + "---|" * len(names))
    for k in range(a.horizon):
        print(f"| {k + 1} | " + " | ".join(f"{np.mean([ar[k] for ar in areas[n]]):.3f}" for n in names) + " |")


if __name__ == "__main__":
    main()
