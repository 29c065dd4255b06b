"""Bayesian optimisation of the misfit: a Gaussian-process surrogate (``bayes_opt``).

The optimiser (Nogueira, *Bayesian Optimization: open source constrained global optimization
tool for Python*, 2014–; scikit-learn's GP with a Matérn 5/2 kernel) works in log10 of the
parameters mapped to [0, 1] over the box and maximises ``-√J`` (:func:`drape.identification.objective.score`). Its
ask–tell interface keeps the loop here: :meth:`Surrogate.suggest` gives the next point,
:meth:`Surrogate.register` adds a finished one, and the constant-liar acquisition lets several
points be in flight at once (each suggested point counts as evaluated at a dummy value until
its result comes). The GP models the drape's own seed scatter as noise (``alpha``).

The identified point maximises the surrogate's score less one posterior standard deviation (a
cautious choice: few evaluations leave it by the best of them rather than in a corner the
surrogate knows nothing of). The uncertainty interval of a parameter is the range it spans over the region of the box
where the surrogate's misfit, one posterior standard deviation on the hopeful side, is within
1 of its mean misfit at the identified point: there a point's drapes may match the scans as well as the best
one, up to one standard deviation of the scans' own scatter per descriptor (``J`` is a sum of
squared standardised differences), given what the evaluations tell. Few evaluations leave
the surrogate unsure, and the intervals wide.
"""
from __future__ import annotations

import contextlib
import io
import math

import numpy as np

from drape.identification.objective import misfit_of_score, score

__all__ = ["Surrogate", "design", "unit_distance", "NOISE", "WITHIN"]

#: GP noise (variance, on the normalised score): the seed scatter of a point's misfit.
NOISE = 0.05
#: The uncertainty region: surrogate misfit within this of its minimum.
WITHIN = 1.0
#: Bounds of the GP's length scales, in units of the box's width (log scale).
LENGTH_SCALES = (0.1, 10.0)
#: Exploration weight of the upper confidence bound.
KAPPA = 2.576


def _key(name: str) -> str:
    return f"u_{name}"


def _unit(box: dict, point: dict) -> dict:
    """``point`` in the surrogate's coordinates: log10 of each parameter mapped to [0, 1] over the box."""
    return {k: math.log10(point[k] / lo) / math.log10(hi / lo) for k, (lo, hi) in box.items()}


def unit_distance(box: dict, a: dict, b: dict) -> float:
    """Largest difference of two points in any parameter, in widths of the box (log scale).

    >>> round(unit_distance({"bending_length": (1.0, 10.0)}, {"bending_length": 2.0}, {"bending_length": 2.2}), 6)
    0.041393
    """
    ua, ub = _unit(box, a), _unit(box, b)
    return max(abs(ua[k] - ub[k]) for k in box)


def design(box: dict, n: int, seed: int = 0) -> list[dict]:
    """The initial points: the box's low and high corners, then ``n`` Latin-hypercube points
    (log scale, fixed seed: the same box gives the same design, so a library reuses it).

    >>> pts = design({"bending_length": (1.0, 4.0)}, 2)
    >>> [round(p["bending_length"], 3) for p in pts[:2]], len(pts)
    ([1.0, 4.0], 4)
    """
    from scipy.stats import qmc

    names = list(box)
    lo = np.log10([box[k][0] for k in names])
    hi = np.log10([box[k][1] for k in names])
    corners = [dict(zip(names, 10 ** lo)), dict(zip(names, 10 ** hi))]
    unit = qmc.LatinHypercube(d=len(names), seed=seed).random(n) if n else np.empty((0, len(names)))
    inner = [dict(zip(names, 10 ** (lo + u * (hi - lo)))) for u in unit]
    return [{k: float(f"{v:.6g}") for k, v in p.items()} for p in corners + inner]


