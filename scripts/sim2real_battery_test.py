#!/usr/bin/env python3
"""Unit tests of the blinded battery's drawing, planting and scoring (no dgmm needed; ctest
`sim2real_battery_scorer`). The battery itself is a script: scripts/sim2real_battery.py."""
import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import unittest

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import sim2real_battery as battery  # noqa: E402
import sim2real_battery_draw as draw  # noqa: E402
import sim2real_battery_score as score  # noqa: E402
import sim2real_battery_tables as tables  # noqa: E402


def nominals():
    return battery.load_nominals()


def verdict(status, named=(), ties=(), unexplained=False, gap=0.9):
    return {"verdict": {"status": status, "named": list(named), "ties": list(ties),
                        "unexplained": {"present": unexplained, "structured_in": []},
                        "gap_closed": gap}}


def name(family, knob=None, value=None, inclusion=0.9, tie_group=None):
    return {"family": family, "knob": knob, "value": value, "inclusion": inclusion,
            "tie_group": tie_group}


def pair(kind, *effects):
    return {"kind": kind, "effects": list(effects)}


FRICTION = {"family": "friction", "knob": "friction.sliding", "value": 0.6}
PAYLOAD = {"family": "payload", "knob": "payload.mass_kg", "value": 2.0}
OOL = {"family": "out_of_library", "knob": None, "value": 0.02}


class DrawTest(unittest.TestCase):
    def test_same_seed_same_pair_and_shares(self):
        n = nominals()
        self.assertEqual(json.dumps(draw.draw_pair(1234, n)), json.dumps(draw.draw_pair(1234, n)))
        pairs = [draw.draw_pair(s, n, version=2) for s in range(20000, 22000)]
        share = lambda k: sum(p["kind"] == k for p in pairs) / len(pairs)
        # Shares of issue #9 (the second robot turns its two-effect / out-of-library draws into
        # single effects, so those shares sit a little under nominal). Binomial slack ~ 3 sd.
        self.assertAlmostEqual(share("null"), 0.2, delta=0.03)
        self.assertAlmostEqual(share("two"), 0.2 * 0.85, delta=0.03)
        self.assertAlmostEqual(share("out_of_library"), 0.1 * 0.85, delta=0.025)
        families = {e["family"] for p in pairs for e in p["effects"]}
        self.assertEqual(families, set(draw.FAMILIES) | {"out_of_library"})

    def test_seed_lists_and_ranges(self):
        self.assertEqual(battery.parse_seeds("1000-1003"), [1000, 1001, 1002, 1003])
        self.assertEqual(battery.parse_seeds("7"), [7])
        self.assertEqual(battery.parse_seeds("1019,1020,1030-1032"), [1019, 1020, 1030, 1031, 1032])

    def test_stop_at_is_the_next_such_time(self):
        evening = 86400 * 20000 + 23 * 3600 + 15 * 60  # 23:15 UTC on some day
        self.assertEqual(battery.stop_time("23:40", evening), evening + 25 * 60)
        self.assertEqual(battery.stop_time("01:10", evening), evening + 115 * 60)  # after midnight
        self.assertEqual(battery.stop_time("23:15", evening), evening)

    def test_values_inside_their_ranges(self):
        n = nominals()
        for s in range(3000, 3400):
            for e in draw.draw_pair(s, n)["effects"]:
                if e["family"] == "latency":
                    self.assertTrue(0.04 <= e["value"] <= 0.1)
                if e["family"] == "friction":
                    self.assertTrue(0.45 <= e["value"] <= 0.85 or 1.3 <= e["value"] <= 2.0)
                if e["family"] == "tracker_noise":
                    self.assertTrue(1.6 <= e["value"] <= 3.0)

    def test_mjcf_edit_sets_the_floor_solref_once(self):
        with open(os.path.join(battery.ROOT, "datasets/robots/scorpion.xml")) as f:
            xml = f.read()
        out = draw.edit_mjcf(xml, {"floor_solref": [0.05, 1.0]})
        self.assertIn('<geom name="floor" solref="0.05000 1.0000"', out)
        with self.assertRaises(ValueError):
            draw.edit_mjcf("<mujoco/>", {"floor_solref": [0.05, 1.0]})


