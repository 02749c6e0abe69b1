#!/usr/bin/python3
"""Checks that dgmm's HDF5 files are readable by h5py (Debian's python3-h5py) and follow
docs/file-format.md: imports a CSV with commands, terrain, episodes and standardisation, fits a
model, then opens both files with h5py and checks every dataset's shape, dtype and attributes
and that the values agree with the CSV. Exits non-zero on any mismatch.

Usage: /usr/bin/python3 scripts/check_h5py.py [--dgmm build/app/dgmm]
"""
import argparse
import os
import subprocess
import sys
import tempfile

import h5py
import numpy as np

FAILURES = []


def check(condition, what):
    if not condition:
        FAILURES.append(what)
        print(f"MISMATCH: {what}")


def text(value):
    """One string attribute: format 2 stores fixed-length strings, which h5py reads as bytes."""
    return value.decode() if isinstance(value, (bytes, np.bytes_)) else str(value)


def strings(values):
    return [v.decode() if isinstance(v, bytes) else str(v) for v in np.atleast_1d(values)]


def write_csv(path, rng):
    rows = ["speed,turn,dx,dyaw,pitch,roll,run"]
    data = []
    for i in range(500):
        c = i % 3
        speed, turn = (0.5, 0) if c == 0 else (0.5, 1) if c == 1 else (0, 1)
        pitch, roll = rng.normal(0, 0.1, 2)
        dx = 0.2 * (c + 1) + pitch + rng.normal(0, 0.02)
        dyaw = 0.3 * turn + roll + rng.normal(0, 0.05)
        run = i // 50
        rows.append(f"{speed},{turn},{dx!r},{dyaw!r},{pitch!r},{roll!r},{run}")
        data.append((c, dx, dyaw, pitch, roll, run))
    with open(path, "w") as f:
        f.write("\n".join(rows) + "\n")
    return data


def check_set(path, data, standardized):
    raw = np.array([d[1:5] for d in data])
    with h5py.File(path, "r") as f:
        check(text(f.attrs["dgmm_format"]) == "sample_set", "set: dgmm_format")
        check(int(f.attrs["dgmm_format_version"]) == 2, "set: dgmm_format_version")
        check(text(f.attrs["source"]) == "real", "set: source")
        n = len(data)
        check(f["x"].shape == (n, 2) and f["x"].dtype == np.float64, "set: x shape/dtype")
        check(f["z"].shape == (n, 2) and f["z"].dtype == np.float64, "set: z shape/dtype")
        check(f["command"].shape == (n,) and f["command"].dtype == np.int32, "set: command")
        for name in ("x", "z", "command", "episode", "step"):
            check(f[name].chunks is not None, f"set: {name} chunked")
            check(f[name].compression == "gzip" and f[name].shuffle, f"set: {name} deflate+shuffle")
        check(strings(f["x"].attrs["names"]) == ["dx", "dyaw"], "set: x names")
        check(strings(f["z"].attrs["names"]) == ["pitch", "roll"], "set: z names")
        check(f["commands/values"].shape == (3, 2), "set: commands/values shape")
        check(strings(f["commands/values"].attrs["dim_names"]) == ["speed", "turn"],
              "set: command dim names")
        check(strings(f["commands/labels"][()]) == ["0.5,0", "0.5,1", "0,1"], "set: labels")
        check(np.array_equal(f["commands/values"][()], [[0.5, 0], [0.5, 1], [0, 1]]),
              "set: command values")
        check(np.array_equal(f["command"][()], [d[0] for d in data]), "set: command per sample")
        check(np.array_equal(f["episode"][()], [d[5] for d in data]), "set: episode")
        check(np.array_equal(f["step"][()], [i % 50 for i in range(n)]), "set: step")
        y = np.hstack([f["x"][()], f["z"][()]])
        if standardized:
            offset, scale = f["transform/offset"][()], f["transform/scale"][()]
            check(offset.shape == (4,) and scale.shape == (4,), "set: transform shapes")
            check(np.allclose(y.mean(axis=0), 0, atol=1e-12), "set: standardised mean 0")
            check(np.allclose(y.std(axis=0), 1, atol=1e-12), "set: standardised sd 1")
            check(np.allclose(offset + scale * y, raw, rtol=0, atol=1e-12), "set: transform")
        else:
            check("transform" not in f, "set: no transform")
            check(np.array_equal(y, raw), "set: x||z equal the CSV exactly")
        check(text(f["metadata"].attrs["imported_from"]) == "walk.csv", "set: metadata")


