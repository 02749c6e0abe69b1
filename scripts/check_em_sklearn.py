#!/usr/bin/python3
"""Checks that `dgmm em` matches scikit-learn's GaussianMixture (full covariances, 10 restarts).

For Old Faithful (raw and standardised) and seeded synthetic 2-D, 6-D and 8-D sets, both fit the
same data with the same components, restarts, tolerance and reg_covar; the mean log-likelihood
per sample of the returned models must agree within 1e-3 nats. Each set is checked with the
default tolerance (1e-3) and with a tight one (1e-8, up to 1000 iterations). Exits non-zero on a
mismatch.

Usage: scripts/check_em_sklearn.py [--dgmm build/app/dgmm] [--bound 1e-3] [--json]
Needs Debian's python3-sklearn and python3-numpy (run with /usr/bin/python3).
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import warnings

import numpy as np
from sklearn.exceptions import ConvergenceWarning
from sklearn.mixture import GaussianMixture

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def synthetic(dim, components, n, seed, spread):
    """n samples from a random full-covariance mixture (means ~ N(0, spread^2 I))."""
    rng = np.random.default_rng(seed)
    means = rng.normal(0.0, spread, size=(components, dim))
    weights = rng.dirichlet(np.full(components, 3.0))
    labels = rng.choice(components, size=n, p=weights)
    X = np.empty((n, dim))
    for k in range(components):
        A = rng.normal(size=(dim, dim)) + 1.5 * np.eye(dim)
        idx = labels == k
        X[idx] = means[k] + rng.normal(size=(idx.sum(), dim)) @ A.T
    return X


def datasets():
    faithful = np.loadtxt(os.path.join(ROOT, "datasets", "old_faithful.csv"), delimiter=",",
                          skiprows=1)
    standardised = (faithful - faithful.mean(0)) / faithful.std(0)
    return [
        ("old_faithful raw", faithful, 2),
        ("old_faithful standardised", standardised, 2),
        ("old_faithful standardised", standardised, 3),
        ("synthetic 2-D", synthetic(2, 3, 900, 11, 4.0), 3),
        ("synthetic 6-D", synthetic(6, 4, 3000, 12, 5.0), 4),
        ("synthetic 8-D", synthetic(8, 3, 3000, 13, 5.0), 3),
    ]


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"check_em_sklearn: {' '.join(cmd)} failed:\n{p.stderr}")
    return p.stdout


def ours(dgmm, workdir, name, X, components, n_init, tol, max_iter, reg_covar, seed):
    """Mean log-likelihood of `dgmm em` on X via a CSV import (no standardisation)."""
    stem = os.path.join(workdir, name.replace(" ", "_"))
    cols = [f"x{j}" for j in range(X.shape[1])]
    np.savetxt(stem + ".csv", X, delimiter=",", header=",".join(cols), comments="", fmt="%.17g")
    run([dgmm, "import", stem + ".csv", "-o", stem + ".h5", "--pose-cols", ",".join(cols)])
    out = run([dgmm, "em", stem + ".h5", "-o", stem + f"_em{components}.h5", "--components",
               str(components), "--n-init", str(n_init), "--tol", repr(tol), "--max-iter",
               str(max_iter), "--reg-covar", repr(reg_covar), "--seed", str(seed), "--json"])
    return json.loads(out)["mean_log_likelihood"]


def theirs(X, components, n_init, tol, max_iter, reg_covar, seed):
    gm = GaussianMixture(components, covariance_type="full", n_init=n_init, tol=tol,
                         max_iter=max_iter, reg_covar=reg_covar, random_state=seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConvergenceWarning)
        gm.fit(X)
    return gm.score(X)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dgmm", default=os.environ.get("DGMM_EXE",
                                                         os.path.join(ROOT, "build/app/dgmm")))
    parser.add_argument("--bound", type=float, default=1e-3, help="nats per sample")
    parser.add_argument("--n-init", type=int, default=10)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args()
    if not os.access(args.dgmm, os.X_OK):
        sys.exit(f"check_em_sklearn: no dgmm binary at {args.dgmm} (build first or pass --dgmm)")
    rows, failures = [], 0
    with tempfile.TemporaryDirectory(prefix="dgmm-em-check-") as workdir:
        for name, X, k in datasets():
            for tol, max_iter in ((1e-3, 100), (1e-8, 1000)):
                a = ours(args.dgmm, workdir, name, X, k, args.n_init, tol, max_iter, 1e-6,
                         args.seed)
                b = theirs(X, k, args.n_init, tol, max_iter, 1e-6, args.seed)
                a, b = float(a), float(b)
                ok = bool(abs(a - b) <= args.bound)
                failures += not ok
                rows.append({"set": name, "n": X.shape[0], "d": X.shape[1], "components": k,
                             "tol": tol, "dgmm": a, "sklearn": b, "difference": a - b,
                             "ok": ok})
    if args.json:
        print(json.dumps({"bound": args.bound, "n_init": args.n_init, "rows": rows}, indent=2))
    else:
        print(f"{'set':28s} {'n':>5s} {'d':>2s} {'K':>2s} {'tol':>6s} {'dgmm':>12s} "
              f"{'sklearn':>12s} {'dgmm-sklearn':>13s}")
        for r in rows:
            print(f"{r['set']:28s} {r['n']:5d} {r['d']:2d} {r['components']:2d} {r['tol']:6.0e} "
                  f"{r['dgmm']:12.6f} {r['sklearn']:12.6f} {r['difference']:13.2e}"
                  f"{'' if r['ok'] else '  MISMATCH'}")
        print(f"{len(rows) - failures}/{len(rows)} within {args.bound:g} nats per sample "
              f"({args.n_init} restarts each)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
