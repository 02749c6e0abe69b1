#!/usr/bin/env python3
"""Blinded battery for `dgmm sim2real` (issue #9, "Proof, blinded"; docs/sim2real.md).

For every seed of a range it draws a concealed pair (scripts/sim2real_battery_draw.py): a robot,
nulls / one effect / two effects / an effect outside every library, physics planted through the sim
config JSON and an edited copy of the MJCF, measurement effects planted in the recorded set with
h5py. Per robot one nominal sim set is recorded once (paper protocol, 166 placements) and reused;
each pair's "real" set is simulated with the concealed change and another seed (paper protocol,
78 placements). The truth (config, MJCF, truth.json) stays in OUT/truth/, which the analysis is
never given; the real set's metadata that would reveal it (its sim config, seed, robot mass) is
replaced by the nominal robot's. Then

    dgmm sim2real --sim <nominal sim set> --real <pair>/real.h5 --sim-config <nominal config>
                  -o <pair>/analysis --no-figures

runs per pair and its report.json verdict is scored against the truth
(scripts/sim2real_battery_score.py). Writes OUT/results.json (every pair), OUT/battery.md (a
confusion matrix and the targets table) and with --write-doc the section `sim2real-battery` of
docs/sim2real.md.

Seed ranges: DEV 1000-1999 (what the method may be developed on), REPORT 5000-5039 (run once).
Draw version 2 (from seed range 11000) adds the solimp contact option and the backlash
family and plants tracker noise through the config; draw version 3 (the default) adds one-leg
geometry and mass edits out of the library (a shorter tibia, a larger foot, a hip mounted off
its place, a mass on one leg), with a quarter of the pairs out of the library and fewer two-effect pairs;
--draw-version 1 redraws the ranges up to 10000-10039 exactly as they were.

Usage: scripts/sim2real_battery.py --seeds 1000-1009 [--jobs 2] [--build build] [--out DIR]
       [--keep] [--smoke] [--generate-only] [--write-doc] [--draw-version {1,2,3}]
       [--protocol {paper,continuous}]
       [--rerun] [--sim2real-args 'ARGS']
"""
import argparse
import concurrent.futures as cf
import json
import os
import shlex
import shutil
import subprocess
import sys
import threading
import time

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import sim2real_battery_draw as draw  # noqa: E402
import sim2real_battery_score as score  # noqa: E402
import sim2real_battery_tables as tables  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ROBOTS = {  # name -> nominal sim config; MJCF of the built-in robot for MJCF edits
    "scorpion": {"config": "datasets/robots/default.json", "mjcf": "datasets/robots/scorpion.xml",
                 "sim_seed": 100},
    "harvestman": {"config": "datasets/robots/harvestman.json",
                   "mjcf": "datasets/robots/harvestman.xml", "sim_seed": 200},
}
SIM_PLACEMENTS, SMOKE_SIM_PLACEMENTS, SMOKE_REAL_PLACEMENTS = 166, 40, 20
LOCK = threading.Lock()
# Metadata of the real set that would reveal the concealed change: its config, seed and mass, and its
# recording's summary (falls, the executions that started tilted, the warnings `dgmm sim2real` relays).
REVEALING_METADATA = ("sim_config", "seed", "robot_mass_kg", "falls", "abandoned_placements", "executions",
                      "tilted_executions", "recording_warnings")


def log(msg):
    print(f"[battery {time.strftime('%H:%M:%S')}] {msg}", flush=True)


def run(cmd, **kw):
    """Runs a command niced; raises with its stderr on failure."""
    p = subprocess.run(["nice", "-n", "5"] + cmd, capture_output=True, text=True, **kw)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {p.returncode}: {p.stderr.strip()[-2000:]}")
    return p


def load_nominals():
    out = {}
    for name, r in ROBOTS.items():
        with open(os.path.join(ROOT, r["config"])) as f:
            out[name] = json.load(f)
    return out


def config_path(robot):
    return os.path.join(ROOT, ROBOTS[robot]["config"])


def absolute_config(robot, cfg):
    """The config with mjcf_path made absolute (relative paths are against the config's folder)."""
    cfg = dict(cfg)
    if cfg.get("mjcf_path"):
        cfg["mjcf_path"] = os.path.normpath(os.path.join(os.path.dirname(config_path(robot)),
                                                         cfg["mjcf_path"]))
    return cfg


