#!/usr/bin/env python3
"""Unit tests of scripts/walk_table.py's bad input (no simulation: a fake dgmm that refuses every
config as dgmm does, one line on stderr and status 2; ctest walk_table_test): a refused pattern is
listed under the table with dgmm's line, nothing walked is a failure, and a missing config is one
line; no traceback anywhere."""
import os
import stat
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SCRIPT = os.path.join(HERE, "walk_table.py")
HEXAPOD = os.path.join(HERE, "..", "datasets", "robots", "hexapod.json")


def fake_build(error_line):
    """A build folder whose app/dgmm prints `error_line` on stderr and exits with status 2."""
    build = tempfile.mkdtemp()
    os.makedirs(os.path.join(build, "app"))
    dgmm = os.path.join(build, "app", "dgmm")
    with open(dgmm, "w") as f:
        f.write(f"#!/bin/sh\necho 'dgmm: simulate: starting' >&2\necho '{error_line}' >&2\nexit 2\n")
    os.chmod(dgmm, os.stat(dgmm).st_mode | stat.S_IXUSR)
    return build


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)


class WalkTable(unittest.TestCase):
    def test_a_refused_pattern_is_listed_with_dgmms_line_and_nothing_walked_fails(self):
        line = "dgmm: error: x.json: robot.gait.pattern: trot needs 4 legs, the robot has 6"
        r = run("--build", fake_build(line), "--config", HEXAPOD, "--patterns", "trot", "--slopes", "0")
        self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
        self.assertIn("refused: 0 deg, trot: " + line, r.stdout)
        self.assertNotIn("Traceback", r.stdout + r.stderr)

    def test_a_missing_config_is_one_line(self):
        r = run("--build", fake_build("unused"), "--config", "/no/such/config.json")
        self.assertEqual(r.returncode, 2)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
        self.assertIn("/no/such/config.json", r.stderr)
        self.assertNotIn("Traceback", r.stderr)


if __name__ == "__main__":
    unittest.main()
