"""A rigid body's prescribed motion: a translation through keyframes, linear between them.

The body is held at its first keyframe's offset before the first time and at its last one's
after the last time. Its velocity is the slope of the keyframe interval that *ends* at or
after t (left-continuous): a time step ending at a keyframe moved the body at that
interval's speed, and one starting there moves it at the next one's.

Examples
--------
>>> push = RigidPath(times=[0.0, 2.0], translations=[[0, 0, 0], [0.04, 0, 0]])
>>> push.offset(1.0).tolist(), push.velocity(1.0).tolist()
([0.02, 0.0, 0.0], [0.02, 0.0, 0.0])
>>> push.offset(5.0).tolist(), push.velocity(5.0).tolist()    # held after the last keyframe
([0.04, 0.0, 0.0], [0.0, 0.0, 0.0])
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import ContactInputError

__all__ = ["RigidPath", "OnPath"]


@dataclass(frozen=True, eq=False)
class RigidPath:
    """Keyframed translation of a rigid body.

    Parameters
    ----------
    times : array_like, shape (k,)
        Keyframe times (s), strictly increasing; k >= 1.
    translations : array_like, shape (k, 3)
        The body's offset from where it was placed (m) at each keyframe.

    Raises
    ------
    ContactInputError
        Shapes that do not match, times not strictly increasing, values not finite.
    """

    times: np.ndarray
    translations: np.ndarray

    def __post_init__(self):
        times = np.array(self.times, dtype=float).reshape(-1)
        moves = np.array(self.translations, dtype=float)
        if times.size == 0:
            raise ContactInputError("path.times must hold at least one time")
        if moves.shape != (times.size, 3):
            raise ContactInputError(f"path.translations must be {times.size} rows of 3 numbers "
                                    f"(one per time), not shape {moves.shape}")
        if not (np.isfinite(times).all() and np.isfinite(moves).all()):
            raise ContactInputError("path.times and path.translations must be finite")
        if (np.diff(times) <= 0).any():
            raise ContactInputError("path.times must be strictly increasing")
        for name, value in (("times", times), ("translations", moves)):
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    @classmethod
    def still(cls) -> "RigidPath":
        """A body that does not move."""
        return cls(times=[0.0], translations=[[0.0, 0.0, 0.0]])

    @property
    def moves(self) -> bool:
        """Whether any keyframe differs from the first."""
        return bool(np.ptp(self.translations, axis=0).any())

    def offset(self, t: float) -> np.ndarray:
        """Translation (m) at time ``t``, shape (3,)."""
        return np.array([np.interp(t, self.times, self.translations[:, k]) for k in range(3)])

    def velocity(self, t: float) -> np.ndarray:
        """Velocity (m/s) at time ``t``, shape (3,): the slope of the interval ``(tᵢ, tᵢ₊₁]``
        holding ``t``, zero before the first keyframe and after the last."""
        i = int(np.searchsorted(self.times, t, side="left"))
        if i == 0 or i == len(self.times):
            return np.zeros(3)
        return (self.translations[i] - self.translations[i - 1]) / (self.times[i] - self.times[i - 1])


class OnPath:
    """Where a body following its ``path`` attribute (a :class:`RigidPath`; None: still) is."""

    path = None

    def offset(self, t: float) -> np.ndarray:
        """Translation [m] of the body at time ``t``."""
        return np.zeros(3) if self.path is None else np.asarray(self.path.offset(t), dtype=float)

    def velocity(self, t: float) -> np.ndarray:
        """Velocity [m/s] of the body at time ``t``."""
        return np.zeros(3) if self.path is None else np.asarray(self.path.velocity(t), dtype=float)