def sim_set(args, robot):
    """Path of the cached nominal sim set of `robot` (recorded on first use)."""
    placements = SMOKE_SIM_PLACEMENTS if args.smoke else SIM_PLACEMENTS
    tag = "" if args.protocol == "paper" else f"_{args.protocol}"
    path = os.path.join(args.out, "cache", f"{robot}_sim_p{placements}{tag}.h5")
    if not os.path.exists(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        log(f"recording the nominal sim set of {robot} ({placements} placements)")
        t = time.time()
        run([args.dgmm, "simulate", "--config", config_path(robot), "--protocol", args.protocol,
             "--placements", str(placements), "--seed", str(ROBOTS[robot]["sim_seed"]),
             "-o", path])
        log(f"  {robot} sim set: {time.time() - t:.0f} s wall")
    return path


def set_string_attr(attrs, name, value, like):
    """Writes a string attribute with the string type of `like` (fixed- or variable-length)."""
    if name in attrs:
        del attrs[name]
    info = h5py.check_string_dtype(like.dtype) if like is not None else None
    if info is not None and info.length is not None:
        data = value.encode()
        attrs.create(name, data, dtype=h5py.string_dtype("utf-8", max(1, len(data))))
    else:
        attrs[name] = value


def conceal_metadata(real_path, sim_path):
    """Replaces the real set's revealing metadata by the nominal sim set's."""
    with h5py.File(sim_path, "r") as s, h5py.File(real_path, "r+") as r:
        sm, rm = s["metadata"].attrs, r["metadata"].attrs
        for key in REVEALING_METADATA:
            if key in sm:
                value = sm[key]
                value = value.decode() if isinstance(value, bytes) else str(value)
                set_string_attr(rm, key, "concealed" if key == "seed" else value,
                                sm.get_id(key))
            elif key in rm:
                del rm[key]


def column(names, name):
    names = [n.decode() if isinstance(n, bytes) else str(n) for n in names]
    return names.index(name)


def apply_data_edits(real_path, effects, seed):
    """Plants measurement and out-of-library effects in the recorded set (in place)."""
    rng = np.random.default_rng(seed + 7919)
    with h5py.File(real_path, "r+") as f:
        x, z = f["x"][...], f["z"][...]
        xn, zn = f["x"].attrs["names"], f["z"].attrs["names"]
        step, episode = f["step"][...], f["episode"][...]
        for e in effects:
            d = e.get("data") or {}
            for k, v in (d.get("x_add") or {}).items():
                x[:, column(xn, k)] += v
            for k, v in (d.get("z_add") or {}).items():
                z[:, column(zn, k)] += v
            for k, sd in (d.get("x_noise_sd") or {}).items():
                x[:, column(xn, k)] += rng.normal(0.0, sd, len(x))
            if "periodic" in d:
                p = d["periodic"]
                x[:, column(xn, p["column"])] += p["amp"] * np.sin(
                    2 * np.pi * step / p["period"] + p["phase"])
            if "fatigue" in d:
                order = np.unique(episode, return_inverse=True)[1]
                share = order / max(1, order.max())
                for k in ("dx", "dy", "dyaw"):
                    x[:, column(xn, k)] *= 1 - d["fatigue"]["rate"] * share
        f["x"][...] = x
        f["z"][...] = z


def generate(args, pair, nominals):
    """Records the pair's real set (and its hidden truth) unless already there."""
    seed, robot = pair["seed"], pair["robot"]
    pdir, tdir = os.path.join(args.out, "pairs", str(seed)), os.path.join(args.out, "truth", str(seed))
    real = os.path.join(pdir, "real.h5")
    if os.path.exists(real) and os.path.exists(os.path.join(tdir, "truth.json")):
        with open(os.path.join(tdir, "truth.json")) as f:
            recorded = json.load(f).get("draw_version", 1)
        if recorded != pair.get("draw_version", 1):
            raise RuntimeError(f"pair {seed}: OUT holds draw version {recorded}, asked for "
                               f"{pair.get('draw_version', 1)}: use another --out")
        return
    os.makedirs(pdir, exist_ok=True)
    os.makedirs(tdir, exist_ok=True)
    try:  # another battery process (e.g. --reverse) may be recording this pair
        os.close(os.open(os.path.join(tdir, ".recording"), os.O_CREAT | os.O_EXCL))
    except FileExistsError:
        return
    cfg = absolute_config(robot, nominals[robot])
    for e in pair["effects"]:
        cfg = draw.merge(cfg, e["config"])
        if e.get("mjcf"):
            src = os.path.join(ROOT, ROBOTS[robot]["mjcf"])
            with open(src) as f:
                xml = draw.edit_mjcf(f.read(), e["mjcf"])
            mjcf = os.path.join(tdir, "robot.xml")
            with open(mjcf, "w") as f:
                f.write(xml)
            cfg["mjcf_path"] = mjcf
    cfg_path = os.path.join(tdir, "real_config.json")
    with open(cfg_path, "w") as f:
        json.dump(cfg, f, indent=2)
    tmp = real + ".tmp.h5"
    cmd = [args.dgmm, "simulate", "--config", cfg_path, "--protocol", args.protocol,
           "--seed", str(pair["real_seed"]), "-o", tmp]
    if args.smoke:
        cmd += ["--placements", str(SMOKE_REAL_PLACEMENTS)]
    t = time.time()
    if any(e["config"] or e.get("mjcf") for e in pair["effects"]):
        run(cmd)
    else:  # nominal physics: one recording per (robot, seed), shared by data-level plants
        cached = os.path.join(args.out, "cache", f"{robot}_real_{pair['real_seed']}_{args.smoke}_{args.protocol}.h5")
        with LOCK:
            if not os.path.exists(cached):
                run(cmd[:-1] + [cached + ".tmp.h5"])
                os.replace(cached + ".tmp.h5", cached)
        shutil.copyfile(cached, tmp)
    apply_data_edits(tmp, pair["effects"], seed)
    conceal_metadata(tmp, sim_set(args, robot))
    os.replace(tmp, real)
    truth = {k: v for k, v in pair.items()}
    truth["real_sim_wall_s"] = time.time() - t
    with open(os.path.join(tdir, "truth.json"), "w") as f:
        json.dump(truth, f, indent=2)
    os.remove(os.path.join(tdir, ".recording"))


def analyse(args, pair):
    """Runs dgmm sim2real on the pair; returns (report dict or None, wall seconds, error)."""
    seed, robot = pair["seed"], pair["robot"]
    pdir = os.path.join(args.out, "pairs", str(seed))
    out = os.path.join(pdir, "analysis")
    report = os.path.join(out, "report.json")
    timing = os.path.join(pdir, "analysis_wall_s.json")
    if os.path.exists(report) and os.path.exists(timing) and not args.rerun:
        with open(report) as f, open(timing) as g:
            return json.load(f), json.load(g)["wall_s"], None
    shutil.rmtree(out, ignore_errors=True)
    cmd = [args.dgmm, "sim2real", "--sim", sim_set(args, robot), "--real",
           os.path.join(pdir, "real.h5"), "--sim-config", config_path(robot), "-o", out,
           "--no-figures"] + shlex.split(args.sim2real_args)
    # The analysis's signature cache lives in OUT (a fresh OUT starts uncached).
    env = dict(os.environ, XDG_CACHE_HOME=os.path.join(args.out, "xdg-cache"))
    if args.stop_at and time.time() >= args.stop_at:
        return None, 0.0, "not started: --stop-at reached"
    t = time.time()
    with open(os.path.join(pdir, "analysis.log"), "w") as logf:
        proc = subprocess.Popen(["nice", "-n", "5"] + cmd, stdout=logf, stderr=subprocess.STDOUT,
                                env=env)
        while proc.poll() is None:
            if args.stop_at and time.time() >= args.stop_at:
                proc.kill()  # this analysis only (its own pid)
                proc.wait()
                return None, time.time() - t, "stopped at --stop-at"
            time.sleep(1)
    if proc.returncode != 0:
        with open(os.path.join(pdir, "analysis.log")) as logf:
            return None, time.time() - t, f"exit {proc.returncode}: {logf.read()[-500:]}"
    wall = time.time() - t
    with open(timing, "w") as g:
        json.dump({"wall_s": wall}, g)
    with open(report) as f:
        return json.load(f), wall, None


def detectability(sim_path, real_path):
    """Method-free size of the planted change. Cells: command x heading sector (8 sectors of the
    terrain's (pitch, roll) direction). mean_shift_z: per cell and pose/terrain dimension a Welch z
    of the mean difference real - sim, summed as (chi2 - df) / sqrt(2 df) (about N(0, 1) when
    nothing differs). consistent_z: the same z's combined per dimension as sum / sqrt(cells)
    (a shift of one sign everywhere), largest |value| of the 8 dimensions (about 2 when nothing
    differs). spread_z: per dimension the log ratio of the within-cell standard deviations
    over its standard error, largest |value| of the 8 dimensions (about 2 when nothing differs)."""
    def load(p):
        with h5py.File(p, "r") as f:
            return np.hstack([f["x"][...], f["z"][...]]), f["z"][...], f["command"][...]
    ys, zs, cs = load(sim_path)
    yr, zr, cr = load(real_path)

    def cells(z, c):
        sector = np.floor((np.arctan2(z[:, 1], z[:, 0]) + np.pi) / (np.pi / 4)).astype(int) % 8
        return c * 8 + sector
    ks, kr = cells(zs, cs), cells(zr, cr)
    chi2, df = 0.0, 0
    res_s, res_r, zsum, cells_used = [], [], 0.0, 0
    for k in np.intersect1d(ks, kr):
        a, b = ys[ks == k], yr[kr == k]
        if len(a) < 3 or len(b) < 3:
            continue
        res_s.append(a - a.mean(0))
        res_r.append(b - b.mean(0))
        se = np.sqrt(a.var(0, ddof=1) / len(a) + b.var(0, ddof=1) / len(b))
        ok = se > 0
        z = np.where(ok, (b.mean(0) - a.mean(0)) / np.where(ok, se, 1), 0.0)
        chi2 += float(np.sum(z ** 2))
        df += int(ok.sum())
        zsum, cells_used = zsum + z, cells_used + 1
    if not df:
        return {"mean_shift_z": None, "consistent_z": None, "spread_z": None}
    rs, rr = np.vstack(res_s), np.vstack(res_r)
    log_ratio = 0.5 * np.log(np.mean(rr ** 2, 0) / np.mean(rs ** 2, 0))
    se = np.sqrt(1 / (2 * len(rr)) + 1 / (2 * len(rs)))
    return {"mean_shift_z": (chi2 - df) / np.sqrt(2 * df),
            "consistent_z": float(np.max(np.abs(zsum)) / np.sqrt(cells_used)),
            "spread_z": float(np.max(np.abs(log_ratio)) / se)}


def weakest_cases():
    """The weakest end of every range (scripts/sim2real_battery_draw.py RANGES), planted one at a
    time on the built-in robot: the realism check (are the ranges detectable in principle?)."""
    R = draw.RANGES
    def low(key, branch=0):  # the end of the range nearest to "no change" (a factor of 1)
        return min(R[key][branch][1], key=lambda v: abs(np.log(v)))
    def eff(what, config=None, mjcf=None, data=None):
        return {"family": what, "what": what, "config": config or {}, "mjcf": mjcf, "data": data}
    gains = [1.0] * 8
    one_leg = list(gains); one_leg[1] = R["leg_gain.one_leg"][1]
    side = [1.0] * 4 + [R["leg_gain.one_side"][1]] * 4
    nominal = load_nominals()["scorpion"]
    kp, damp = nominal["actuators"]["kp_nm_per_rad"], nominal["actuators"]["joint_damping_nms_per_rad"]
    return [
        eff("none (another seed)"),
        eff(f"friction {low('friction.sliding')}", {"friction": {"sliding": low("friction.sliding")}}),
        eff(f"friction {low('friction.sliding', 1)}", {"friction": {"sliding": low("friction.sliding", 1)}}),
        eff(f"solref time constant {R['floor.solref.timeconst'][0]} s",
            mjcf={"floor_solref": [R["floor.solref.timeconst"][0], 1.0]}),
        eff(f"solref damping ratio {low('floor.solref.dampratio')}",
            mjcf={"floor_solref": [0.02, low("floor.solref.dampratio")]}),
        eff(f"solref damping ratio {low('floor.solref.dampratio', 1)}",
            mjcf={"floor_solref": [0.02, low("floor.solref.dampratio", 1)]}),
        eff(f"masses x{low('masses.scale')}",
            {"masses": {k: v * low("masses.scale") for k, v in nominal["masses"].items()}}),
        eff(f"masses x{low('masses.scale', 1)}",
            {"masses": {k: v * low("masses.scale", 1) for k, v in nominal["masses"].items()}}),
        eff(f"payload {R['payload.mass_kg'][0]} kg at (0.1, 0.06)",
            {"payload": {"mass_kg": R["payload.mass_kg"][0], "position_body_m": [0.1, 0.06, 0.05]}}),
        eff(f"leg 1 gain {one_leg[1]}", {"actuators": {"leg_gain": one_leg}}),
        eff(f"right side gain {side[4]}", {"actuators": {"leg_gain": side}}),
        eff(f"kp x{low('kp.scale')}", {"actuators": {"kp_nm_per_rad": kp * low("kp.scale")}}),
        eff(f"kp x{low('kp.scale', 1)}", {"actuators": {"kp_nm_per_rad": kp * low("kp.scale", 1)}}),
        eff(f"joint damping x{low('joint_damping.scale')}",
            {"actuators": {"joint_damping_nms_per_rad": damp * low("joint_damping.scale")}}),
        eff(f"joint damping x{low('joint_damping.scale', 1)}",
            {"actuators": {"joint_damping_nms_per_rad": damp * low("joint_damping.scale", 1)}}),
        eff(f"latency {R['latency_s'][0]} s", {"actuators": {"latency_s": R["latency_s"][0]}}),
        eff(f"IMU pitch bias {R['imu_bias_rad'][0]} rad", data={"z_add": {"pitch": R["imu_bias_rad"][0]}}),
        eff(f"tracker dx bias {R['tracker_bias_m'][0]} m", data={"x_add": {"dx": R["tracker_bias_m"][0]}}),
        eff(f"tracker noise x{R['tracker_noise.scale'][0]}",
            data={"x_noise_sd": {k: v * float(np.sqrt(R["tracker_noise.scale"][0] ** 2 - 1)) for k, v in
                                 {"dx": 0.003, "dy": 0.003, "dz": 0.003, "droll": 0.005,
                                  "dpitch": 0.005, "dyaw": 0.01}.items()}}),
        eff(f"heading drift {R['heading_drift_rad'][0]} rad", data={"x_add": {"dyaw": R["heading_drift_rad"][0]}}),
        eff(f"periodic pitch {R['ool.periodic_pitch_rad'][0]} rad, period 2",
            data={"periodic": {"column": "dpitch", "amp": R["ool.periodic_pitch_rad"][0], "period": 2,
                               "phase": 0.5}}),
        eff(f"fatigue {R['ool.fatigue_rate'][0]}", data={"fatigue": {"rate": R["ool.fatigue_rate"][0]}}),
    ]


def realism(args, nominals):
    """Detectability of the weakest end of every range; writes OUT/realism.md."""
    pairs = [{"seed": 900 + i, "robot": "scorpion", "kind": "realism", "effects": [e],
              "real_seed": 100900 if not e["config"] and not e["mjcf"] else 100900 + i}
             for i, e in enumerate(weakest_cases())]
    sim_set(args, "scorpion")
    with cf.ThreadPoolExecutor(args.jobs) as pool:
        list(pool.map(lambda p: generate(args, p, nominals), pairs))
    rows = ["| weakest planted change | mean shift z | consistent shift z | spread z |",
            "|---|---|---|---|"]
    for p in pairs:
        d = detectability(sim_set(args, "scorpion"),
                          os.path.join(args.out, "pairs", str(p["seed"]), "real.h5"))
        rows.append(f"| {p['effects'][0]['what']} | {d['mean_shift_z']:.1f} | "
                    f"{d['consistent_z']:.1f} | {d['spread_z']:.1f} |")
    text = ("Generated by `scripts/sim2real_battery.py --seeds 900 --realism --write-doc` "
            "(real sets seeded 100900, ...; nominal sim set seed 100, 166 placements).\n\n"
            + "\n".join(rows) + "\n")
    with open(os.path.join(args.out, "realism.md"), "w") as f:
        f.write(text)
    print(text)
    if args.write_doc:
        write_section("sim2real-battery-realism", text)


def write_section(name, text):
    subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "replace_section.py"),
                    os.path.join(ROOT, "docs", "sim2real.md"), name, "-"],
                   input=text, text=True, check=True)


