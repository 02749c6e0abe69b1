#!/usr/bin/env python3
"""Unit tests of scripts/sim2real_robots.py's planting (no dgmm needed; ctest sim2real_robots_planting):
the out-of-library MJCF edits touch exactly one leg's lowest body, as documented."""
import importlib.util
import os
import random
import re
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
spec = importlib.util.spec_from_file_location("robots", os.path.join(HERE, "sim2real_robots.py"))
robots = importlib.util.module_from_spec(spec)
spec.loader.exec_module(robots)

HEXAPOD = os.path.join(HERE, "..", "datasets", "robots", "hexapod.xml")


def changed_lines(a, b):
    return [(x, y) for x, y in zip(a.splitlines(), b.splitlines()) if x != y]


class EditLeg(unittest.TestCase):
    def setUp(self):
        self.xml = open(HEXAPOD).read()

    def test_short_tibia_scales_the_foot_bodys_geoms_only(self):
        out = robots.edit_leg(self.xml, "middle_left_foot", "short_tibia", 0.5, 0.3)
        diff = changed_lines(self.xml, out)
        self.assertEqual(len(diff), 2, diff)  # the tibia capsule and the foot box
        self.assertIn('pos="0.015 0 -0.08"', out)  # the box foot at (0.03, 0, -0.16) halved
        self.assertIn('<body name="middle_left_tibia" pos="0.08 0 0.05">', out)  # the joint stays

    def test_leg_mass_adds_one_body_under_the_foot_body(self):
        out = robots.edit_leg(self.xml, "rear_right_foot", "leg_mass", 0.123, 0.3)
        self.assertEqual(out.count("dgmm_added_mass"), 1)
        at = out.index("dgmm_added_mass")
        self.assertEqual(out.rfind("<body name=", 0, at - 20), out.index('<body name="rear_right_tibia"'))
        self.assertIn('mass="0.123"', out)
        # Placed and sized in leg reaches: a robot twice as large gets a sphere twice as large.
        self.assertIn('pos="0 0 -0.021"><geom type="sphere" size="0.0105"', out)
        big = robots.edit_leg(self.xml, "rear_right_foot", "leg_mass", 0.123, 0.6)
        self.assertIn('pos="0 0 -0.042"><geom type="sphere" size="0.021"', big)

    def test_a_foot_in_a_body_with_child_bodies_is_refused(self):
        child = '<body name="child"><geom name="x" type="sphere" size="0.01"/></body>'
        foot = '<geom name="foot" type="sphere" size="0.01"/>'
        for inner in (child + foot, foot + child):  # either order: the span would not be the whole body
            with self.assertRaises(ValueError):
                robots.edit_leg(f'<body name="tibia">{inner}</body>', "foot", "short_tibia", 0.6, 0.3)

    def test_a_missing_foot_is_refused(self):
        with self.assertRaises(ValueError):
            robots.edit_leg(self.xml, "no_such_foot", "leg_mass", 0.1, 0.3)


class Planted(unittest.TestCase):
    def config(self, d):
        return {"mjcf_path": os.path.abspath(HEXAPOD),
                "robot": {"legs": [{"name": n, "foot": {"geom": n + "_foot"}} for n in
                                   ["front_left", "middle_left", "rear_left", "front_right", "middle_right",
                                    "rear_right"]]}}

    def test_kinds_by_seed(self):
        kinds = ["null", "leg", "leg_mass", "short_tibia"]
        with tempfile.TemporaryDirectory() as d:
            cfg = self.config(d)
            self.assertEqual(robots.planted(4, cfg, 2.9, 0.3, kinds, d), ("-", 0.0))
            knob, gain = robots.planted(5, cfg, 2.9, 0.3, kinds, d)
            self.assertTrue(re.fullmatch(r"actuators\.\w+\.gain", knob) and 0.3 <= gain <= 0.6)
            cfg = self.config(d)
            knob, kg = robots.planted(6, cfg, 2.9, 0.3, kinds, d)
            self.assertTrue(knob.startswith("leg_mass:") and 0.03 * 2.9 <= kg <= 0.08 * 2.9)
            self.assertEqual(cfg["mjcf_path"], os.path.join(d, "real.xml"))
            self.assertIn("dgmm_added_mass", open(cfg["mjcf_path"]).read())
            with self.assertRaises(ValueError):
                robots.planted(7, self.config(d), 2.9, 0.3, ["nonsense"], d)


if __name__ == "__main__":
    unittest.main()
