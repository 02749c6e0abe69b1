#!/usr/bin/env python3
"""Unit tests of scripts/scaled_robot.py (ctest scaled_robot_test; no simulation): the hexapod at 4x
has its lengths, masses, torques, damping and times scaled by s, s^3, s^4, s^4.5 and sqrt(s), its
config's times by sqrt(s); a factor of 1 keeps every number; what the script cannot scale (a mesh)
and a factor that is not positive are refused in one line, nothing written."""
import json
import os
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "scaled_robot.py")
HEXAPOD = os.path.join(HERE, "..", "datasets", "robots", "hexapod.json")


def run(config, factor, out):
    return subprocess.run([sys.executable, SCRIPT, "--config", config, "--factor", str(factor), "-o", out],
                          capture_output=True, text=True)


def numbers(el, key):
    return [float(v) for v in el.get(key).split()]


class ScaledRobot(unittest.TestCase):
    def scaled(self, factor):
        out = tempfile.mkdtemp()
        r = run(HEXAPOD, factor, out)
        self.assertEqual(r.returncode, 0, r.stderr)
        cfg = json.load(open(r.stdout.strip()))
        return ET.parse(os.path.join(out, cfg["mjcf_path"])).getroot(), cfg

    def test_every_quantity_scales_with_its_dimension(self):
        s = 4.0
        root, cfg = self.scaled(s)
        orig = ET.parse(os.path.join(os.path.dirname(HEXAPOD), "hexapod.xml")).getroot()
        torso, torso0 = root.find(".//geom[@name='torso']"), orig.find(".//geom[@name='torso']")
        self.assertAlmostEqual(float(torso.get("mass")), float(torso0.get("mass")) * s ** 3)
        for a, b in zip(numbers(torso, "size"), numbers(torso0, "size")):
            self.assertAlmostEqual(a, b * s)
        foot, foot0 = root.find(".//geom[@name='front_left_foot']"), orig.find(".//geom[@name='front_left_foot']")
        for a, b in zip(numbers(foot, "fromto"), numbers(foot0, "fromto")):
            self.assertAlmostEqual(a, b * s)
        d, d0 = root.find("default"), orig.find("default")
        self.assertAlmostEqual(float(d.find("position").get("kp")), float(d0.find("position").get("kp")) * s ** 4)
        self.assertAlmostEqual(float(d.find("joint").get("damping")), float(d0.find("joint").get("damping")) * s ** 4.5)
        self.assertAlmostEqual(float(d.find("joint").get("armature")), float(d0.find("joint").get("armature")) * s ** 5)
        self.assertAlmostEqual(numbers(d.find("geom"), "solref")[0], 0.02 * s ** 0.5)
        self.assertAlmostEqual(numbers(d.find("geom"), "solimp")[2], 0.001 * s)
        self.assertEqual(root.find(".//joint[@name='front_left_knee']").get("range"), "-100 60")  # angles stay
        cfg0 = json.load(open(HEXAPOD))
        for key in ("timestep_s", "command_duration_s", "settle_duration_s"):
            self.assertAlmostEqual(cfg[key], cfg0[key] * s ** 0.5)
        self.assertAlmostEqual(cfg["robot"]["gait"]["period_s"], cfg0["robot"]["gait"]["period_s"] * s ** 0.5)
        self.assertEqual(cfg["robot"]["gait"]["stride_reach"], cfg0["robot"]["gait"]["stride_reach"])  # relative

    def test_a_factor_of_one_keeps_every_number(self):
        root, _ = self.scaled(1)
        orig = ET.parse(os.path.join(os.path.dirname(HEXAPOD), "hexapod.xml")).getroot()
        for a, b in zip(root.iter("geom"), orig.iter("geom")):
            for key in ("mass", "size", "fromto", "pos"):
                if key in b.attrib:
                    self.assertEqual(numbers(a, key), numbers(b, key))

    def test_what_it_cannot_scale_is_refused_in_one_line(self):
        folder = tempfile.mkdtemp()
        with open(os.path.join(folder, "m.xml"), "w") as f:
            f.write('<mujoco><asset><mesh name="m" file="m.stl"/></asset><worldbody/></mujoco>')
        with open(os.path.join(folder, "m.json"), "w") as f:
            json.dump({"mjcf_path": "m.xml"}, f)
        out = os.path.join(folder, "out")
        for config, factor, expected in ((os.path.join(folder, "m.json"), 2, "<mesh> is not scaled"),
                                         (HEXAPOD, 0, "--factor: a positive number expected"),
                                         (os.path.join(folder, "none.json"), 2, "none.json")):
            r = run(config, factor, out)
            self.assertEqual(r.returncode, 2, r.stdout)
            self.assertIn(expected, r.stderr)
            self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
            self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main()