def find_key(obj, key):
    """The first dict (depth first) in a parsed JSON holding `key`, or None."""
    if isinstance(obj, dict):
        if key in obj:
            return obj
        obj = list(obj.values())
    if isinstance(obj, list):
        for v in obj:
            found = find_key(v, key)
            if found is not None:
                return found
    return None


def stop_time(hh_mm, now):
    """The next time of day `hh_mm` (UTC) at or after `now` (epoch seconds): 01:10 said at 23:15
    is tomorrow's (it was today's, already past, so nothing started)."""
    hh, mm = (int(v) for v in hh_mm.split(":"))
    day = now - now % 86400
    at = day + (hh * 60 + mm) * 60
    return at if at >= now else at + 86400


def parse_seeds(text):
    """Seeds from "A-B", "A" or a comma-separated list of those ("1019,1020,1030-1039")."""
    seeds = []
    for part in text.split(","):
        a, _, b = part.strip().partition("-")
        seeds += range(int(a), int(b or a) + 1)
    return seeds


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", required=True, help="seeds: A-B, or a comma-separated list of seeds and ranges (DEV 1000-1999)")
    ap.add_argument("--jobs", type=int, default=2, help="parallel simulations/analyses (<= 2)")
    ap.add_argument("--build", default=os.path.join(ROOT, "build"))
    ap.add_argument("--out", default=None, help="work folder (default out/battery-A-B)")
    ap.add_argument("--keep", action="store_true", help="keep the sets and analyses afterwards")
    ap.add_argument("--smoke", action="store_true", help="3 pairs, few placements (a quick check)")
    ap.add_argument("--generate-only", action="store_true", help="record the pairs, analyse none")
    ap.add_argument("--reverse", action="store_true",
                    help="record from the last seed down (a second recording process)")
    ap.add_argument("--realism", action="store_true",
                    help="plant the weakest end of every range and print its detectability")
    ap.add_argument("--stop-at", default=None, metavar="HH:MM",
                    help="UTC time after which no analysis starts and running ones are stopped "
                         "(their pairs are listed as not analysed)")
    ap.add_argument("--rerun", action="store_true", help="rerun analyses already in OUT")
    ap.add_argument("--sim2real-args", default="", metavar="'ARGS'",
                    help="more options of every dgmm sim2real call, e.g. '--signature-executions 5'")
    ap.add_argument("--kinds", default=None, metavar="K[,K]",
                    help="keep only pairs of these kinds (null, single, two, out_of_library): "
                         "for development on one kind; a report runs every pair of its range")
    ap.add_argument("--draw-version", type=int, choices=draw.DRAW_VERSIONS,
                    default=draw.DEFAULT_DRAW_VERSION,
                    help="pair generator: 1 = seed ranges up to 10000-10039 as drawn then; 2 "
                         "adds solimp and backlash, tracker noise through the config; 3 (default) "
                         "adds leg geometry and mass out of the library")
    ap.add_argument("--protocol", default="paper", choices=["paper", "continuous"],
                    help="of the sim and real sets: continuous draws each execution's velocity command "
                         "at random (kept in z as cmd_long, cmd_lat, cmd_turn; issue #25)")
    ap.add_argument("--write-doc", action="store_true",
                    help="write the tables into docs/sim2real.md (section sim2real-battery)")
    args = ap.parse_args()
    if not 1 <= args.jobs <= 2:
        ap.error("--jobs: expected 1 or 2 (the machine has 2 cores)")
    seeds = parse_seeds(args.seeds)[: 3 if args.smoke else None]
    if args.stop_at:
        args.stop_at = stop_time(args.stop_at, time.time())
    args.out = os.path.abspath(args.out or os.path.join(ROOT, "out", f"battery-{args.seeds}"))
    args.dgmm = os.path.join(os.path.abspath(args.build), "app", "dgmm")
    if not os.access(args.dgmm, os.X_OK):
        sys.exit(f"sim2real_battery: {args.dgmm}: not built")
    nominals = load_nominals()
    if args.realism:
        realism(args, nominals)
        return 0
    pairs = [draw.draw_pair(s, nominals, args.draw_version) for s in seeds]
    if args.kinds:
        kinds = set(args.kinds.split(","))
        pairs = [p for p in pairs if p["kind"] in kinds]
        seeds = [p["seed"] for p in pairs]
        if not pairs:
            sys.exit(f"sim2real_battery: no pair of kind {args.kinds} among seeds {args.seeds}")
    t0 = time.time()
    for robot in sorted({p["robot"] for p in pairs}):
        sim_set(args, robot)
    log(f"generating {len(pairs)} pairs")
    with cf.ThreadPoolExecutor(args.jobs) as pool:
        list(pool.map(lambda p: generate(args, p, nominals), pairs[::-1] if args.reverse else pairs))
    log(f"generated in {time.time() - t0:.0f} s")
    if args.generate_only:
        return 0
    # Built-in robot first, in seed order (its signature cache fills with the first analysis);
    # then the second robot's pairs, in seed order.
    firsts = {}
    for p in pairs:
        firsts.setdefault(p["robot"], p["seed"])
    results = {}

    def one(p):
        report, wall, error = analyse(args, p)
        with open(os.path.join(args.out, "truth", str(p["seed"]), "truth.json")) as f:
            truth = json.load(f)
        r = {"seed": p["seed"], "robot": p["robot"], "kind": p["kind"],
             "draw_version": truth.get("draw_version", 1),
             "effects": [{k: e.get(k) for k in ("family", "kind", "knob", "value", "unit", "what")}
                         for e in truth["effects"]],
             "analysis_wall_s": wall, "first_of_robot": firsts[p["robot"]] == p["seed"],
             "detectability": detectability(sim_set(args, p["robot"]),
                                            os.path.join(args.out, "pairs", str(p["seed"]), "real.h5"))}
        if report is None:
            r["error"] = error
        else:
            r["score"] = score.score_pair(truth, report)
            recordings = (report.get("knobs") or {}).get("recordings")
            stats = find_key(report, "from_cache")
            if recordings is not None:  # issue #22's report
                r["simulations"] = recordings["signatures"] + recordings["refinement"]
                r["from_cache"] = recordings["signatures_from_cache"] + recordings["refinement_from_cache"]
                r["signature_simulations"] = recordings["signatures"]
            elif stats is not None:
                r["simulations"], r["from_cache"] = stats.get("simulations"), stats["from_cache"]
                r["signature_simulations"] = stats.get("signature_simulations")
        results[p["seed"]] = r
        log(f"pair {p['seed']} ({p['robot']}, {p['kind']}): {wall:.0f} s")
    order = sorted(pairs, key=lambda p: (p["robot"] != "scorpion", p["seed"]))
    # The first analysis runs alone: two analyses on a cold cache would simulate the same
    # signatures twice (each analysis simulates on 2 threads itself).
    one(order[0])
    with cf.ThreadPoolExecutor(args.jobs) as pool:
        list(pool.map(one, order[1:]))
    ordered = [results[s] for s in seeds]
    summary = score.summarize(ordered)
    shown, skip = [], False
    for a in sys.argv[1:]:  # the command line without the machine-specific folders
        if skip or a.split("=")[0] in ("--out", "--build"):
            skip = not skip and "=" not in a
            continue
        shown.append(a)
    command = "scripts/sim2real_battery.py " + " ".join(shown)
    doc = tables.markdown(ordered, summary, command, smoke=args.smoke)
    out = {"seeds": args.seeds, "smoke": args.smoke, "draw_version": args.draw_version,
           "summary": summary, "pairs": ordered}
    tmp = os.path.join(args.out, "results.json.tmp")
    with open(tmp, "w") as f:
        json.dump(out, f, indent=2)
    os.replace(tmp, os.path.join(args.out, "results.json"))
    with open(os.path.join(args.out, "battery.md"), "w") as f:
        f.write(doc)
    print(doc)
    if args.write_doc:
        write_section("sim2real-battery", doc)
    if not args.keep:
        for sub in ("pairs",):
            shutil.rmtree(os.path.join(args.out, sub), ignore_errors=True)
    log(f"done in {time.time() - t0:.0f} s; results in {args.out}/results.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
