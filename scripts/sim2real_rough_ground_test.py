#!/usr/bin/env python3
"""Unit tests of scripts/sim2real_rough_ground.py's planting (no dgmm needed; ctest
sim2real_rough_ground_planting): the built-in octopod's kinds draw as they always did, and a config
with a robot block gets a leg by its own name, a payload in shares of its own mass and reach."""
import importlib.util
import json
import os
import random
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("rough", os.path.join(HERE, "sim2real_rough_ground.py"))
rough = importlib.util.module_from_spec(spec)
spec.loader.exec_module(rough)

ROBOTS = os.path.join(HERE, "..", "datasets", "robots")


def octopod():
    return json.load(open(os.path.join(ROBOTS, "rough_ground.json")))


def hexapod_on_rough_ground():
    cfg = rough.ROBOTS.with_absolute_paths(json.load(open(os.path.join(ROBOTS, "hexapod.json"))),
                                           os.path.join(ROBOTS, "hexapod.json"))
    cfg["terrain"] = octopod()["terrain"]
    return cfg


class Octopod(unittest.TestCase):
    def test_a_weak_leg_is_one_of_eight_by_index_as_before(self):
        cfg = octopod()
        knob, gain = rough.planted(7, cfg, ["leg"])
        r = random.Random(7)
        leg, expected = r.randrange(8), r.uniform(0.25, 0.5)
        self.assertEqual(knob, f"actuators.leg{leg}.gain")
        self.assertEqual(gain, expected)
        self.assertEqual(cfg["actuators"]["leg_gain"], [gain if i == leg else 1.0 for i in range(8)])

    def test_a_ground_kind_scales_the_terrain(self):
        cfg = octopod()
        knob, factor = rough.planted(3, cfg, ["rough"])
        self.assertEqual(knob, "terrain.rough.rms_scale")
        self.assertAlmostEqual(cfg["terrain"]["rough"]["rms_height_m"], 0.005 * factor)


class RobotBlock(unittest.TestCase):
    LEGS = {"front_left", "front_right", "middle_left", "middle_right", "rear_left", "rear_right"}

    def test_a_weak_leg_is_named_by_the_robots_own_leg_names(self):
        seen = set()
        for seed in range(40):
            cfg = hexapod_on_rough_ground()
            knob, gain = rough.planted(seed, cfg, ["leg"], (2.0, 0.3, "/nowhere"))
            leg = knob.split(".")[1]
            self.assertIn(leg, self.LEGS)
            self.assertEqual(cfg["robot"]["leg_gain"], {leg: gain})
            self.assertNotIn("actuators", cfg)
            seen.add(leg)
        self.assertEqual(seen, self.LEGS)  # every leg of six drawn, none beyond them

    def test_a_payload_is_a_share_of_the_robots_mass_and_reach(self):
        for mass, reach in ((2.0, 0.3), (40.0, 0.9)):
            cfg = hexapod_on_rough_ground()
            knob, kg = rough.planted(11, cfg, ["payload"], (mass, reach, "/nowhere"))
            self.assertEqual(knob, "payload.mass_kg")
            self.assertTrue(0.15 * mass <= kg <= 0.30 * mass)
            self.assertLessEqual(abs(cfg["payload"]["position_body_m"][0]), 0.15 * reach)

    def test_friction_overwrites_the_models_geoms(self):
        cfg = hexapod_on_rough_ground()
        knob, factor = rough.planted(5, cfg, ["friction"], (2.0, 0.3, "/nowhere"))
        self.assertEqual(knob, "geoms.friction_scale")
        self.assertTrue(cfg["robot"]["overwrite_physics"])
        self.assertAlmostEqual(cfg["friction"]["sliding"], factor * rough.ROBOTS.MODEL_MAX_FRICTION)

    def test_the_ground_kinds_are_the_same_for_every_robot(self):
        a, b = octopod(), hexapod_on_rough_ground()
        self.assertEqual(rough.planted(9, a, ["stones"]), rough.planted(9, b, ["stones"]))
        self.assertEqual(a["terrain"], b["terrain"])

    def test_without_the_robots_mass_and_reach_it_is_refused(self):
        with self.assertRaisesRegex(ValueError, "robot block"):
            rough.planted(1, hexapod_on_rough_ground(), ["payload"])

    def test_the_mjcf_path_is_made_absolute_from_the_configs_folder(self):
        cfg = hexapod_on_rough_ground()
        self.assertTrue(os.path.isabs(cfg["mjcf_path"]))
        self.assertTrue(os.path.exists(cfg["mjcf_path"]))


if __name__ == "__main__":
    unittest.main()
