#!/usr/bin/env python3
"""Tests of scripts/multimodality.py's statistic, bootstrap and corrections (ctest: multimodality_test).

Small sizes: runs in seconds. The statistic must be affine invariant (the bootstrap relies on it),
find two separated clusters, not find them in one Gaussian, and the EM must reach scikit-learn's
maximum on a clear two-cluster set."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import multimodality as mm  # noqa: E402


def p_value(x, bootstrap, seed, z=None):
  rng = np.random.default_rng(seed)
  data = x[None] if z is None else mm.residuals(x[None], z)
  t_obs, _ = mm.statistic(data, 20, rng)
  noise = rng.standard_normal((bootstrap,) + x.shape)
  t_null, _ = mm.statistic(noise if z is None else mm.residuals(noise, z), 20, rng)
  return (1 + np.count_nonzero(t_null >= t_obs[0])) / (bootstrap + 1)


class Statistic(unittest.TestCase):
  def setUp(self):
    rng = np.random.default_rng(7)
    self.gauss = rng.standard_normal((15, 3))
    self.two = rng.standard_normal((15, 3)) * 0.2
    self.two[:7, 0] += 3.0  # two clusters 15 sd apart along the first axis

  def test_affine_invariant(self):
    a = np.array([[2.0, 0.3, 0.0], [0.0, 0.01, 0.5], [1.0, 0.0, 40.0]])
    t1, _ = mm.statistic(self.two[None], 20, np.random.default_rng(1))
    t2, _ = mm.statistic((self.two @ a.T + 5.0)[None], 20, np.random.default_rng(1))
    self.assertAlmostEqual(t1[0], t2[0], places=6)

  def test_two_clusters_found_one_gaussian_not(self):
    self.assertLessEqual(p_value(self.two, 99, 1), 0.01)
    self.assertGreater(p_value(self.gauss, 99, 1), 0.05)

  def test_given_z_removes_modes_that_z_explains(self):
    z = np.zeros((15, 1))
    z[:7, 0] = 1.0  # the clusters are exactly the two values of z
    self.assertGreater(p_value(self.two, 99, 2, z=z), 0.05)

  def test_em_reaches_the_maximum(self):
    try:
      from sklearn.mixture import GaussianMixture
    except ImportError:
      self.skipTest("scikit-learn not installed")
    xw = mm.whiten(self.two[None])
    ours, _ = mm.tied_two_loglik(xw, 20, np.random.default_rng(3))
    gm = GaussianMixture(2, covariance_type="tied", n_init=20, reg_covar=1e-10, random_state=0,
                         max_iter=1000, tol=1e-10).fit(xw[0])
    self.assertGreater(ours[0], gm.score(xw[0]) * 15 - 1e-6)

  def test_held_out_gain_rewards_seen_clusters_only(self):
    rng = np.random.default_rng(4)
    train, test = self.two[::2], self.two[1::2]
    self.assertGreater(mm.held_out_gain(train, test, 20, rng), 0.0)
    # A cluster never seen in training, between the two: the tight two-cluster fit pays for it.
    third = self.two[7:11] + np.array([1.5, 0.0, 0.0])
    self.assertLess(mm.held_out_gain(self.two, third, 20, rng), 0.0)


class Holm(unittest.TestCase):
  def test_step_down(self):
    p = np.array([0.001, 0.04, 0.012, 0.3])
    # thresholds 0.05/4, 0.05/3, 0.05/2, 0.05/1 in order of p: 0.001 and 0.012 pass, 0.04 fails.
    self.assertEqual(mm.holm(p, 0.05).tolist(), [True, False, True, False])


if __name__ == "__main__":
  unittest.main()