class Surrogate:
    """The GP surrogate and its acquisition over ``box`` (name -> (low, high))."""

    def __init__(self, box: dict, random_state: int = 0):
        from bayes_opt import BayesianOptimization, acquisition
        from sklearn.gaussian_process.kernels import Matern

        self.box = dict(box)
        self.names = list(box)
        bounds = {_key(k): (0.0, 1.0) for k in box}       # log10 of the box mapped to [0, 1]
        acq = acquisition.ConstantLiar(
            acquisition.UpperConfidenceBound(kappa=KAPPA, random_state=random_state),
            random_state=random_state)
        self.bo = BayesianOptimization(f=None, pbounds=bounds, acquisition_function=acq,
                                       random_state=random_state, verbose=0,
                                       allow_duplicate_points=True)
        # length scales from a tenth of the box up: a few evaluations must not let the fit
        # pick a scale so short that the surrogate knows nothing between them
        self.bo.set_gp_params(alpha=NOISE, normalize_y=True, kernel=Matern(
            length_scale=[0.3] * len(box), length_scale_bounds=LENGTH_SCALES, nu=2.5))
        self.count = 0

    def _params(self, point: dict) -> dict:
        return {_key(k): v for k, v in _unit(self.box, point).items()}

    def _point(self, params: dict) -> dict:
        return {k: float(f"{lo * (hi / lo) ** float(params[_key(k)]):.6g}")
                for k, (lo, hi) in self.box.items()}

    def register(self, point: dict, J: float) -> None:
        """Add an evaluated point (its misfit J)."""
        # a point run twice (seeds of a library point, a resumed final) is data, not an error;
        # bayes_opt prints a line for each such point, held back here
        with contextlib.redirect_stdout(io.StringIO()):
            self.bo.register(self._params(point), score(J))
        self.count += 1

    def suggest(self) -> dict:
        """The next point to evaluate (values, not logs)."""
        return self._point(self.bo.suggest())

    def withdraw(self) -> None:
        """Forget the last suggestion, which will not be run: the constant liar would otherwise
        keep its stand-in score there in every later suggestion."""
        dummies = self.bo.acquisition_function.dummies
        if dummies:
            dummies.pop()

    def predict(self, points: list[dict]) -> tuple[np.ndarray, np.ndarray]:
        """Surrogate misfit at ``points``: its posterior mean J and the J one standard
        deviation better (the optimistic side)."""
        mean, std = self.bo.predict([self._params(p) for p in points], return_std=True)
        return misfit_of_score(mean), misfit_of_score(np.asarray(mean) + np.asarray(std))

    def sample(self, n: int = 4096, seed: int = 1) -> list[dict]:
        """Points filling the box (a full grid in 1-D and 2-D, Sobol beyond)."""
        from scipy.stats import qmc

        d = len(self.names)
        if d <= 2:
            side = 121 if d == 1 else 61
            axes = np.meshgrid(*[np.linspace(0.0, 1.0, side)] * d, indexing="ij")
            unit = np.stack([a.ravel() for a in axes], axis=1)
        else:
            unit = qmc.Sobol(d=d, seed=seed).random(n)
        lo = np.log10([self.box[k][0] for k in self.names])
        hi = np.log10([self.box[k][1] for k in self.names])
        return [dict(zip(self.names, 10 ** (lo + u * (hi - lo)))) for u in unit]

    def identified(self) -> dict:
        """The surrogate's best point and each parameter's interval (module docstring)."""
        points = self.sample()
        mean, std = self.bo.predict([self._params(p) for p in points], return_std=True)
        J, J_hopeful = misfit_of_score(mean), misfit_of_score(mean + std)
        # the answer is where the surrogate is best one standard deviation on the cautious
        # side: with few evaluations that stays by the best of them, not in a corner the
        # surrogate knows nothing of; with many it is the minimum of the mean
        best = int(np.argmin(misfit_of_score(mean - std)))
        inside = J_hopeful <= J[best] + WITHIN
        out = {"point": {k: float(points[best][k]) for k in self.names},
               "J_surrogate": float(J[best]), "intervals": {}}
        for k in self.names:
            values = np.array([p[k] for p in points])[inside]
            lo, hi = float(values.min()), float(values.max())
            edge = [side for side, v, b in (("low", lo, self.box[k][0]), ("high", hi, self.box[k][1]))
                    if math.isclose(v, b, rel_tol=1e-6)]
            out["intervals"][k] = {"low": lo, "high": hi, "at_box_edge": edge}
        return out
