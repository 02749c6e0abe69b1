"""dgmm from Python: dynamic Gaussian mixture motion models (Edgington, Kassahun & Kirchner).

Low level (the C++ library, module ``dgmm._dgmm``): ``SampleSet``, ``MotionModel``, ``fit_dgmm``,
``fit_em``, ``predict``. Estimators in the style of scikit-learn: ``DGMM`` and ``EMMixture``
(parameters in the constructor, ``fit``, ``score_samples``, ``score``, ``sample``, ``get_params``,
``set_params``; ``save`` and ``load`` for the library's HDF5 model files). See docs/python.md.
"""
import numpy as np

from ._dgmm import InputError, MotionModel, SampleSet, calibrate_regions, estimate_persistence, fit_dgmm, fit_em, predict

__all__ = ["DGMM", "EMMixture", "InputError", "MotionModel", "SampleSet", "calibrate_regions", "estimate_persistence", "fit_dgmm", "fit_em", "predict", "as_set"]


def as_set(X, commands=None, Z=None):
    """A SampleSet from a SampleSet (returned as is) or from arrays: X (n, dx) pose changes,
    commands (n,) integer command ids (default: all 0), Z (n, dz) terrain or None."""
    if isinstance(X, SampleSet):
        return X
    X = np.asarray(X, dtype=float)
    if X.ndim != 2:
        raise ValueError(f"X: expected a 2-D array (samples x pose dimensions), got shape {X.shape}")
    commands = np.zeros(len(X), dtype=np.int32) if commands is None else np.asarray(commands, dtype=np.int32)
    Z = None if Z is None else np.asarray(Z, dtype=float).reshape(len(X), -1)
    return SampleSet(X, commands, Z)


class _Estimator:
    """Shared behaviour: parameters from the constructor's signature, scoring through the model."""

    _params = ()

    def get_params(self, deep=True):
        return {name: getattr(self, name) for name in self._params}

    def set_params(self, **params):
        for name, value in params.items():
            if name not in self._params:
                raise ValueError(f"{type(self).__name__}: unknown parameter {name!r}")
            setattr(self, name, value)
        return self

    def _model(self):
        if getattr(self, "model_", None) is None:
            raise ValueError(f"{type(self).__name__}: not fitted yet; call fit first")
        return self.model_

    def score_samples(self, X, commands=None, Z=None):
        """log p(x_i | c_i [, z_i]) of every sample, in the raw units of x."""
        return np.asarray(self._model().score_samples(as_set(X, commands, Z)))

    def score(self, X, commands=None, Z=None):
        """Mean log-likelihood per sample."""
        return float(self._model().score(as_set(X, commands, Z)))

    def sample(self, n_samples=1, command=0, z=None, random_state=None):
        """n_samples draws of x from p(x | command[, z]) (n_samples x dx)."""
        seed = self.seed if random_state is None else int(random_state)
        return np.asarray(self._model().sample(command, n_samples, None if z is None else np.asarray(z, float), seed))

    def save(self, path):
        self._model().write(str(path))

    @classmethod
    def load(cls, path):
        estimator = cls()
        estimator.model_ = MotionModel.read(str(path))
        return estimator


class DGMM(_Estimator):
    """One dynamic Gaussian mixture per command, learnt one sample at a time (as `dgmm fit`).

    k: merge rate; with_terrain: model x || z and condition on z; max_components: cap per
    command (None: the library's default rule); variant, covariance, init_scale: as the CLI's
    --variant, --covariance and --init-scale; seed: of every random choice."""

    _params = ("k", "with_terrain", "max_components", "variant", "covariance", "init_scale", "seed")

    def __init__(self, k=0.7, with_terrain=True, max_components=None, variant="faithful", covariance="prior",
                 init_scale=0.3, seed=1):
        self.k, self.with_terrain, self.max_components = k, with_terrain, max_components
        self.variant, self.covariance, self.init_scale, self.seed = variant, covariance, init_scale, seed

    def fit(self, X, commands=None, Z=None):
        self.model_ = fit_dgmm(as_set(X, commands, Z), k=self.k, with_terrain=self.with_terrain, seed=self.seed,
                               max_components=self.max_components or 0, variant=self.variant,
                               covariance=self.covariance, init_scale=self.init_scale)
        return self


class EMMixture(_Estimator):
    """The EM reference: one full-covariance Gaussian mixture per command (as `dgmm em`;
    scikit-learn GaussianMixture semantics: k-means++ initialisation, reg_covar, tol)."""

    _params = ("n_components", "n_init", "max_iter", "tol", "reg_covar", "with_terrain", "seed")

    def __init__(self, n_components=2, n_init=1, max_iter=100, tol=1e-3, reg_covar=1e-6, with_terrain=True, seed=1):
        self.n_components, self.n_init, self.max_iter, self.tol = n_components, n_init, max_iter, tol
        self.reg_covar, self.with_terrain, self.seed = reg_covar, with_terrain, seed

    def fit(self, X, commands=None, Z=None):
        self.model_ = fit_em(as_set(X, commands, Z), components=self.n_components, n_init=self.n_init,
                             max_iterations=self.max_iter, tolerance=self.tol, reg_covar=self.reg_covar,
                             seed=self.seed, with_terrain=self.with_terrain)
        return self
