"""A specimen's rigidity varying from place to place: a seeded, log-normal random field.

A real specimen is not uniform: its yarn density, crimp and finish vary over a few
centimetres, and so does its bending rigidity (strips cut from one fabric read different B).
The drape of a uniform sheet settles into evenly spaced, equal folds once a transient
perturbation has gone; a real one keeps unequal folds (the outline's irregularity,
:func:`drape.analyses.outline.outline_irregularity`, docs/theory.md §6). This field is one
persistent imperfection of that kind: the sheet's bending moment (elastic and friction alike,
so B and 2HB vary together and 2HB/B does not) is multiplied at each point by

    s(x) = exp(σ g(x) − σ²/2),   σ² = ln(1 + cv²),

with ``g`` a stationary Gaussian field of zero mean, unit variance and correlation
``exp(−|r|² / (2 ℓ²))``, so that ``s`` has mean 1 and coefficient of variation ``cv``. ``g`` is
drawn as a sum of random Fourier features (Rahimi & Recht, *Random features for large-scale
kernel machines*, NIPS 2007): ``g(x) = √(2/J) Σ_j cos(ω_j·x + φ_j)`` with ``ω_j ~ N(0, I/ℓ²)``
and ``φ_j ~ U(0, 2π)``, a smooth field defined at any point, independent of the mesh.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["RigidityVariation"]


@dataclass(frozen=True)
class RigidityVariation:
    """A seeded log-normal field of rigidity factors with mean 1.

    Parameters
    ----------
    cv : float
        Coefficient of variation of the factor, ``>= 0`` (0: uniform, every factor 1).
    correlation_length : float
        ℓ [m], the length over which the factor stays alike, ``> 0``.
    seed : int
        Seed of the field (another seed, another specimen).
    modes : int
        Number of Fourier features J.

    Examples
    --------
    >>> field = RigidityVariation(cv=0.1, correlation_length=0.02, seed=3)
    >>> s = field(np.random.default_rng(0).uniform(0, 1, (2, 20000)))
    >>> bool(abs(s.mean() - 1) < 0.02), bool(abs(s.std() / s.mean() - 0.1) < 0.02)
    (True, True)
    >>> float(RigidityVariation(cv=0.0, correlation_length=0.02)(np.zeros((2, 3))).max())
    1.0
    """

    cv: float
    correlation_length: float
    seed: int = 0
    modes: int = 256

    def __post_init__(self):
        if not (np.isfinite(self.cv) and self.cv >= 0):
            raise ValueError(f"cv = {self.cv!r} breaks cv >= 0")
        if not (np.isfinite(self.correlation_length) and self.correlation_length > 0):
            raise ValueError(f"correlation_length = {self.correlation_length!r} breaks > 0")
        if int(self.modes) < 1:
            raise ValueError(f"modes = {self.modes!r} breaks modes >= 1")

    def gaussian(self, x) -> np.ndarray:
        """``g`` at points ``x`` of shape (2, …) [m]: zero mean, unit variance over seeds."""
        x = np.asarray(x, dtype=float)
        rng = np.random.default_rng(self.seed)
        omega = rng.normal(0.0, 1.0 / self.correlation_length, (int(self.modes), 2))
        phase = rng.uniform(0.0, 2.0 * np.pi, int(self.modes))
        arg = np.tensordot(omega, x[:2], axes=(1, 0)) + phase.reshape((-1,) + (1,) * (x.ndim - 1))
        return np.sqrt(2.0 / self.modes) * np.cos(arg).sum(axis=0)

    def __call__(self, x) -> np.ndarray:
        """The factor ``s`` at points ``x`` of shape (2, …) [m]; shape (…)."""
        x = np.asarray(x, dtype=float)
        if self.cv == 0.0:
            return np.ones(x.shape[1:])
        sigma2 = np.log1p(self.cv ** 2)
        return np.exp(np.sqrt(sigma2) * self.gaussian(x) - 0.5 * sigma2)