# The draw generator before draw versions existed (commit 32e2dee); version 1 must equal it.
GENERATOR_V1_COMMIT = "32e2dee"
# Fingerprints of version-1 draws by that generator: (seed, robot, kind, [(family, knob, value)]).
V1_FINGERPRINTS = [
    (1020, "scorpion", "two", [("payload", "payload.mass_kg", 1.7219253054796524),
                               ("friction", "friction.sliding", 0.7311098108730703)]),
    (5028, "scorpion", "single", [("latency", "actuators.latency_s", 0.076)]),
    (10017, "scorpion", "two", [("latency", "actuators.latency_s", 0.059),
                                ("tracker_noise", "tracker.noise_scale", 2.1400791675332487)]),
]


def generator_v1():
    """The draw module as of GENERATOR_V1_COMMIT (None outside a git checkout)."""
    try:
        text = subprocess.run(["git", "-C", HERE, "show",
                               f"{GENERATOR_V1_COMMIT}:scripts/sim2real_battery_draw.py"],
                              capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    tmp = tempfile.NamedTemporaryFile("w", suffix=".py", delete=False)
    with tmp:
        tmp.write(text)
    spec = importlib.util.spec_from_file_location("draw_v1_generator", tmp.name)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    os.remove(tmp.name)
    return module


class DrawVersionTest(unittest.TestCase):
    def test_version_1_reproduces_the_old_draws(self):
        n = nominals()
        for seed, robot, kind, effects in V1_FINGERPRINTS:
            p = draw.draw_pair(seed, n, version=1)
            self.assertEqual((p["robot"], p["kind"], p["draw_version"]), (robot, kind, 1))
            self.assertEqual([(e["family"], e["knob"], e["value"]) for e in p["effects"]], effects)
        old = generator_v1()
        if old is None:
            self.skipTest("not a git checkout: only the fingerprints were compared")
        seeds = list(range(1000, 1300)) + list(range(5000, 5040)) + list(range(10000, 10040))
        for s in seeds:
            p = draw.draw_pair(s, n, version=1)
            self.assertEqual(p.pop("draw_version"), 1)
            self.assertEqual(json.dumps(p), json.dumps(old.draw_pair(s, n)), s)
            for e in p["effects"]:
                if e.get("mjcf"):
                    xml = '<geom name="floor" type="plane"/>'
                    self.assertEqual(draw.edit_mjcf(xml, e["mjcf"]), old.edit_mjcf(xml, e["mjcf"]))

    def test_version_2_draws_the_new_options(self):
        n = nominals()
        with self.assertRaises(ValueError):
            draw.draw_pair(11000, n, version=4)
        pairs = [draw.draw_pair(s, n, version=2) for s in range(11000, 11400)]
        effects = [dict(e, robot=p["robot"]) for p in pairs for e in p["effects"]]
        knobs = {e["knob"] for e in effects}
        for k in ("floor.solimp.dmax", "floor.solref.timeconst", "floor.solref.dampratio",
                  "actuators.backlash_rad", "tracker.noise_scale"):
            self.assertIn(k, knobs)
        for e in effects:
            if e["knob"] == "floor.solimp.dmax":
                self.assertTrue(0.55 <= e["value"] <= 0.8)
                dmin, dmax = e["mjcf"]["floor_solimp"][:2]
                self.assertEqual((dmin, dmax), (min(0.9, e["value"]), e["value"]))
            if e["family"] == "backlash":
                self.assertTrue(0.03 <= e["value"] <= 0.1)
                self.assertEqual(e["config"], {"actuators": {"backlash_rad": e["value"]}})
                self.assertEqual((e["unit"], e["nominal"]), ("rad", 0.0))
            if e["family"] == "tracker_noise":  # planted in the simulator, not in the data
                self.assertTrue(1.6 <= e["value"] <= 3.0)
                self.assertIsNone(e["data"])
                self.assertEqual(set(e["config"]["noise"]),
                                 {"tracker_position_sd_m", "tracker_yaw_sd_rad",
                                  "tracker_roll_sd_rad", "tracker_pitch_sd_rad"})
                for k, v in e["config"]["noise"].items():
                    self.assertAlmostEqual(v, n[e["robot"]]["noise"][k] * e["value"])

    def test_version_3_is_the_default_and_adds_geometry_out_of_library(self):
        n = nominals()
        self.assertEqual(draw.draw_pair(12000, n), draw.draw_pair(12000, n, version=3))
        pairs = [draw.draw_pair(s, n) for s in range(30000, 32000)]
        share = lambda k: sum(p["kind"] == k for p in pairs) / len(pairs)
        self.assertAlmostEqual(share("out_of_library"), 0.25 * 0.85, delta=0.03)
        kinds = {p["effects"][0]["kind"] for p in pairs if p["kind"] == "out_of_library"}
        self.assertEqual(kinds, set(draw.OUT_OF_LIBRARY) | set(draw.OUT_OF_LIBRARY_GEOMETRY))
        with open(os.path.join(battery.ROOT, "datasets/robots/scorpion.xml")) as f:
            xml = f.read()
        for p in pairs:
            e = p["effects"][0] if p["effects"] else {}
            if e.get("kind") in draw.OUT_OF_LIBRARY_GEOMETRY:
                self.assertEqual(p["robot"], "scorpion")
                edited = draw.edit_mjcf(xml, e["mjcf"])
                self.assertNotEqual(edited, xml)
                leg = list(e["mjcf"].values())[0][0]
                a, b = draw._leg_block(xml, leg)
                self.assertEqual(edited[:a], xml[:a])  # only that leg changes
        short = draw.edit_mjcf(xml, {"tibia_scale": [3, 0.5]})
        a, b = draw._leg_block(short, 3)
        self.assertEqual(short[a:b].count("-0.08000"), 3)  # segment end, foot geom, foot site
        heavy = draw.edit_mjcf(xml, {"leg_mass": [6, 0.8]})
        self.assertIn('name="leg6_extra_mass"', heavy)

    def test_solimp_edit_sets_the_floor_solimp(self):
        with open(os.path.join(battery.ROOT, "datasets/robots/scorpion.xml")) as f:
            xml = f.read()
        out = draw.edit_mjcf(xml, {"floor_solimp": [0.7, 0.7, 0.001, 0.5, 2.0]})
        self.assertIn('<geom name="floor" solimp="0.7 0.7 0.001 0.5 2"', out)


class PlantTest(unittest.TestCase):
    def test_data_edits_change_only_their_columns(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "s.h5")
            n = 30
            with h5py.File(path, "w") as f:
                f["x"] = np.zeros((n, 6))
                f["x"].attrs["names"] = ["dx", "dy", "dz", "droll", "dpitch", "dyaw"]
                f["z"] = np.zeros((n, 2))
                f["z"].attrs["names"] = ["pitch", "roll"]
                f["step"] = np.tile(np.arange(5), 6).astype(np.int32)
                f["episode"] = np.repeat(np.arange(6), 5).astype(np.int32)
            effects = [{"data": {"x_add": {"dy": 0.01}, "z_add": {"roll": -0.03}}},
                       {"data": {"periodic": {"column": "dpitch", "amp": 0.02, "period": 2,
                                              "phase": np.pi / 2}}}]
            battery.apply_data_edits(path, effects, seed=1)
            with h5py.File(path, "r") as f:
                x, z = f["x"][...], f["z"][...]
            np.testing.assert_allclose(x[:, 1], 0.01)
            np.testing.assert_allclose(z[:, 1], -0.03)
            np.testing.assert_allclose(x[:, 4], 0.02 * np.cos(np.pi * np.tile(np.arange(5), 6)),
                                       atol=1e-12)
            self.assertTrue(np.all(x[:, [0, 2, 3, 5]] == 0) and np.all(z[:, 0] == 0))


class ScoreTest(unittest.TestCase):
    def test_null(self):
        self.assertTrue(score.score_pair(pair("null"), verdict("clean"))["clean"])
        s = score.score_pair(pair("null"), verdict("explained", [name("payload", inclusion=0.85)]))
        self.assertFalse(s["clean"])
        self.assertTrue(s["confident_wrong"])

    def test_first_named_or_tie(self):
        right = verdict("explained", [name("friction", "floor.friction.sliding", 0.66)])
        s = score.score_pair(pair("single", FRICTION), right)
        self.assertTrue(s["correct"])
        self.assertAlmostEqual(s["values"]["friction"]["error"], 0.1)
        tied = verdict("explained", [name("mass", tie_group=0, inclusion=0.95)],
                       ties=[{"families": ["mass", "friction"]}])
        s = score.score_pair(pair("single", FRICTION), tied)
        self.assertTrue(s["correct"])
        self.assertFalse(s["confident_wrong"])
        self.assertEqual(s["column"], "tie")
        self.assertIsNone(s["values"]["friction"])  # found only through the tie: no value
        wrong = verdict("explained", [name("mass", inclusion=0.95)])
        s = score.score_pair(pair("single", FRICTION), wrong)
        self.assertFalse(s["correct"])
        self.assertTrue(s["confident_wrong"])
        unsure = verdict("explained", [name("mass", inclusion=None)])  # not computed
        self.assertFalse(score.score_pair(pair("single", FRICTION), unsure)["confident_wrong"])
        doubted = {"verdict": dict(wrong["verdict"], status="partly_explained",
                                   doubts=["mass.scale pinned at its upper limit 2"])}
        self.assertFalse(score.score_pair(pair("single", FRICTION), doubted)["confident_wrong"])

    def test_value_needs_the_planted_knob(self):
        other = verdict("explained", [name("friction", "floor.friction.torsional", 0.6)])
        v = score.score_pair(pair("single", FRICTION), other)["values"]["friction"]
        self.assertIsNone(v["error"])
        leg3 = {"family": "actuator_gain", "knob": "actuators.leg_gain[3]", "value": 0.5}
        for knob, ok in [("actuators.leg3.gain", True), ("actuators.leg5.gain", False),
                         ("actuators.left_side.gain", False)]:
            got = verdict("explained", [name("actuator_gain", knob, 0.55)])
            v = score.score_pair(pair("single", leg3), got)["values"]["actuator_gain"]
            self.assertEqual(v["error"] is not None, ok, knob)
        # The payload's mass is compared even when its position is named first.
        both = verdict("explained", [name("payload", "payload.position_x_m", 0.1),
                                     name("payload", "payload.mass_kg", 2.2)])
        v = score.score_pair(pair("single", PAYLOAD), both)["values"]["payload"]
        self.assertAlmostEqual(v["error"], 0.1)

    def test_backlash_and_tracker_noise_values(self):
        backlash = {"family": "backlash", "knob": "actuators.backlash_rad", "value": 0.05}
        got = verdict("explained", [name("backlash", "actuators.backlash_rad", 0.06)])
        s = score.score_pair(pair("single", backlash), got)
        self.assertTrue(s["correct"])
        self.assertAlmostEqual(s["values"]["backlash"]["error"], 0.2)
        latency = verdict("explained", [name("latency", "actuators.latency_s", 0.05)])
        self.assertFalse(score.score_pair(pair("single", backlash), latency)["correct"])
        noise = {"family": "tracker_noise", "knob": "tracker.noise_scale", "value": 2.0}
        for knob in ("tracker.noise_scale", "noise"):  # the knob path's and the data level's
            got = verdict("explained", [name("tracker_noise", knob, 1.8)])
            v = score.score_pair(pair("single", noise), got)["values"]["tracker_noise"]
            self.assertAlmostEqual(v["error"], -0.1)
        solimp = {"family": "contact", "knob": "floor.solimp.dmax", "value": 0.7}
        other = verdict("explained", [name("contact", "floor.solref.timeconst", 0.05)])
        self.assertIsNone(score.score_pair(pair("single", solimp), other)["values"]["contact"]["error"])

    def test_two_effects_and_out_of_library(self):
        both = verdict("explained", [name("payload"), name("friction")])
        s = score.score_pair(pair("two", FRICTION, PAYLOAD), both)
        self.assertTrue(s["both_found"])
        one = verdict("explained", [name("payload")])
        s = score.score_pair(pair("two", FRICTION, PAYLOAD), one)
        self.assertFalse(s["both_found"])
        self.assertTrue(s["one_found"])
        s = score.score_pair(pair("out_of_library", OOL), verdict("unexplained"))
        self.assertTrue(s["unexplained_reported"])
        s = score.score_pair(pair("out_of_library", OOL),
                             verdict("explained", [name("tracker_noise", inclusion=0.95)]))
        self.assertFalse(s["unexplained_reported"])
        self.assertTrue(s["confident_wrong"])

    def test_advice_is_scored_against_the_truth(self):
        def advised(family, needed):
            return dict(verdict("unexplained"), more_data={
                "knob": "payload.mass_kg" if family == "payload" else "geoms.friction_scale",
                "family": family, "reason": "near_miss", "placements_needed": needed, "max_factor": 12})
        on = score.score_pair(pair("single", PAYLOAD), advised("payload", 203))
        self.assertTrue(on["advice"]["on_truth"])
        off = score.score_pair(pair("single", PAYLOAD), advised("friction", None))
        self.assertFalse(off["advice"]["on_truth"])
        self.assertIsNone(score.score_pair(pair("single", PAYLOAD), verdict("unexplained"))["advice"])
        results = [{"kind": "single", "score": on, "analysis_wall_s": 1.0},
                   {"kind": "single", "score": off, "analysis_wall_s": 1.0},
                   {"kind": "null", "score": score.score_pair(pair("null"), advised("friction", 90)),
                    "analysis_wall_s": 1.0}]
        s = score.summarize(results)
        self.assertEqual((s["advised"], s["advised_in_library_on_truth"], s["advised_nulls"]), (3, (1, 2), 1))
        for r, seed in zip(results, (1, 2, 3)):
            r.update(seed=seed, robot="scorpion", effects=[], detectability={
                "mean_shift_z": None, "consistent_z": None, "spread_z": None})
        table = tables.pair_table(results)
        self.assertIn("advice: 203 placements (payload.mass_kg)", table)
        self.assertIn("advice: beyond 12 times the placements (geoms.friction_scale)", table)
        self.assertIn("| 3; 1 of 2; 1; 0 |", tables.targets_table(s))

    def test_old_reports_map_onto_families(self):
        old = {"effects": [{"effect": "slope_slip", "inclusion_probability": 1.0}],
               "unexplained": [], "conditional_flagged_regions": 4, "gap_closed": 0.9}
        s = score.score_pair(pair("single", FRICTION), old)
        self.assertTrue(s["correct"] and s["fallback_mapping"])
        self.assertEqual(s["status"], "explained")

    def test_summary_counts(self):
        results = [{"kind": "single", "score": score.score_pair(
                        pair("single", FRICTION),
                        verdict("explained", [name("friction", "sliding", 0.61)])),
                    "analysis_wall_s": 10.0, "first_of_robot": True},
                   {"kind": "null", "score": score.score_pair(pair("null"), verdict("clean", gap=None)),
                    "analysis_wall_s": 4.0, "first_of_robot": False}]
        s = score.summarize(results)
        self.assertEqual(s["in_library_correct"], (1, 1))
        self.assertEqual(s["null_clean"], (1, 1))
        self.assertEqual(s["value_within_25pct"], (1, 1))
        self.assertEqual(s["wall_s_first_uncached"], [10.0])
        self.assertEqual(s["wall_s_cached_median"], 4.0)


if __name__ == "__main__":
    unittest.main()
