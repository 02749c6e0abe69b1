#!/usr/bin/env python3
"""Unit tests of scripts/drop_leg.py (no dgmm needed; ctest drop_leg_test): the leg's body, its
joints, actuators and config entry go and nothing else does; bad input exits with one line."""
import json
import os
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "drop_leg.py")
HEXAPOD = os.path.join(HERE, "..", "datasets", "robots", "hexapod.json")


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


def names(root, tag):
    return {e.get("name") for e in root.iter(tag) if e.get("name")}


class DropLeg(unittest.TestCase):
    def setUp(self):
        self.out = tempfile.mkdtemp()

    def test_the_leg_goes_with_its_joints_actuators_and_config_entry(self):
        r = run("--config", HEXAPOD, "--leg", "rear_right", "--out", self.out)
        self.assertEqual(r.returncode, 0, r.stderr)
        cfg = json.load(open(r.stdout.strip().splitlines()[-1]))
        self.assertEqual([l["name"] for l in cfg["robot"]["legs"]],
                         ["front_left", "middle_left", "rear_left", "front_right", "middle_right"])
        self.assertEqual(cfg["robot"]["gait"]["pattern"], "auto")  # tripod needs six legs
        before = ET.parse(os.path.join(os.path.dirname(HEXAPOD), "hexapod.xml")).getroot()
        after = ET.parse(cfg["mjcf_path"]).getroot()
        self.assertEqual(names(before, "joint") - names(after, "joint"),
                         {"rear_right_hip_yaw", "rear_right_hip_pitch", "rear_right_knee"})
        self.assertEqual(len(list(before.iter("position"))) - len(list(after.iter("position"))), 3)
        self.assertEqual(names(before, "geom") - names(after, "geom"), {"rear_right_foot"})
        self.assertTrue(os.path.isabs(after.find("compiler").get("meshdir")))

    def test_custom_phases_lose_the_legs_phase(self):
        cfg = json.load(open(HEXAPOD))
        cfg["mjcf_path"] = os.path.abspath(os.path.join(os.path.dirname(HEXAPOD), cfg["mjcf_path"]))
        cfg["robot"]["gait"].update(pattern="custom", phases=[0.0, 0.1, 0.2, 0.3, 0.4, 0.5])
        path = os.path.join(self.out, "custom.json")
        json.dump(cfg, open(path, "w"))
        r = run("--config", path, "--leg", "front_right", "--out", self.out)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(json.load(open(r.stdout.strip()))["robot"]["gait"]["phases"], [0.0, 0.1, 0.2, 0.4, 0.5])

    def test_bad_input_is_one_line_naming_the_part_and_writes_nothing(self):
        r = run("--config", HEXAPOD, "--leg", "tail", "--out", self.out)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("no leg named tail", r.stderr)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
        r = run("--config", os.path.join(self.out, "missing.json"), "--leg", "rear_right", "--out", self.out)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("missing.json", r.stderr)
        self.assertEqual(os.listdir(self.out), [])


if __name__ == "__main__":
    unittest.main()
