"""The Python module (python/): fit, save, reload and score match the dgmm command line; arrays
round-trip; estimators follow scikit-learn conventions; bad input raises ValueError.
Run by ctest (tests/python/CMakeLists.txt) with PYTHONPATH=<build>/python and DGMM_CLI=<dgmm>."""
import json, os, subprocess

import numpy as np
import pytest

import dgmm

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")
SHIPPED = os.path.join(ROOT, "datasets", "scorpion_sim_390.h5")
CLI = os.environ.get("DGMM_CLI", "dgmm")


def cli(*args):
    out = subprocess.run([CLI, "--quiet", *args], check=True, capture_output=True, text=True).stdout
    return json.loads(out) if "--json" in args else out


def test_fit_save_reload_score_matches_the_command_line(tmp_path):
    s = dgmm.SampleSet.read(SHIPPED)
    est = dgmm.DGMM(seed=3).fit(s)
    est.save(tmp_path / "py.h5")
    again = dgmm.DGMM.load(tmp_path / "py.h5")
    cli("fit", SHIPPED, "--seed", "3", "-o", str(tmp_path / "cli.h5"))
    cli_score = cli("score", str(tmp_path / "cli.h5"), SHIPPED, "--json")["mean_log_likelihood"]
    assert again.score(s) == pytest.approx(est.score(s), abs=1e-12)
    assert est.score(s) == pytest.approx(cli_score, rel=1e-10)
    per_sample = again.score_samples(s)
    assert per_sample.shape == (len(s),)
    assert per_sample.mean() == pytest.approx(cli_score, rel=1e-10)


def test_em_matches_the_command_line(tmp_path):
    s = dgmm.SampleSet.read(SHIPPED)
    em = dgmm.EMMixture(n_components=2, seed=5).fit(s)
    cli("em", SHIPPED, "--components", "2", "--seed", "5", "-o", str(tmp_path / "em.h5"))
    assert em.score(s) == pytest.approx(cli("score", str(tmp_path / "em.h5"), SHIPPED, "--json")["mean_log_likelihood"],
                                        rel=1e-10)
    assert em.model_.kind == "em"


def test_arrays_in_and_out():
    s = dgmm.SampleSet.read(SHIPPED)
    x = s.x
    assert x.shape == (len(s), 6) and not x.flags.owndata  # a view of the set's own array
    rng = np.random.default_rng(0)
    X = np.vstack([rng.normal(0, 1, (200, 2)), rng.normal(5, 0.5, (200, 2))])
    c = np.repeat([0, 1], 200)
    est = dgmm.DGMM(seed=1).fit(X, c)
    draws = est.sample(500, command=1, random_state=7)
    assert draws.shape == (500, 2)
    assert np.allclose(draws.mean(0), [5, 5], atol=0.15)
    assert np.array_equal(draws, est.sample(500, command=1, random_state=7))  # seeded
    mixture = est.model_.pose_mixture(1)
    assert mixture["weights"].sum() == pytest.approx(1.0)
    assert mixture["covariances"].shape[1:] == (2, 2)
    ll = est.model_.log_density(0, X[:5])
    assert ll.shape == (5,) and np.all(np.isfinite(ll))


def test_terrain_is_conditioned_on():
    rng = np.random.default_rng(1)
    Z = rng.uniform(-1, 1, (600, 1))
    X = 2.0 * Z + rng.normal(0, 0.05, (600, 1))
    est = dgmm.DGMM(seed=2).fit(X, None, Z)
    for z in (-0.5, 0.5):
        draws = est.sample(2000, command=0, z=[z], random_state=3)
        assert draws.mean() == pytest.approx(2 * z, abs=0.1)


def test_samples_near_falls_outside_the_training_range():
    rng = np.random.default_rng(2)
    Z = rng.normal(0, 0.3, (800, 1))  # e.g. a continuous command
    X = 2.0 * Z + rng.normal(0, 0.05, (800, 1))
    model = dgmm.DGMM(seed=2).fit(X, None, Z)._model()
    inside, at_data = model.samples_near(0, [0.0])
    outside, _ = model.samples_near(0, [3.0])
    assert inside > 0.5 * at_data > 0
    assert outside < 1e-6 * at_data


def test_predict_follows_the_commands():
    est = dgmm.DGMM(seed=1).fit(dgmm.SampleSet.read(SHIPPED))
    labels = est.model_.command_labels
    forward = next(i for i, l in labels.items() if l == "+0.5,0,0")
    out = dgmm.predict(est.model_, [forward] * 3, terrain=np.array([[0.0, 0.0]]), trajectories=400, seed=2)
    assert out["poses"].shape == (3, 400, 4)
    assert out["mean"][2, 0] > out["mean"][0, 0] > 0  # further forward after every command
    again = dgmm.predict(est.model_, [forward] * 3, terrain=np.array([[0.0, 0.0]]), trajectories=400, seed=2)
    assert np.array_equal(out["poses"], again["poses"])
    # On the 18 degree slope facing uphill the robot is slower than facing downhill.
    up = dgmm.predict(est.model_, [forward] * 2, ground_slope_deg=18, trajectories=400)
    down = dgmm.predict(est.model_, [forward] * 2, ground_slope_deg=18, start=[0, 0, np.pi], trajectories=400)
    assert up["mean"][1, 0] < -down["mean"][1, 0]


