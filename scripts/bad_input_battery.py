#!/usr/bin/python3
"""The bad-input table of issue #13, rerun: a few hundred inputs that have no answer (or that
dgmm must read despite looking odd), each run twice through the CLI.

Usage: /usr/bin/python3 scripts/bad_input_battery.py DGMM WORKDIR [--seed N] [--markdown FILE]
                                                       [--only SUBSTRING] [--timeout S]

Every case is run twice: once with no output at the output path ("fresh") and once with an
older valid output already there ("older"). For each run the table records
  crash      the process ended with a signal
  hang       it ran past --timeout (killed)
  input      an input file changed (SHA-256 before and after)
  clobber    a refused run changed the older output
  partial    a refused run left an output (fresh run) or a `*.tmp-*` file/folder behind
  silent     exit 0 on a case that has no answer, or 'nan' on stdout with exit 0
  message    a refused run's stderr is not one line of at most 300 characters naming the
             file or field the case is about
Cases whose input is odd but valid (CR-only line endings, 1e-400, a version-2 file given to
`upgrade`) must succeed instead; byte-mutated files may be read or refused (never crash).
Mutations (truncation points, flipped bytes) are drawn from --seed. Needs h5py and numpy
(Debian python3-h5py). Renders run once with DISPLAY unset and once under
scripts/with-display.sh.
"""
import argparse
import hashlib
import os
import random
import re
import resource
import shutil
import signal
import subprocess
import sys
import time

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CHECKS = ["crash", "hang", "input", "clobber", "partial", "silent", "message"]


# ----------------------------------------------------------------------------------------------
# Inputs


def write(path, data, mode="w"):
    with open(path, mode) as f:
        f.write(data)


def sha(path):
    """Hash of a file, or of a folder's sorted (name, hash) list; None when absent."""
    if os.path.isdir(path):
        h = hashlib.sha256()
        for dirpath, dirs, files in sorted(os.walk(path)):
            dirs.sort()
            for name in sorted(files):
                p = os.path.join(dirpath, name)
                h.update(os.path.relpath(p, path).encode())
                h.update((sha(p) or "").encode())
        return "dir:" + h.hexdigest()
    if not os.path.exists(path):
        return None
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def good_csv(n=200, seed=0):
    rng = random.Random(seed)
    lines = ["c,x,y,z"]
    for i in range(n):
        c = i % 2
        lines.append(f"{c},{rng.gauss(0.1 * c, 0.05):.6f},{rng.gauss(-0.1 * c, 0.03):.6f},"
                     f"{rng.uniform(-0.2, 0.2):.6f}")
    return "\n".join(lines) + "\n"


