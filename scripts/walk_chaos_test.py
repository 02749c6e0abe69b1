#!/usr/bin/env python3
"""Unit tests of scripts/walk_chaos.py (ctest walk_chaos_test; no simulation): the heavier config
adds the mass to the payload (at the torso's origin without one) and changes nothing else; the
ratio is 0 for recordings that pair, about sqrt(2) for independent ones, and refuses recordings
of different sizes; only executions both recordings kept are paired; an unbuilt dgmm is one line and exit 1."""
import os
import subprocess
import sys
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import walk_chaos  # noqa: E402


class WalkChaos(unittest.TestCase):
    def test_heavier_adds_the_mass_to_the_payload_only(self):
        cfg = {"slope_deg": 10, "robot": {"torso_body": "torso"}}
        out = walk_chaos.heavier(cfg, 0.002)
        self.assertEqual(out["payload"], {"mass_kg": 0.002, "position_body_m": [0.0, 0.0, 0.0]})
        self.assertNotIn("payload", cfg, "the config given is not changed")
        self.assertEqual({k: v for k, v in out.items() if k != "payload"}, cfg)
        carried = walk_chaos.heavier({"payload": {"mass_kg": 1.5, "position_body_m": [0.1, 0, 0]}}, 0.001)
        self.assertAlmostEqual(carried["payload"]["mass_kg"], 1.501)
        self.assertEqual(carried["payload"]["position_body_m"], [0.1, 0, 0])

    def test_ratio_is_zero_for_paired_and_near_sqrt2_for_independent_recordings(self):
        rng = np.random.default_rng(3)
        command = np.repeat(np.arange(10), 200)
        x = rng.normal(size=(2000, 6)) + command[:, None]
        np.testing.assert_allclose(walk_chaos.paired_ratio(x, x.copy(), command), 0)
        independent = rng.normal(size=(2000, 6)) + command[:, None]
        np.testing.assert_allclose(walk_chaos.paired_ratio(x, independent, command), np.sqrt(2), rtol=0.1)
        slight = x + 0.01 * rng.normal(size=x.shape)
        self.assertLess(walk_chaos.paired_ratio(x, slight, command).max(), 0.02)
        with self.assertRaises(ValueError):
            walk_chaos.paired_ratio(x, x[:-5], command)

    def test_only_executions_both_recordings_kept_are_paired(self):
        x = {(0, 0): [1.0], (0, 1): [2.0], (1, 0): [3.0]}
        changed = {(0, 0): [1.5], (1, 0): [3.5], (2, 0): [9.0]}
        a, b, command, unpaired = walk_chaos.in_both(x, changed, {k: 7 for k in x})
        np.testing.assert_array_equal(a, [[1.0], [3.0]])
        np.testing.assert_array_equal(b, [[1.5], [3.5]])
        np.testing.assert_array_equal(command, [7, 7])
        self.assertEqual(unpaired, 2)

    def test_an_unbuilt_dgmm_is_one_line(self):
        config = os.path.join(HERE, "..", "datasets", "robots", "hexapod.json")
        run = subprocess.run([sys.executable, os.path.join(HERE, "walk_chaos.py"), "--config", config,
                              "--build", "/nonexistent"], capture_output=True, text=True)
        self.assertEqual(run.returncode, 1)
        self.assertEqual(len(run.stderr.strip().splitlines()), 1)
        self.assertIn("not built", run.stderr)


if __name__ == "__main__":
    unittest.main()