def test_persistence_matches_the_command_line_and_widens_only_later_steps(tmp_path):
    s = dgmm.SampleSet.read(SHIPPED)
    est = dgmm.DGMM(seed=1).fit(s)
    p = dgmm.estimate_persistence(est.model_, s)
    assert p["episodes"] == 78 and p["pairs"][0] == 312 and p["lag_correlation"].shape == (6, 5)
    assert p["first_steps"] == 78 and p["first_scale"].shape == (6,)
    # The command line prints the same estimate (two decimals) for every pose dimension.
    est.save(tmp_path / "m.h5")
    out = subprocess.run([CLI, "predict", str(tmp_path / "m.h5"), "--commands", "+0.5,0,0", "--persistence", SHIPPED,
                          "--trajectories", "10"], check=True, capture_output=True, text=True).stdout
    for name, a, phi, first in zip(s.x_names, p["shared"], p["decay"], p["first_scale"]):
        assert f"{name:<8} a = {a:.2f}  phi = {phi:.2f}" in out and f"standing x{first:.2f}" in out
    # Fully persistent dyaw: the first step is as without persistence, later ones spread wider.
    forward = next(i for i, l in est.model_.command_labels.items() if l == "+0.5,0,0")
    strong = {"shared": np.array([0, 0, 0, 0, 0, 1.0]), "decay": np.array([0, 0, 0, 0, 0, 0.95])}
    plain = dgmm.predict(est.model_, [forward] * 8, terrain=np.array([[0.0, 0.0]]), trajectories=4000, seed=3)
    held = dgmm.predict(est.model_, [forward] * 8, terrain=np.array([[0.0, 0.0]]), trajectories=4000, seed=3,
                        persistence=strong)
    assert abs(held["covariance"][0, 3, 3] / plain["covariance"][0, 3, 3] - 1) < 0.15
    assert held["covariance"][7, 3, 3] > 3 * plain["covariance"][7, 3, 3]
    with pytest.raises(ValueError):
        dgmm.predict(est.model_, [forward], persistence={"shared": np.zeros(2), "decay": np.zeros(2)})


def test_calibrated_regions_match_the_command_line(tmp_path):
    s = dgmm.SampleSet.read(SHIPPED)
    est = dgmm.DGMM(seed=1).fit(s)
    cal = dgmm.calibrate_regions(est.model_, s, trajectories=300)
    assert cal["levels"] == [0.5, 0.9] and cal["factor"].shape == (5, 2) and list(cal["episodes"]) == [78] * 5
    # The command line prints the same factors (two decimals) per horizon.
    est.save(tmp_path / "m.h5")
    out = subprocess.run([CLI, "predict", str(tmp_path / "m.h5"), "--commands", "+0.5,0,0", "--calibrate", SHIPPED,
                          "--trajectories", "300"], check=True, capture_output=True, text=True).stdout
    for k, (f50, f90) in enumerate(cal["factor"]):
        assert f"after {k + 1:2d} commands  x{f50:.2f}  x{f90:.2f}  (78 episodes)" in out
    # Applied to predict's regions: r2 scaled by the factor, the trajectories unchanged.
    forward = next(i for i, l in est.model_.command_labels.items() if l == "+0.5,0,0")
    plain = dgmm.predict(est.model_, [forward] * 2, terrain=np.array([[0.0, 0.0]]), trajectories=500, seed=3)
    wide = dgmm.predict(est.model_, [forward] * 2, terrain=np.array([[0.0, 0.0]]), trajectories=500, seed=3,
                        calibration=cal)
    assert np.array_equal(plain["poses"], wide["poses"])
    np.testing.assert_allclose(wide["region_r2"] / plain["region_r2"], cal["factor"][:2], rtol=1e-12)


def test_estimator_conventions():
    est = dgmm.DGMM(k=0.5)
    assert est.get_params()["k"] == 0.5
    assert est.set_params(k=0.9).k == 0.9
    with pytest.raises(ValueError):
        est.set_params(bogus=1)
    with pytest.raises(ValueError, match="not fitted"):
        est.score(np.zeros((3, 2)))


def test_bad_input_raises_value_error(tmp_path):
    with pytest.raises(ValueError, match="no_such.h5"):
        dgmm.SampleSet.read(str(tmp_path / "no_such.h5"))
    with pytest.raises(ValueError):
        dgmm.DGMM(k=-1).fit(np.zeros((10, 2)))
    est = dgmm.DGMM().fit(np.random.default_rng(0).normal(size=(50, 2)))
    with pytest.raises(ValueError, match="z"):
        est.sample(3, z=[1.0])
    with pytest.raises(ValueError):
        est.score(np.zeros((3, 3)))