def check_model(path):
    with h5py.File(path, "r") as f:
        check(text(f.attrs["dgmm_format"]) == "model", "model: dgmm_format")
        check(int(f.attrs["dgmm_format_version"]) == 2, "model: version")
        check(text(f.attrs["kind"]) == "dgmm", "model: kind")
        d = int(f.attrs["pose_dim"]) + int(f.attrs["terrain_dim"])
        check((int(f.attrs["pose_dim"]), int(f.attrs["terrain_dim"])) == (2, 2), "model: dims")
        check(int(f.attrs["seed"]) == 7, "model: seed")
        check(strings(f.attrs["pose_names"]) == ["dx", "dyaw"], "model: pose names")
        check(strings(f.attrs["terrain_names"]) == ["pitch", "roll"], "model: terrain names")
        check(np.array_equal(f["commands/ids"][()], [0, 1, 2]), "model: command ids")
        check(f["commands/values"].shape == (3, 2), "model: command values")
        opts = f["dgmm_options"].attrs
        check(text(opts["variant"]) == "faithful" and float(opts["k"]) == 0.5, "model: options")
        check(np.array_equal(f["dgmm_options/initial_covariance_diagonal"][()],
                             [0.1, 0.1, 0.1, 0.1]), "model: initial covariance")
        check(f["transform/offset"].shape == (4,), "model: transform")
        check(sorted(f["mixtures"].keys()) == ["0", "1", "2"], "model: one mixture per command")
        total = 0
        for name, g in f["mixtures"].items():
            k = int(g.attrs["num_components"])
            check(int(g.attrs["command_id"]) == int(name), f"model: mixtures/{name} command_id")
            check(g["weights"].shape == (k,), f"model: mixtures/{name}/weights shape")
            check(g["means"].shape == (k, d), f"model: mixtures/{name}/means shape")
            check(g["covariances"].shape == (k, d, d), f"model: mixtures/{name}/covs shape")
            covs = g["covariances"][()]
            check(np.allclose(covs, covs.transpose(0, 2, 1)), f"model: {name} symmetric")
            check(all(np.linalg.eigvalsh(c).min() > 0 for c in covs), f"model: {name} PD")
            total += g["weights"][()].sum()
        check(abs(total - 500) < 1e-9, "model: weights are sample counts (sum 500)")


def run(args):
    result = subprocess.run(args, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit(f"check_h5py: {' '.join(args)} failed: {result.stderr.strip()}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    parser.add_argument("--dgmm", default=os.path.join(root, "build", "app", "dgmm"))
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    with tempfile.TemporaryDirectory() as tmp:
        csv = os.path.join(tmp, "walk.csv")
        data = write_csv(csv, rng)
        cols = ["--command-cols", "speed,turn", "--pose-cols", "dx,dyaw", "--terrain-cols",
                "pitch,roll", "--episode-col", "run", "--source", "real"]
        for standardized in (False, True):
            out = os.path.join(tmp, f"set{int(standardized)}.h5")
            run([args.dgmm, "import", csv, "-o", out] + cols +
                (["--standardize"] if standardized else []))
            check_set(out, data, standardized)
        model = os.path.join(tmp, "model.h5")
        run([args.dgmm, "fit", os.path.join(tmp, "set1.h5"), "-o", model, "--k", "0.5",
             "--seed", "7", "--init-cov", "0.1"])
        check_model(model)
    if FAILURES:
        print(f"check_h5py: {len(FAILURES)} mismatch(es)")
        return 1
    print(f"check_h5py: OK (h5py {h5py.__version__}, HDF5 {h5py.version.hdf5_version}): "
          "sample sets and a model written by dgmm read as documented")
    return 0


if __name__ == "__main__":
    sys.exit(main())
