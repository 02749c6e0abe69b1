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

Usage: scripts/predict_calibration.py [--build build] [--train datasets/scorpion_sim_830.h5 | trajectories]
                                      [--train-seed 6] [--seeds 5] [--horizon 10] [--trajectories 2000]
                                      [--persistence]
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


def coverage(dgmm, model, persistence, s, episodes, horizon, trajectories, seed):
    """Counts of outcomes inside the 50% and 90% regions per horizon, and the number of episodes."""
    x, z, command, episode, step = s.x, s.z, s.command, s.episode, s.step
    inside = np.zeros((horizon, 2))
    used = 0
    for e in episodes:
        rows = np.flatnonzero(episode == e)
        rows = rows[np.argsort(step[rows])][:horizon]
        if len(rows) < horizon:
            continue
        used += 1
        truth = compose(x, rows)
        p = dgmm.predict(model, [int(c) for c in command[rows]], terrain=z[rows], trajectories=trajectories,
                         seed=seed + int(e), pose_dims=["dx", "dy", "dyaw"], persistence=persistence)
        for k in range(horizon):
            xy = p["poses"][k][:, :2]
            mean = xy.mean(0)
            inv = np.linalg.inv(np.cov(xy.T))
            d2 = np.einsum("ij,jk,ik->i", xy - mean, inv, xy - mean)
            t = truth[k] - mean
            d2_truth = t @ inv @ t
            inside[k] += [d2_truth <= np.quantile(d2, 0.5), d2_truth <= np.quantile(d2, 0.9)]
    return inside, used


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
    lo, _, hi = a.seeds.partition("-")
    seeds = range(int(lo), int(hi or lo) + 1)
    totals = {name: np.zeros((a.horizon, 2)) for name in models}
    episodes_used = 0
    for seed in seeds:
        if a.train == "trajectories" and seed == a.train_seed:
            sys.exit("--seeds must not include --train-seed")
        path = os.path.join(tmp, f"trajectories_{seed}.h5")
        simulate(a.build, a.horizon, seed, path)
        s = dgmm.SampleSet.read(path)
        for name, (model, persistence) in models.items():
            inside, used = coverage(dgmm, model, persistence, s, np.unique(s.episode), a.horizon, a.trajectories, 1000 * seed)
            totals[name] += inside
        episodes_used += used
    trained_on = f"300 trajectory episodes (seed {a.train_seed})" if a.train == "trajectories" else a.train
    print(f"Trained on {trained_on}; {episodes_used} held-out episodes of {a.horizon} commands (trajectory seeds "
          f"{a.seeds}), {a.trajectories} predicted trajectories each; share of true end points inside the "
          f"predicted region after k commands\n")
    names = list(models)
    print("| k | " + " | ".join(f"{n} 50% | {n} 90%" for n in names) + " |")
    print("|---|" + "---|---|" * len(names))
    for k in range(a.horizon):
        cells = " | ".join(f"{totals[n][k, 0] / episodes_used:.2f} | {totals[n][k, 1] / episodes_used:.2f}" for n in names)
        print(f"| {k + 1} | {cells} |")


if __name__ == "__main__":
    main()
