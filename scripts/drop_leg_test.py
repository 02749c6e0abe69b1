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

    def test_an_included_model_is_inlined_and_its_keyframe_loses_the_legs_entries(self):
        # The layout of MuJoCo Menagerie: scene.xml includes the robot's file, which has a home keyframe.
        robot = ET.parse(os.path.join(os.path.dirname(HEXAPOD), "hexapod.xml")).getroot()
        joints = [j.get("name") for j in robot.iter("joint") if j.get("name")]
        actuators = [a.get("joint") for s in robot.findall("actuator") for a in s]
        qpos = ["0", "0", "0.2", "1", "0", "0", "0"] + [str(i) for i in range(len(joints))]
        ET.SubElement(ET.SubElement(robot, "keyframe"), "key", name="home", qpos=" ".join(qpos),
                      ctrl=" ".join(str(100 + joints.index(j)) for j in actuators))
        ET.ElementTree(robot).write(os.path.join(self.out, "robot.xml"))
        with open(os.path.join(self.out, "scene.xml"), "w") as f:
            f.write('<mujoco model="scene"><include file="robot.xml"/></mujoco>')
        cfg = json.load(open(HEXAPOD))
        cfg["mjcf_path"] = "scene.xml"
        path = os.path.join(self.out, "scene.json")
        json.dump(cfg, open(path, "w"))
        r = run("--config", path, "--leg", "middle_left", "--out", os.path.join(self.out, "out"))
        self.assertEqual(r.returncode, 0, r.stderr)
        after = ET.parse(json.load(open(r.stdout.strip().splitlines()[-1]))["mjcf_path"]).getroot()
        self.assertIsNone(after.find(".//include"))
        key = after.find("keyframe/key")
        kept = [i for i, j in enumerate(joints) if not j.startswith("middle_left_")]
        self.assertEqual(key.get("qpos").split(), qpos[:7] + [str(i) for i in kept])
        self.assertEqual(key.get("ctrl").split(),
                         [str(100 + joints.index(j)) for j in actuators if not j.startswith("middle_left_")])

    def test_a_keyframe_of_another_length_is_refused(self):
        robot = ET.parse(os.path.join(os.path.dirname(HEXAPOD), "hexapod.xml")).getroot()
        ET.SubElement(ET.SubElement(robot, "keyframe"), "key", name="home", qpos="0 0 0.2")
        ET.ElementTree(robot).write(os.path.join(self.out, "short_key.xml"))
        cfg = json.load(open(HEXAPOD))
        cfg["mjcf_path"] = "short_key.xml"
        json.dump(cfg, open(os.path.join(self.out, "short_key.json"), "w"))
        r = run("--config", os.path.join(self.out, "short_key.json"), "--leg", "rear_right",
                "--out", os.path.join(self.out, "out"))
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("keyframe home: qpos has 3 values, 25 expected", r.stderr)
        self.assertFalse(os.path.exists(os.path.join(self.out, "out")))

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