def dgmm_ok(dgmm, args):
    r = subprocess.run([dgmm, "--quiet"] + args, capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        sys.exit(f"setup failed: dgmm {' '.join(args)}\n{r.stderr}")


def copy_h5(src, dst):
    shutil.copyfile(src, dst)
    return dst


def replace_dataset(f, name, data, dtype=None, chunks=None, maxshape=None, shape=None):
    """Replaces dataset `name` keeping its attributes."""
    attrs = {}
    if name in f:
        attrs = {k: f[name].attrs[k] for k in f[name].attrs}
        del f[name]
    if shape is not None:
        ds = f.create_dataset(name, shape=shape, dtype=dtype, chunks=chunks, maxshape=maxshape)
    else:
        ds = f.create_dataset(name, data=data, dtype=dtype, chunks=chunks, maxshape=maxshape)
    for k, v in attrs.items():
        ds.attrs[k] = v


def set_vlen_attr(f, obj, name):
    value = f[obj].attrs[name]
    if isinstance(value, bytes):
        value = value.decode()
    if isinstance(value, np.ndarray):
        items = [v.decode() if isinstance(v, bytes) else str(v) for v in value]
        del f[obj].attrs[name]
        f[obj].attrs.create(name, items, dtype=h5py.string_dtype())
        return
    del f[obj].attrs[name]
    f[obj].attrs.create(name, str(value), dtype=h5py.string_dtype())


def edit(src, dst, fn):
    shutil.copyfile(src, dst)
    with h5py.File(dst, "r+", libver=("v110", "latest")) as f:
        fn(f)
    return dst


def version_one(src, dst):
    """A file as dgmm version 1 wrote it: earliest format bounds, variable-length root strings."""
    with h5py.File(src, "r") as s, h5py.File(dst, "w", libver="earliest") as d:
        for name in s:
            s.copy(s[name], d, name=name)
        for k in s.attrs:
            v = s.attrs[k]
            if isinstance(v, (bytes, np.bytes_)):
                d.attrs.create(k, v.decode(), dtype=h5py.string_dtype())
            else:
                d.attrs[k] = v
        d.attrs["dgmm_format_version"] = np.int64(1)
    return dst


def mixture_names(f):
    return sorted(f["mixtures"].keys())


def make_inputs(dgmm, w, seed):
    """Builds every input under w/in; returns a dict name -> path."""
    d = os.path.join(w, "in")
    os.makedirs(d)
    P = lambda name: os.path.join(d, name)  # noqa: E731
    inp = {}

    # Valid files.
    write(P("good.csv"), good_csv())
    dgmm_ok(dgmm, ["import", P("good.csv"), "-o", P("set.h5"), "--command-cols", "c",
                   "--pose-cols", "x,y", "--terrain-cols", "z"])
    dgmm_ok(dgmm, ["import", P("good.csv"), "-o", P("set_pose1.h5"), "--command-cols", "c",
                   "--pose-cols", "x"])
    dgmm_ok(dgmm, ["import", P("good.csv"), "-o", P("set_other.h5"), "--command-cols", "c",
                   "--pose-cols", "y,x", "--terrain-cols", "z"])
    dgmm_ok(dgmm, ["fit", P("set.h5"), "-o", P("m.h5")])
    dgmm_ok(dgmm, ["fit", P("set_pose1.h5"), "-o", P("m_pose1.h5")])
    dgmm_ok(dgmm, ["em", P("set.h5"), "-o", P("em.h5"), "--components", "2"])
    dgmm_ok(dgmm, ["export", P("m.h5"), "-o", P("m.json")])
    for name in ["good.csv", "set.h5", "set_pose1.h5", "set_other.h5", "m.h5", "m_pose1.h5",
                 "em.h5", "m.json"]:
        inp[name] = P(name)
    os.makedirs(P("folder.h5"))
    inp["folder.h5"] = P("folder.h5")
    os.makedirs(P("folder.csv"))
    inp["folder.csv"] = P("folder.csv")
    os.makedirs(P("folder.json"))
    inp["folder.json"] = P("folder.json")
    inp["missing.h5"] = P("missing.h5")
    inp["missing.csv"] = P("missing.csv")
    inp["missing.json"] = P("missing.json")
    write(P("empty.h5"), "")
    write(P("text.h5"), "x,y\n1,2\n")
    inp["empty.h5"], inp["text.h5"] = P("empty.h5"), P("text.h5")

    # Byte-mutated and truncated HDF5 files (positions drawn from the seed).
    rng = random.Random(seed)
    for base in ["set.h5", "m.h5"]:
        data = open(P(base), "rb").read()
        stem = base[:-3]
        for i in range(8):
            cut = rng.choice([0, 8, 47, 96, 512]) if i < 3 else rng.randrange(1, len(data))
            name = f"{stem}_cut{i}.h5"
            write(P(name), data[:cut], "wb")
            inp[name] = P(name)
        for i in range(16):
            m = bytearray(data)
            span = 4096 if i % 2 == 0 else len(m)
            for _ in range(1 + i % 3):
                m[rng.randrange(min(span, len(m)))] ^= rng.randrange(1, 256)
            name = f"{stem}_flip{i}.h5"
            write(P(name), bytes(m), "wb")
            inp[name] = P(name)

    # Crafted sample sets.
    S = P("set.h5")
    crafted_sets = {
        "set_vlen_format.h5": lambda f: set_vlen_attr(f, "/", "dgmm_format"),
        "set_vlen_names.h5": lambda f: set_vlen_attr(f, "x", "names"),
        "set_version3.h5": lambda f: f.attrs.modify("dgmm_format_version", np.int64(3)),
        "set_version1_attr.h5": lambda f: f.attrs.modify("dgmm_format_version", np.int64(1)),
        "set_huge_rows.h5": lambda f: replace_dataset(f, "x", None, dtype="f8", chunks=(64, 2),
                                                      maxshape=(None, 2), shape=(2**42, 2)),
        "set_huge_cols.h5": lambda f: replace_dataset(f, "x", None, dtype="f8", chunks=(1, 4096),
                                                      maxshape=(None, 2**30), shape=(200, 2**30)),
        "set_string_x.h5": lambda f: replace_dataset(
            f, "x", np.array([[b"1.0", b"2.0"]] * 200), dtype="S3"),
        "set_int_x.h5": lambda f: replace_dataset(f, "x", np.ones((200, 2), dtype="i4")),
        "set_f32_x.h5": lambda f: replace_dataset(f, "x", np.ones((200, 2), dtype="f4")),
        "set_rank1_x.h5": lambda f: replace_dataset(f, "x", np.ones(200)),
        "set_rows_mismatch.h5": lambda f: replace_dataset(f, "z", np.ones((150, 1))),
        "set_nan_x.h5": lambda f: f["x"].__setitem__((5, 1), np.nan),
        "set_inf_z.h5": lambda f: f["z"].__setitem__((7, 0), np.inf),
        "set_cmd_range.h5": lambda f: f["command"].__setitem__(3, 99),
        "set_cmd_negative.h5": lambda f: f["command"].__setitem__(3, -1),
        "set_no_x.h5": lambda f: f.__delitem__("x"),
        "set_names_count.h5": lambda f: f["x"].attrs.__setitem__("names", np.array([b"a"])),
    }

    def zero_rows(f):
        for name in ["x", "z", "command", "episode", "step"]:
            if name in f:
                old = f[name]
                shape = (0,) + old.shape[1:]
                replace_dataset(f, name, np.zeros(shape, dtype=old.dtype), chunks=None)
    crafted_sets["set_zero_rows.h5"] = zero_rows
    for name, fn in crafted_sets.items():
        inp[name] = edit(S, P(name), fn)
    inp["set_v1.h5"] = version_one(S, P("set_v1.h5"))
    data = open(P("set_v1.h5"), "rb").read()
    write(P("set_v1_cut.h5"), data[: len(data) // 2], "wb")
    inp["set_v1_cut.h5"] = P("set_v1_cut.h5")
    m = bytearray(data)
    for _ in range(3):
        m[rng.randrange(len(m))] ^= rng.randrange(1, 256)
    write(P("set_v1_flip.h5"), bytes(m), "wb")
    inp["set_v1_flip.h5"] = P("set_v1_flip.h5")

    # Crafted models.
    M = P("m.h5")

    def on_mix(fn):
        def apply(f):
            g = f["mixtures"][mixture_names(f)[0]]
            fn(f, g)
        return apply

    def zero_components(f, g):
        d = g["means"].shape[1]
        replace_dataset(g, "weights", np.zeros((0,)))
        replace_dataset(g, "means", np.zeros((0, d)))
        replace_dataset(g, "covariances", np.zeros((0, d, d)))
        if "num_components" in g.attrs:
            g.attrs.modify("num_components", np.int64(0))

    def weights(value):
        def fn(f, g):
            w = g["weights"][...]
            w[0] = value
            g["weights"][...] = w
        return fn

    def all_weights(value):
        def fn(f, g):
            g["weights"][...] = np.full(g["weights"].shape, value)
        return fn

    def asymmetric(f, g):
        c = g["covariances"][...]
        c[0, 0, 1] += 0.5 * abs(c[0, 0, 0])
        g["covariances"][...] = c

    def non_spd(f, g):
        c = g["covariances"][...]
        c[0] = -np.eye(c.shape[1])
        g["covariances"][...] = c

    def singular(f, g):
        c = g["covariances"][...]
        c[0] = np.zeros_like(c[0])
        g["covariances"][...] = c

    def nan_mean(f, g):
        m = g["means"][...]
        m[0, 0] = np.nan
        g["means"][...] = m

    def huge_k(f, g):
        replace_dataset(g, "weights", None, dtype="f8", chunks=(1024,), maxshape=(None,),
                        shape=(2**40,))

    def no_mixtures(f):
        for name in mixture_names(f):
            del f["mixtures"][name]

    crafted_models = {
        "m_zero_components.h5": on_mix(zero_components),
        "m_no_mixtures.h5": no_mixtures,
        "m_weight_nan.h5": on_mix(weights(np.nan)),
        "m_weight_inf.h5": on_mix(weights(np.inf)),
        "m_weight_neg.h5": on_mix(weights(-1.0)),
        "m_weight_zero.h5": on_mix(weights(0.0)),
        "m_weight_1e308.h5": on_mix(all_weights(1e308)),
        "m_asymmetric.h5": on_mix(asymmetric),
        "m_non_spd.h5": on_mix(non_spd),
        "m_singular.h5": on_mix(singular),
        "m_nan_mean.h5": on_mix(nan_mean),
        "m_huge_k.h5": on_mix(huge_k),
        "m_vlen_kind.h5": lambda f: set_vlen_attr(f, "/", "kind"),
        "m_version3.h5": lambda f: f.attrs.modify("dgmm_format_version", np.int64(3)),
        "m_k_negative.h5": lambda f: f["dgmm_options"].attrs.modify("k", -1.0),
        "m_pose_dim_wrong.h5": lambda f: f.attrs.modify("pose_dim", np.int64(7)),
    }
    for name, fn in crafted_models.items():
        # Weights that overflow only when summed: the EM model has two components per mixture.
        inp[name] = edit(P("em.h5") if name == "m_weight_1e308.h5" else M, P(name), fn)
    inp["m_v1.h5"] = version_one(M, P("m_v1.h5"))

    # CSV files.
    rows = good_csv(20).splitlines()
    csvs = {
        "nan.csv": rows[:3] + ["1,NaN,0.1,0.1"] + rows[3:],
        "nan_lower.csv": rows[:3] + ["1,nan,0.1,0.1"] + rows[3:],
        "inf.csv": rows[:3] + ["1,0.1,inf,0.1"] + rows[3:],
        "neg_inf.csv": rows[:3] + ["1,0.1,0.2,-Infinity"] + rows[3:],
        "big_exp.csv": rows[:3] + ["1,1e400,0.1,0.1"] + rows[3:],
        "text_cell.csv": rows[:3] + ["1,abc,0.1,0.1"] + rows[3:],
        "empty_cell.csv": rows[:3] + ["1,,0.1,0.1"] + rows[3:],
        "ragged.csv": rows[:3] + ["1,0.1,0.1"] + rows[3:],
        "ragged_long.csv": rows[:3] + ["1,0.1,0.1,0.1,9"] + rows[3:],
        "header_only.csv": rows[:1],
        "no_header_match.csv": ["a,b,d"] + rows[1:],
        "dup_header.csv": ["c,x,x,z"] + rows[1:],
        "overflow_std.csv": ["c,x,y,z"] + [f"0,{s}1e308,0.1,0.2" for s in ["", "-"] * 5],
        "episode_1e12.csv": ["e,x,y"] + [f"1e12,{i * 0.1},{i * 0.2}" for i in range(6)],
        "episode_frac.csv": ["e,x,y"] + [f"1.5,{i * 0.1},{i * 0.2}" for i in range(6)],
    }
    for name, lines in csvs.items():
        write(P(name), "\n".join(lines) + "\n")
        inp[name] = P(name)
    write(P("empty.csv"), "")
    write(P("cr_only.csv"), "\r".join(rows) + "\r")
    write(P("crlf.csv"), "\r\n".join(rows) + "\r\n")
    write(P("tiny.csv"), "\n".join(rows[:3] + ["1,1e-400,0.1,0.1"] + rows[3:]) + "\n")
    write(P("long_small.csv"),
          "\n".join(rows[:3] + ["1,0." + "0" * 400 + "1,0.1,0.1"] + rows[3:]) + "\n")
    write(P("huge_cell.csv"), "\n".join(rows[:3] + ["1," + "7" * (5 << 20) + ",0.1,0.1"] +
                                        rows[3:]) + "\n")
    write(P("binary.csv"), bytes(random.Random(seed + 1).randrange(256) for _ in range(4096)),
          "wb")
    write(P("utf16.csv"), "\n".join(rows).encode("utf-16"), "wb")
    write(P("big.csv"), "x,y\n" + "".join(f"{i * 0.37},{i % 97}\n" for i in range(40000)))
    for name in ["empty.csv", "cr_only.csv", "crlf.csv", "tiny.csv", "long_small.csv",
                 "huge_cell.csv", "binary.csv", "utf16.csv", "big.csv"]:
        inp[name] = P(name)

    # Logs (import-log): the shipped logs, cut short, and broken copies.
    logs = os.path.join(ROOT, "datasets", "logs")
    for name in ["commands.csv", "pose.csv", "imu.csv"]:
        lines = open(os.path.join(logs, name)).read().splitlines()
        keep = {"commands.csv": 300, "pose.csv": 900, "imu.csv": 1500}[name]
        write(P("log_" + name), "\n".join(lines[:keep]) + "\n")
        inp["log_" + name] = P("log_" + name)
        bad = list(lines[:keep])
        bad[10] = bad[10].replace(bad[10].split(",")[0], "nan", 1)
        write(P("log_nan_" + name), "\n".join(bad) + "\n")
        inp["log_nan_" + name] = P("log_nan_" + name)
    lines = open(P("log_pose.csv")).read().splitlines()
    lines[20], lines[21] = lines[21], lines[20]
    write(P("log_backwards_pose.csv"), "\n".join(lines) + "\n")
    inp["log_backwards_pose.csv"] = P("log_backwards_pose.csv")
    write(P("log_header_pose.csv"), lines[0] + "\n")
    inp["log_header_pose.csv"] = P("log_header_pose.csv")

    # Simulation configs.
    configs = {
        "cfg_good.json": "{}\n",
        "cfg_bad.json": "{ not json",
        "cfg_1e400.json": '{"friction": {"sliding": 1e400}}\n',
        "cfg_type.json": '{"friction": "slippery"}\n',
        "cfg_negative.json": '{"friction": {"sliding": -1}}\n',
        "cfg_unknown.json": '{"frobnication": 3}\n',
        "cfg_array.json": "[1, 2]\n",
        "cfg_nan.json": '{"friction": {"sliding": NaN}}\n',
        "cfg_empty.json": "",
    }
    for name, text in configs.items():
        write(P(name), text)
        inp[name] = P(name)
    inp["sim"] = os.path.join(ROOT, "datasets", "sim2real", "sim.h5")
    inp["real"] = os.path.join(ROOT, "datasets", "sim2real", "slip", "real.h5")
    shutil.copyfile(inp["sim"], P("sim_copy.h5"))
    inp["sim_copy.h5"] = P("sim_copy.h5")
    shutil.copyfile(os.path.join(ROOT, "datasets", "robots", "hexapod.xml"), P("robot.xml"))
    inp["robot.xml"] = P("robot.xml")
    write(P("robot_bad.xml"), "<mujoco><worldbody><body name=\"b\">")
    inp["robot_bad.xml"] = P("robot_bad.xml")
    return inp


def make_older_outputs(dgmm, w, inp):
    """One valid older output per kind of output."""
    d = os.path.join(w, "older")
    os.makedirs(d)
    old = {"h5_set": inp["set_other.h5"], "h5_model": inp["m_pose1.h5"], "json": inp["m.json"]}
    write(os.path.join(d, "old.png"), b"\x89PNG\r\n\x1a\nolder picture", "wb")
    old["png"] = os.path.join(d, "old.png")
    write(os.path.join(d, "old.csv"), "k,loglik\n0.7,1.0\n")
    old["csv"] = os.path.join(d, "old.csv")
    report = os.path.join(d, "report")
    dgmm_ok(dgmm, ["sim2real", "--sim", inp["sim"], "--real",
                   os.path.join(ROOT, "datasets", "sim2real", "null", "real.h5"), "-o", report,
                   "--no-figures", "--locate-only", "--permutations", "50"])
    old["dir"] = report
    os.makedirs(os.path.join(d, "logdir"))
    for name in ["commands.csv", "pose.csv", "imu.csv"]:
        write(os.path.join(d, "logdir", name), "t\n0\n")
    old["logdir"] = os.path.join(d, "logdir")
    return old


# ----------------------------------------------------------------------------------------------
# Cases


class Case:
    def __init__(self, category, name, args, inputs, out=None, kind=None, expect="refuse",
                 needles=None, display="none", fsize=None, timeout=None):
        self.category, self.name, self.args = category, name, args
        self.inputs = [p for p in inputs if p and os.path.exists(p)]
        self.out, self.kind, self.expect = out, kind, expect
        self.needles = needles or []
        self.display, self.fsize, self.timeout = display, fsize, timeout


def cases(inp, seed):
    I = inp  # noqa: E741
    C = []
    O = "{OUT}"  # replaced by the run's output path

    def add(*a, **k):
        C.append(Case(*a, **k))

    b = os.path.basename

    # --- corrupt, truncated and byte-mutated HDF5 (mutations from the seed) ---
    set_cmds = [("info", lambda f: ["info", f], None, None),
                ("fit", lambda f: ["fit", f, "-o", O], "h5_model", "model"),
                ("score", lambda f: ["score", I["m.h5"], f], None, None),
                ("em", lambda f: ["em", f, "-o", O], "h5_model", "model")]
    model_cmds = [("info", lambda f: ["info", f], None, None),
                  ("score", lambda f: ["score", f, I["set.h5"]], None, None),
                  ("export", lambda f: ["export", f, "-o", O], "json", "json"),
                  ("mise", lambda f: ["mise", f, I["m.h5"], "--command", "0"], None, None)]
    for stem, cmds in [("set", set_cmds), ("m", model_cmds)]:
        for i in range(8):
            f = I[f"{stem}_cut{i}.h5"]
            for j, (cmd, mk, kind, _) in enumerate(cmds):
                if (i + j) % 2 == 0:
                    add("mutated HDF5", f"{cmd} {b(f)}", mk(f), [f, I["m.h5"], I["set.h5"]],
                        out=O if kind else None, kind=kind, expect="refuse", needles=[b(f)])
        for i in range(16):
            f = I[f"{stem}_flip{i}.h5"]
            for j, (cmd, mk, kind, _) in enumerate(cmds):
                if (i + j) % 2 == 0:
                    add("mutated HDF5", f"{cmd} {b(f)}", mk(f), [f, I["m.h5"], I["set.h5"]],
                        out=O if kind else None, kind=kind, expect="either", needles=[b(f)])

    # --- crafted sample sets (vlen strings, versions, huge dims, zero rows, types, values) ---
    crafted_sets = [k for k in I if k.startswith("set_") and k.endswith(".h5") and
                    ("_cut" not in k and "_flip" not in k or k.startswith("set_v1"))
                    and k not in ("set_pose1.h5", "set_other.h5")]
    for name in sorted(crafted_sets):
        f = I[name]
        for cmd, mk, kind, _ in set_cmds[:3]:
            add("crafted set", f"{cmd} {name}", mk(f), [f, I["m.h5"]], out=O if kind else None,
                kind=kind, needles=[name])
    for name in ["set_zero_rows.h5", "set_nan_x.h5", "set_vlen_format.h5", "set_huge_rows.h5"]:
        f = I[name]
        add("crafted set", f"em {name}", ["em", f, "-o", O], [f], out=O, kind="h5_model",
            needles=[name])
        add("crafted set", f"cv {name}", ["cv", f, "--folds", "2", "--repeats", "1", "--no-em",
                                         "--threads", "1"], [f], needles=[name])
        add("crafted set", f"tune {name}", ["tune", f, "--folds", "2", "--repeats", "1",
                                           "--grid-points", "3", "--refine-points", "0",
                                           "--threads", "1"], [f], needles=[name])
    add("crafted set", "render --data set_nan_x.h5",
        ["render", I["m.h5"], "-o", O, "--command", "0", "--marginalise", "--data",
         I["set_nan_x.h5"]],
        [I["m.h5"], I["set_nan_x.h5"]], out=O, kind="png", needles=["set_nan_x.h5"],
        display="xvfb")

    # --- crafted models (zero components, non-finite / overflowing weights, asymmetric,
    #     non-SPD, version 1, vlen strings, huge declared K) ---
    crafted_models = sorted(k for k in I if k.startswith("m_") and k.endswith(".h5") and
                            "_cut" not in k and "_flip" not in k and k != "m_pose1.h5")
    for name in crafted_models:
        f = I[name]
        for cmd, mk, kind, _ in model_cmds:
            add("crafted model", f"{cmd} {name}", mk(f), [f, I["set.h5"], I["m.h5"]],
                out=O if kind else None, kind=kind, needles=[name])
    for name in ["m_weight_1e308.h5", "m_zero_components.h5", "m_asymmetric.h5", "m_weight_nan.h5"]:
        f = I[name]
        add("crafted model", f"render {name}", ["render", f, "-o", O, "--command", "0",
                                                "--marginalise"],
            [f], out=O, kind="png", needles=[name], display="xvfb")

    # --- CSV import ---
    imp = lambda f, *extra: ["import", f, "-o", O, "--command-cols", "c", "--pose-cols",  # noqa
                             "x,y", "--terrain-cols", "z"] + list(extra)
    for name in ["nan.csv", "nan_lower.csv", "inf.csv", "neg_inf.csv", "big_exp.csv",
                 "text_cell.csv", "empty_cell.csv", "ragged.csv", "ragged_long.csv",
                 "header_only.csv", "no_header_match.csv", "dup_header.csv", "empty.csv",
                 "huge_cell.csv", "binary.csv", "utf16.csv"]:
        add("CSV import", f"import {name}", imp(I[name]), [I[name]], out=O, kind="h5_set",
            needles=[name])
    # +-1e308 cells: the standard deviation must be computed without overflowing (read, not refused).
    add("CSV import (valid)", "import overflow_std.csv --standardize",
        imp(I["overflow_std.csv"], "--standardize"), [I["overflow_std.csv"]], out=O,
        kind="h5_set", expect="accept")
    for name in ["cr_only.csv", "crlf.csv", "tiny.csv", "long_small.csv"]:
        add("CSV import (valid)", f"import {name}", imp(I[name]), [I[name]], out=O,
            kind="h5_set", expect="accept")
    for name in ["episode_1e12.csv", "episode_frac.csv"]:
        add("CSV import", f"import {name} --episode-col e",
            ["import", I[name], "-o", O, "--pose-cols", "x,y", "--episode-col", "e"], [I[name]],
            out=O, kind="h5_set", needles=[name])
    g = I["good.csv"]
    for label, extra, needle in [
            ("--units x=furlong", ["--units", "x=furlong"], "furlong"),
            ("--units q=m", ["--units", "q=m"], "q"),
            ("--delimiter ::", ["--delimiter", "::"], "delimiter"),
            ("--pose-cols ''", None, "column"),
            ("--episode-col nosuch", ["--episode-col", "nosuch"], "nosuch")]:
        args = imp(g, *extra) if extra is not None else ["import", g, "-o", O, "--pose-cols", ""]
        add("CSV import", f"import good.csv {label}", args, [g], out=O, kind="h5_set",
            needles=[needle])
    add("CSV import", "import folder", imp(I["folder.csv"]), [], out=O, kind="h5_set",
        needles=["folder.csv"])
    add("CSV import", "import missing file", imp(I["missing.csv"]), [], out=O, kind="h5_set",
        needles=["missing.csv"])

    # --- import-log ---
    def log(commands=None, pose=None, imu=None, extra=()):
        return (["import-log", "--commands", commands or I["log_commands.csv"], "--command-cols",
                 "mode", "--pose", pose or I["log_pose.csv"], "--pose-cols",
                 "x_mm,y_mm,yaw_deg", "--attitude", imu or I["log_imu.csv"], "--attitude-time",
                 "t_ms", "--terrain-cols", "pitch_deg,roll_deg", "--units",
                 "x_mm=mm,y_mm=mm,yaw_deg=deg,t_ms=ms,pitch_deg=deg,roll_deg=deg", "--window",
                 "1.5", "-o", O] + list(extra))
    logs = [I["log_commands.csv"], I["log_pose.csv"], I["log_imu.csv"]]
    for label, args, needle in [
            ("NaN time in commands", log(commands=I["log_nan_commands.csv"]), "log_nan_commands"),
            ("NaN time in pose", log(pose=I["log_nan_pose.csv"]), "log_nan_pose"),
            ("NaN time in imu", log(imu=I["log_nan_imu.csv"]), "log_nan_imu"),
            ("time going backwards", log(pose=I["log_backwards_pose.csv"]), "log_backwards"),
            ("pose header only", log(pose=I["log_header_pose.csv"]), "log_header_pose"),
            ("pose is a folder", log(pose=I["folder.csv"]), "folder.csv"),
            ("commands missing", log(commands=I["missing.csv"]), "missing.csv"),
            ("pose with CR-only? binary", log(pose=I["binary.csv"]), "binary.csv"),
            ("--gap -1", log(extra=["--gap", "-1"]), "--gap"),
            ("--window nan", log(extra=["--window", "nan"]), "--window"),
            ("--bins -3", log(extra=["--bins", "-3"]), "--bins"),
            ("unknown unit", log(extra=["--units", "x_mm=parsec"]), "parsec")]:
        add("import-log", f"import-log {label}", args, logs + [I["log_nan_commands.csv"],
                                                              I["log_nan_pose.csv"]],
            out=O, kind="h5_set", needles=[needle])

    # --- info, missing / folder / empty / text ---
    for name in ["missing.h5", "folder.h5", "empty.h5", "text.h5", "good.csv"]:
        add("not a dgmm file", f"info {name}", ["info", I[name]], [I[name]], needles=[name])
        add("not a dgmm file", f"fit {name}", ["fit", I[name], "-o", O], [I[name]], out=O,
            kind="h5_model", needles=[name])
        add("not a dgmm file", f"score m.h5 {name}", ["score", I["m.h5"], I[name]],
            [I[name], I["m.h5"]], needles=[name])
    add("not a dgmm file", "fit: a model where a set is expected", ["fit", I["m.h5"], "-o", O],
        [I["m.h5"]], out=O, kind="h5_model", needles=["m.h5"])
    add("not a dgmm file", "score: a set where a model is expected",
        ["score", I["set.h5"], I["set.h5"]], [I["set.h5"]], needles=["set.h5"])

    # --- options without an answer ---
    s = I["set.h5"]
    fit = lambda *extra: ["fit", s, "-o", O] + list(extra)  # noqa: E731
    for label, extra, needle in [
            ("--k 0", ["--k", "0"], "--k"), ("--k -1", ["--k", "-1"], "--k"),
            ("--k nan", ["--k", "nan"], "--k"), ("--k inf", ["--k", "inf"], "--k"),
            ("--chunk-rows 0", ["--chunk-rows", "0"], "--chunk-rows"),
            ("--chunk-rows -5", ["--chunk-rows", "-5"], "--chunk-rows"),
            ("--max-components 0", ["--max-components", "0"], "--max-components"),
            ("--max-components -1", ["--max-components", "-1"], "--max-components"),
            ("--init-cov 1,2 (3 dimensions)", ["--init-cov", "1,2"], "--init-cov"),
            ("--init-cov -1", ["--init-cov", "-1"], "--init-cov"),
            ("--init-scale 0", ["--init-scale", "0"], "--init-scale"),
            ("--floor -1", ["--floor", "-1"], "--floor"),
            ("--floor nan", ["--floor", "nan"], "--floor"),
            ("--floor-relative inf", ["--floor-relative", "inf"], "--floor-relative"),
            ("--prior-count 0", ["--prior-count", "0"], "--prior-count"),
            ("--variant bogus", ["--variant", "bogus"], "--variant"),
            ("--covariance bogus", ["--covariance", "bogus"], "--covariance")]:
        add("bad option", f"fit {label}", fit(*extra), [s], out=O, kind="h5_model",
            needles=[needle])
    em = lambda *extra: ["em", s, "-o", O] + list(extra)  # noqa: E731
    for label, extra, needle in [
            ("--components 0", ["--components", "0"], "--components"),
            ("--components -2", ["--components", "-2"], "--components"),
            ("--components 1000 (> samples)", ["--components", "1000"], "--components"),
            ("--reg-covar -1", ["--reg-covar", "-1"], "--reg-covar"),
            ("--tol nan", ["--tol", "nan"], "--tol"),
            ("--n-init 0", ["--n-init", "0"], "--n-init")]:
        add("bad option", f"em {label}", em(*extra), [s], out=O, kind="h5_model",
            needles=[needle])
    cv = lambda *extra: ["cv", s, "--repeats", "1", "--no-em", "--threads", "1"] + list(extra)  # noqa
    for label, extra, needle in [
            ("--folds 100000", ["--folds", "100000"], "--folds"),
            ("--folds 201 (> 200 samples)", ["--folds", "201"], "--folds"),
            ("--folds 1", ["--folds", "1"], "--folds"),
            ("--folds 0", ["--folds", "0"], "--folds"),
            ("--repeats 0", ["--repeats", "0"], "--repeats"),
            ("--k 0", ["--k", "0"], "--k"),
            ("--threads -1", ["--threads", "-1"], "--threads"),
            ("--pose-dims nosuch", ["--pose-dims", "nosuch"], "nosuch")]:
        add("bad option", f"cv {label}", cv(*extra), [s], needles=[needle])
    add("bad option", "cv --em-max-components 0",
        ["cv", s, "--repeats", "1", "--folds", "2", "--threads", "1", "--em-max-components", "0"],
        [s], needles=["--em-max-components"])
    tune = lambda *extra: ["tune", s, "--repeats", "1", "--threads", "1", "--grid-points", "3",  # noqa
                           "--refine-points", "0"] + list(extra)
    for label, extra, needle in [
            ("--folds 100000", ["--folds", "100000"], "--folds"),
            ("--k-min 0", ["--k-min", "0"], "--k-min"),
            ("--k-min 10 --k-max 1", ["--k-min", "10", "--k-max", "1"], "--k-m"),
            ("--grid-points 0", ["--grid-points", "0"], "--grid-points"),
            ("--init-scales -1", ["--init-scales", "-1"], "--init-scales")]:
        add("bad option", f"tune {label}", tune(*extra), [s], needles=[needle])
    add("bad option", "tune --folds 100000 with --curve-csv",
        tune("--folds", "100000", "--curve-csv", O), [s], out=O, kind="csv", needles=["--folds"])
    sc = lambda *extra: ["score", I["m.h5"], s] + list(extra)  # noqa: E731
    add("bad option", "score --chunk-rows 0", sc("--chunk-rows", "0"), [s, I["m.h5"]],
        needles=["--chunk-rows"])
    add("wrong dimensions", "score: model 3-D, set 2-D", ["score", I["m.h5"], I["set_pose1.h5"]],
        [I["m.h5"], I["set_pose1.h5"]], needles=["set_pose1.h5"])
    add("wrong dimensions", "score: model 2-D, set 3-D", ["score", I["m_pose1.h5"], s],
        [I["m_pose1.h5"], s], needles=["set.h5"])
    add("wrong dimensions", "mise: 3-D vs 2-D", ["mise", I["m.h5"], I["m_pose1.h5"],
                                                 "--command", "0"],
        [I["m.h5"], I["m_pose1.h5"]], needles=["m_pose1.h5"])
    add("wrong dimensions", "mise: unknown command", ["mise", I["m.h5"], I["em.h5"], "--command",
                                                     "nosuch"], [I["m.h5"], I["em.h5"]],
        needles=["nosuch"])
    add("wrong dimensions", "render --x-dim nosuch",
        ["render", I["m.h5"], "-o", O, "--command", "0", "--x-dim", "nosuch"], [I["m.h5"]],
        out=O, kind="png", needles=["nosuch"], display="xvfb")

    # --- render: conditions far off, odd sizes; with and without a display ---
    for disp in ["none", "xvfb"]:
        for label, extra, needle in [
                ("--condition z=1e308", ["--condition", "z=1e308"], "z"),
                ("--condition z=-1e308", ["--condition", "z=-1e308"], "z"),
                ("--condition z=nan", ["--condition", "z=nan"], "z"),
                ("--condition nosuch=1", ["--condition", "nosuch=1"], "nosuch"),
                ("--grid 0", ["--grid", "0", "--marginalise"], "--grid"),
                ("--size 0x0", ["--size", "0x0", "--marginalise"], "--size"),
                ("--window 1,0,0,1", ["--window", "1,0,0,1", "--marginalise"], "--window"),
                ("--color-scale bogus", ["--color-scale", "bogus", "--marginalise"],
                 "--color-scale")]:
            # Without a display a render is refused for that reason or for a flag checked first.
            add("render", f"render {label} (display: {disp})",
                ["render", I["m.h5"], "-o", O, "--command", "0"] + extra, [I["m.h5"]], out=O,
                kind="png", needles=[needle] + ([] if disp == "xvfb" else ["display"]),
                display=disp)
    add("render", "render --diff with one model (display: xvfb)",
        ["render", I["m.h5"], "-o", O, "--diff"], [I["m.h5"]], out=O, kind="png",
        needles=["--diff"], display="xvfb")
    add("render", "render without a display", ["render", I["m.h5"], "-o", O, "--command", "0"],
        [I["m.h5"]], out=O, kind="png", needles=["display"], display="none")

    # --- output == input ---
    def same(cmd_label, args, path):
        add("output = input", cmd_label, args, [path], out=None, needles=[b(path)],
            display="xvfb")
    same("fit set.h5 -o set.h5", ["fit", s, "-o", s], s)
    same("fit set.h5 -o ./set.h5", ["fit", s, "-o", os.path.join(os.path.dirname(s), ".",
                                                                 "set.h5")], s)
    same("em set.h5 -o set.h5", ["em", s, "-o", s], s)
    same("export m.h5 -o m.h5", ["export", I["m.h5"], "-o", I["m.h5"]], I["m.h5"])
    same("import good.csv -o good.csv", ["import", g, "-o", g, "--pose-cols", "x,y"], g)
    same("simulate --config c.json -o c.json",
         ["simulate", "--config", I["cfg_good.json"], "-o", I["cfg_good.json"]],
         I["cfg_good.json"])
    same("robot-draft robot.xml -o robot.xml", ["robot-draft", I["robot.xml"], "-o", I["robot.xml"]],
         I["robot.xml"])
    same("upgrade set_v1.h5 -o set_v1.h5", ["upgrade", I["set_v1.h5"], "-o", I["set_v1.h5"]],
         I["set_v1.h5"])
    same("render m.h5 -o m.h5", ["render", I["m.h5"], "-o", I["m.h5"], "--command", "0"],
         I["m.h5"])
    same("render --data set.h5 -o set.h5",
         ["render", I["m.h5"], "--data", s, "-o", s, "--command", "0"], s)
    same("import-log -o commands.csv", log()[:-1] + [I["log_commands.csv"]],
         I["log_commands.csv"])
    for flag in ["--curve-csv", "--plot"]:
        same(f"tune set.h5 {flag} set.h5", ["tune", s, "--folds", "2", "--repeats", "1",
                                            "--grid-points", "3", "--refine-points", "0",
                                            "--threads", "1", flag, s], s)

    # --- simulate: malformed configs ---
    for name in ["cfg_bad.json", "cfg_1e400.json", "cfg_type.json", "cfg_negative.json",
                 "cfg_unknown.json", "cfg_array.json", "cfg_nan.json", "cfg_empty.json",
                 "folder.json", "missing.json"]:
        add("simulate", f"simulate --config {name}",
            ["simulate", "--config", I[name], "-o", O, "--placements", "1", "--executions", "1"],
            [I[name]], out=O, kind="h5_set", needles=[name])
    for label, extra, needle in [("--placements -1", ["--placements", "-1"], "--placements"),
                                 ("--executions 0", ["--executions", "0"], "--executions"),
                                 ("--protocol bogus", ["--protocol", "bogus"], "--protocol")]:
        add("simulate", f"simulate {label}", ["simulate", "-o", O] + extra, [], out=O,
            kind="h5_set", needles=[needle])

    # --- robot-draft: models it cannot read or draft, flags it cannot take ---
    for name, extra, needle in [("robot_bad.xml", [], "robot_bad.xml"), ("missing.json", [], "missing.json"),
                                ("robot.xml", ["--forward-axis", "0,0,1"], "forward_axis"),
                                ("robot.xml", ["--forward-axis", "1,0"], "--forward-axis"),
                                ("robot.xml", ["--foot-band", "2"], "foot_band")]:
        add("robot-draft", f"robot-draft {name} {' '.join(extra)}".strip(),
            ["robot-draft", I[name], "-o", O] + extra, [I[name]], out=O, kind="json", needles=[needle])

    # --- sim2real ---
    def s2r(sim, real, *extra):
        return ["sim2real", "--sim", sim, "--real", real, "-o", O, "--no-figures", "--bootstrap",
                "0", "--permutations", "50", "--cache", "-"] + list(extra)
    sim, real = I["sim"], I["real"]
    for label, args, ins, needle in [
            ("identical --sim/--real", s2r(sim, sim), [sim], "sim.h5"),
            ("--real a byte copy of --sim", s2r(sim, I["sim_copy.h5"]), [sim, I["sim_copy.h5"]],
             "sim_copy.h5"),
            ("malformed --sim-config", s2r(sim, real, "--sim-config", I["cfg_bad.json"]),
             [sim, real, I["cfg_bad.json"]], "cfg_bad.json"),
            ("--sim-config 1e400", s2r(sim, real, "--sim-config", I["cfg_1e400.json"]),
             [sim, real, I["cfg_1e400.json"]], "cfg_1e400.json"),
            ("--sim-config a folder", s2r(sim, real, "--sim-config", I["folder.json"]),
             [sim, real], "folder.json"),
            ("--sim-config missing", s2r(sim, real, "--sim-config", I["missing.json"]),
             [sim, real], "missing.json"),
            ("--real missing", s2r(sim, I["missing.h5"]), [sim], "missing.h5"),
            ("--real zero rows", s2r(sim, I["set_zero_rows.h5"]), [sim, I["set_zero_rows.h5"]],
             "set_zero_rows.h5"),
            ("--real other dimensions", s2r(sim, I["set.h5"]), [sim, I["set.h5"]], "set.h5"),
            ("--real mutated", s2r(sim, I["set_flip1.h5"]), [sim, I["set_flip1.h5"]],
             "set_flip1.h5"),
            ("--real version 1", s2r(sim, I["set_v1.h5"]), [sim, I["set_v1.h5"]], "set_v1.h5"),
            ("--threads -1", s2r(sim, real, "--threads", "-1"), [sim, real], "--threads"),
            ("--sim a model", s2r(I["m.h5"], real), [I["m.h5"], real], "m.h5")]:
        add("sim2real", f"sim2real {label}", args, ins, out=O, kind="dir", needles=[needle])
    add("sim2real", "sim2real -o an input file",
        ["sim2real", "--sim", sim, "--real", real, "-o", I["good.csv"], "--no-figures",
         "--bootstrap", "0", "--cache", "-"], [sim, real, g], needles=["good.csv"])
    add("sim2real", "sim2real -o a folder that is not a report",
        s2r(sim, real), [sim, real], out=O, kind="logdir", needles=["report.json"])

    # --- upgrade ---
    add("upgrade", "upgrade a version-2 file (writes nothing)", ["upgrade", s, "-o", O], [s],
        out=O, kind="h5_set", expect="accept-no-output")
    for name in ["missing.h5", "text.h5", "set_v1_cut.h5", "set_v1_flip.h5", "folder.h5",
                 "m_cut3.h5"]:
        add("upgrade", f"upgrade {name}", ["upgrade", I[name], "-o", O], [I[name]], out=O,
            kind="h5_set", needles=[name])

    # --- unknown commands and usage errors ---
    for label, args, needle in [
            ("unknown command", ["frobnicate"], "frobnicate"),
            ("no command", [], "command"),
            ("fit without arguments", ["fit"], "set"),
            ("unknown option", ["fit", s, "-o", O, "--frobnicate"], "--frobnicate"),
            ("extra positional", ["info", s, s], s),
            ("--k without value", ["fit", s, "-o", O, "--k"], "--k")]:
        add("usage", label, args, [s], out=O if "-o" in args else None,
            kind="h5_model" if "-o" in args else None, needles=[needle])

    # --- refused because the answer is empty ---
    add("no answer", "fit set_zero_rows.h5 (older model must stay)",
        ["fit", I["set_zero_rows.h5"], "-o", O], [I["set_zero_rows.h5"]], out=O,
        kind="h5_model", needles=["set_zero_rows.h5"])
    add("no answer", "fit with --k 1e-9 (valid; capped)", ["fit", s, "-o", O, "--k", "1e-9"], [s],
        out=O, kind="h5_model", expect="accept")
    add("no answer", "em --max-iter 0 (valid: k-means only)", ["em", s, "-o", O, "--max-iter",
                                                              "0"], [s], out=O, kind="h5_model",
        expect="accept")

    # --- disk full (ulimit -f) ---
    fs_limit = 16 << 10
    add("disk full", "import big.csv (16 KiB file limit)",
        ["import", I["big.csv"], "-o", O, "--pose-cols", "x,y"], [I["big.csv"]], out=O,
        kind="h5_set", needles=["disk full"], fsize=fs_limit)
    add("disk full", "fit (4 KiB file limit)", ["fit", s, "-o", O], [s], out=O, kind="h5_model",
        needles=["disk full"], fsize=4096)
    add("disk full", "em (4 KiB file limit)", ["em", s, "-o", O], [s], out=O, kind="h5_model",
        needles=["disk full"], fsize=4096)
    add("disk full", "export (1 KiB file limit)", ["export", I["m.h5"], "-o", O], [I["m.h5"]],
        out=O, kind="json", needles=["disk full"], fsize=1024)
    add("disk full", "simulate (4 KiB file limit)",
        ["simulate", "-o", O, "--placements", "1", "--executions", "1"], [], out=O,
        kind="h5_set", needles=["disk full"], fsize=4096)
    add("disk full", "render (2 KiB file limit)",
        ["render", I["m.h5"], "-o", O, "--command", "0", "--grid", "40", "--marginalise"],
        [I["m.h5"]], out=O,
        kind="png", needles=["disk full"], fsize=2048, display="xvfb")
    add("disk full", "sim2real (64 KiB file limit)", s2r(sim, real), [sim, real], out=O,
        kind="dir", needles=["disk full"], fsize=64 << 10)
    add("disk full", "upgrade (4 KiB file limit)", ["upgrade", I["set_v1.h5"], "-o", O],
        [I["set_v1.h5"]], out=O, kind="h5_set", needles=["disk full"], fsize=4096)
    return C


# ----------------------------------------------------------------------------------------------
# Running


NAN_RE = re.compile(r"(?<![A-Za-z_])-?nan(?![A-Za-z_])", re.IGNORECASE)


def temp_leftovers(dirs):
    found = []
    for d in dirs:
        if os.path.isdir(d):
            found += [os.path.join(d, n) for n in os.listdir(d) if ".tmp-" in n]
    return found


def run_case(dgmm, case, variant, w, older, pristine, timeout, xvfb_display):
    run_dir = os.path.join(w, "runs", f"{case.index:03d}-{variant}")
    os.makedirs(run_dir)
    out = None
    if case.out:
        ext = {"h5_set": ".h5", "h5_model": ".h5", "json": ".json", "png": ".png",
               "csv": ".csv", "dir": "", "logdir": ""}[case.kind]
        out = os.path.join(run_dir, "out" + ext)
        if variant == "older" or case.kind == "logdir":
            src = older[case.kind]
            if os.path.isdir(src):
                shutil.copytree(src, out)
            else:
                shutil.copyfile(src, out)
    args = [a.replace("{OUT}", out) if out else a for a in case.args]
    before = {p: sha(p) for p in case.inputs}
    out_before = sha(out) if out else None
    env = dict(os.environ)
    env.pop("DISPLAY", None)
    if case.display == "xvfb":
        env["DISPLAY"] = xvfb_display

    def limits():
        if case.fsize:
            resource.setrlimit(resource.RLIMIT_FSIZE, (case.fsize, case.fsize))
        os.setsid()
    t0 = time.monotonic()
    p = subprocess.Popen([dgmm, "--quiet"] + args, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, env=env, preexec_fn=limits, cwd=run_dir)
    hang = False
    try:
        stdout, stderr = p.communicate(timeout=case.timeout or timeout)
    except subprocess.TimeoutExpired:
        hang = True
        os.killpg(p.pid, signal.SIGKILL)
        stdout, stderr = p.communicate()
    seconds = time.monotonic() - t0
    code = p.returncode
    stdout = stdout.decode("utf-8", "replace")
    stderr = stderr.decode("utf-8", "replace")
    refused = code != 0
    res = {"exit": code, "seconds": seconds, "stderr": stderr.strip(), "problems": {}}
    pr = res["problems"]
    if hang:
        pr["hang"] = f"killed after {case.timeout or timeout} s"
    elif code < 0:
        pr["crash"] = f"signal {-code} ({signal.Signals(-code).name})"
    changed = [p_ for p_ in case.inputs if sha(p_) != before[p_]]
    if changed:
        pr["input"] = "changed: " + ", ".join(os.path.basename(c) for c in changed)
        for c in changed:  # restore for the next cases
            if c in pristine:
                if os.path.isdir(c):
                    shutil.rmtree(c)
                shutil.copyfile(pristine[c], c)
    if out:
        now = sha(out)
        if refused or hang or code < 0:
            if out_before is not None and now != out_before:
                pr["clobber"] = "older output changed" if now else "older output removed"
            if out_before is None and now is not None:
                pr["partial"] = "output created by a refused run"
        elif case.expect == "accept-no-output" and now != out_before:
            pr["partial" if out_before is None else "clobber"] = "output written where none was expected"
    leftovers = temp_leftovers([run_dir] + [os.path.dirname(p_) for p_ in case.inputs])
    if leftovers:
        pr["partial"] = (pr.get("partial", "") + " temporary left: " +
                         ", ".join(os.path.basename(x) for x in leftovers)).strip()
        for x in leftovers:
            shutil.rmtree(x, ignore_errors=True) if os.path.isdir(x) else os.remove(x)
    if code == 0 and not hang:
        if case.expect == "refuse":
            pr["silent"] = "exit 0 on a case without an answer"
        if NAN_RE.search(stdout):
            pr["silent"] = "'nan' on stdout with exit 0"
    if case.expect in ("accept", "accept-no-output") and code != 0 and not hang and code > 0:
        pr["silent"] = f"valid input refused (exit {code}): {stderr.strip()[:120]}"
    if refused and code > 0 and case.expect != "accept":
        lines = [ln for ln in stderr.splitlines() if ln.strip()]
        msg = stderr.strip()
        why = []
        if len(lines) != 1:
            why.append(f"{len(lines)} lines")
        if len(msg) > 300:
            why.append(f"{len(msg)} characters")
        if case.needles and not any(n.lower() in msg.lower() for n in case.needles):
            why.append("does not name " + " or ".join(repr(n) for n in case.needles))
        if why:
            pr["message"] = "; ".join(why)
    shutil.rmtree(run_dir, ignore_errors=True)
    return res


def start_xvfb():
    """A private Xvfb for the cases run 'under a display' (as scripts/with-display.sh would)."""
    if os.environ.get("DISPLAY"):
        return os.environ["DISPLAY"], None
    for n in range(90, 140):
        if os.path.exists(f"/tmp/.X11-unix/X{n}") or os.path.exists(f"/tmp/.X{n}-lock"):
            continue
        proc = subprocess.Popen(["Xvfb", f":{n}", "-screen", "0", "1920x1080x24", "-nolisten",
                                 "tcp"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        for _ in range(50):
            if os.path.exists(f"/tmp/.X11-unix/X{n}"):
                return f":{n}", proc
            time.sleep(0.1)
        proc.kill()
    sys.exit("cannot start Xvfb")


def markdown(results, cmdline, seed, total_seconds):
    cats = {}
    for case, runs in results:
        c = cats.setdefault(case.category, {"cases": 0, "runs": 0, **{k: 0 for k in CHECKS}})
        c["cases"] += 1
        for variant, r in runs.items():
            c["runs"] += 1
            for k in r["problems"]:
                c[k] += 1
    lines = [f"Command: `{cmdline}` (seed {seed}; {len(results)} cases, "
             f"{sum(len(r) for _, r in results)} runs, {total_seconds:.0f} s).", "",
             "| category | cases | runs | " + " | ".join(CHECKS) + " |",
             "|---|---|---|" + "---|" * len(CHECKS)]
    tot = {"cases": 0, "runs": 0, **{k: 0 for k in CHECKS}}
    for cat, c in cats.items():
        lines.append(f"| {cat} | {c['cases']} | {c['runs']} | " +
                     " | ".join(str(c[k]) for k in CHECKS) + " |")
        for k in tot:
            tot[k] += c[k]
    lines.append(f"| **all** | **{tot['cases']}** | **{tot['runs']}** | " +
                 " | ".join(f"**{tot[k]}**" for k in CHECKS) + " |")
    either = [r for case, runs in results if case.expect == "either" for r in runs.values()]
    read = sum(r["exit"] == 0 for r in either)
    failures = [(case, v, r) for case, runs in results for v, r in runs.items() if r["problems"]]
    lines += ["", f"Byte-flipped files read without error (the flip hit nothing that is checked, "
              f"e.g. padding): {read} of {len(either)} runs; the others were refused.", "",
              f"Runs with a problem: {len(failures)}."]
    if failures:
        lines += ["", "| case | run | exit | problems | stderr |", "|---|---|---|---|---|"]
        for case, v, r in failures:
            probs = "; ".join(f"{k}: {t}" for k, t in r["problems"].items())
            err = r["stderr"].replace("|", "\\|").replace("\n", " / ")[:160]
            lines.append(f"| {case.name} | {v} | {r['exit']} | {probs} | {err} |")
    return "\n".join(lines) + "\n", tot


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dgmm")
    ap.add_argument("workdir")
    ap.add_argument("--seed", type=int, default=13)
    ap.add_argument("--timeout", type=float, default=60)
    ap.add_argument("--only", default="", help="run only cases whose name contains this")
    ap.add_argument("--markdown", default="", help="write the summary table here")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    a = ap.parse_args()
    dgmm = os.path.abspath(a.dgmm)
    w = os.path.abspath(a.workdir)
    if os.path.exists(w):
        shutil.rmtree(w)
    os.makedirs(w)
    t0 = time.monotonic()
    inp = make_inputs(dgmm, w, a.seed)
    older = make_older_outputs(dgmm, w, inp)
    pristine_dir = os.path.join(w, "pristine")
    os.makedirs(pristine_dir)
    pristine = {}
    for k, p in inp.items():
        if os.path.isfile(p):
            q = os.path.join(pristine_dir, f"{len(pristine)}-{os.path.basename(p)}")
            shutil.copyfile(p, q)
            pristine[p] = q
    all_cases = cases(inp, a.seed)
    for i, c in enumerate(all_cases):
        c.index = i
    if a.list:
        for c in all_cases:
            print(f"{c.index:3d} [{c.category}] {c.name}")
        return 0
    selected = [c for c in all_cases if a.only in c.name]
    display, xvfb = start_xvfb()
    results = []
    try:
        for c in selected:
            runs = {}
            for variant in ["fresh", "older"]:
                runs[variant] = run_case(dgmm, c, variant, w, older, pristine, a.timeout, display)
            results.append((c, runs))
            bad = {v: r["problems"] for v, r in runs.items() if r["problems"]}
            status = "ok" if not bad else "PROBLEM " + str(bad)
            print(f"{c.index:3d} {c.name}: exit {runs['fresh']['exit']}/{runs['older']['exit']} "
                  f"{status}", flush=True)
    finally:
        if xvfb:
            xvfb.terminate()
            xvfb.wait()
    cmdline = ("/usr/bin/python3 scripts/bad_input_battery.py build/app/dgmm <workdir> "
               f"--seed {a.seed}" + (f" --only '{a.only}'" if a.only else ""))
    md, tot = markdown(results, cmdline, a.seed, time.monotonic() - t0)
    print()
    print(md)
    if a.markdown:
        write(a.markdown, md)
    return 1 if any(tot[k] for k in CHECKS) else 0


if __name__ == "__main__":
    sys.exit(main())
