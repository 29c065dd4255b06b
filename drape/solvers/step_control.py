"""The step size of :func:`drape.solvers.time_stepping.integrate`: by Newton, or by the local error.

By Newton: halved on failure, doubled after a run of successes. By the local error estimate
of Zienkiewicz & Xie (1991), ``e = |β − 1/6| Δt² ‖a₁ − a₀‖``, kept below
``error_tolerance × max‖u‖``.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # annotations only: newmark imports this module
    from drape.solvers.newmark import NewmarkState
__all__ = ['StepControl']


@dataclass
class StepControl:
    """Where :func:`integrate`'s step control stands after a converged step.

    Given back to :func:`integrate` (``control=``), the step sequence continues as if the
    integration had never stopped (a run resumed from its checkpoint).
    """

    dt: float                      # size of the next step, before landing on hit times
    successes: int = 0             # converged steps since the size last changed
    patience: int | None = None    # converged steps the size must wait before it doubles
    trial: bool = False            # the size was just doubled and has not converged yet


class _StepSize:
    """Step size of :func:`integrate`: halved on failure; then doubled after ``patience``
    successes up to ``dt_max``, or set by the local error estimate.

    ``patience`` starts at ``grow_after`` and doubles with every failure (up to
    ``MAX_BACKOFF × grow_after``); once a doubled size has converged it is ``grow_after``
    again. Where a size keeps failing for a while, as where a limp fabric folds, the step
    stays short longer each time instead of being cut again after every few steps."""

    MAX_BACKOFF = 16

    def __init__(self, dt, dt_max, max_cuts, grow_after, error_tolerance, control):
        self.dt, self.dt_max, self.grow_after = dt, dt_max, int(grow_after)
        self.h_min = dt / 2.0 ** int(max_cuts)
        self.error_tolerance = error_tolerance
        self.h, self.successes, self.patience = dt, 0, self.grow_after
        self.trial = False          # the size was just doubled and has not converged yet
        if control is not None:
            self.h = float(np.clip(control.dt, self.h_min, dt_max))
            self.successes = int(control.successes)
            if control.patience is not None:
                self.patience = max(int(control.patience), self.grow_after)
            self.trial = bool(control.trial)

    def can_cut(self) -> bool:
        """Whether a failed step can still be halved."""
        return self.h > self.h_min * (1 + 1e-12)

    def failed(self) -> bool:
        """Halve after a Newton failure; False when already at the smallest size."""
        if not self.can_cut():
            return False
        self.h, self.successes = max(0.5 * self.h, self.h_min), 0
        self.patience = min(2 * self.patience, self.MAX_BACKOFF * self.grow_after)
        self.trial = False
        return True

    def error(self, old: NewmarkState, new: NewmarkState, beta: float) -> float:
        """Zienkiewicz-Xie estimate relative to the tolerance (NaN without one)."""
        if self.error_tolerance is None:
            return float("nan")
        h = new.t - old.t
        e = abs(beta - 1.0 / 6.0) * h * h * float(np.linalg.norm(new.a - old.a))
        ref = max(float(np.linalg.norm(new.u)), float(np.linalg.norm(old.u)), np.finfo(float).tiny)
        return e / (self.error_tolerance * ref)

    def accept(self, eta: float, h_taken: float, landed: bool) -> bool:
        """Next size after a converged step of size ``h_taken``; False: redo with the new size."""
        if self.error_tolerance is None:
            self.successes += 1
            if self.trial:
                self.patience, self.trial = self.grow_after, False
            if self.successes >= self.patience and self.h < self.dt_max:
                self.h, self.successes, self.trial = min(2.0 * self.h, self.dt_max), 0, True
            return True
        factor = float(np.clip(0.9 * max(eta, 1e-12) ** (-1.0 / 3.0), 0.5, 2.0))
        if eta > 1.0 and h_taken > self.h_min * (1 + 1e-12):
            self.h, self.successes = max(factor * h_taken, self.h_min), 0
            return False
        if not landed:  # a step shortened to land on a mark says nothing about the size
            self.h = float(np.clip(factor * h_taken, self.h_min, self.dt_max))
        self.successes += 1
        return True
