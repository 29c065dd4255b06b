"""Friction points that switch branch between the evaluation points of a step.

A Bliman–Sorine friction point's tangent jumps where its curvature increment over the step
changes sign (stick ↔ slip; :mod:`constitutive.friction`), and Newton converges quadratically
only once no point switches any more. :class:`SwitchCounter` wraps a friction state class's
``trial`` and ``commit`` and counts, per committed step, the points whose increment
κ − κ_committed has another sign than at the previous evaluation point (Newton iterates and
line-search trials; repeated evaluations at one point are counted once).

>>> from constitutive.friction import FrictionParams, FrictionState
>>> class Counted(FrictionState):      # a subclass, so that FrictionState stays as it is
...     pass
>>> counter = SwitchCounter(Counted).install()
>>> state = Counted(FrictionParams(1.0, 0.0, 0.5, 0.5), shape=(2,))
>>> for kappa in ([1.0, -1.0], [1.0, -1.0], [1.0, 1.0]):
...     _ = state.trial(np.array(kappa))
>>> state.commit(np.array([1.0, 1.0]))
>>> counter.take()
[1]
"""
from __future__ import annotations

import numpy as np

__all__ = ["SwitchCounter"]


class SwitchCounter:
    """Counts sign changes of Δκ between the distinct trial points of each step.

    Parameters
    ----------
    friction_state_class : type
        The class whose ``trial(kappa)`` and ``commit(kappa, ...)`` are wrapped by
        :meth:`install` (e.g. :class:`constitutive.friction.FrictionState`); every instance
        of it is then counted.
    """

    def __init__(self, friction_state_class):
        self.cls = friction_state_class
        self.signs = {}        # state -> sign pattern at each distinct evaluation point
        self.step = {}         # state -> switches at each new point, for the step just committed

    def install(self) -> "SwitchCounter":
        """Wrap the class's ``trial`` and ``commit``; returns the counter."""
        trial, commit = self.cls.trial, self.cls.commit
        counter = self

        def counted_trial(state, kappa):
            sig = np.sign(np.asarray(kappa, dtype=float) - state.kappa)
            seen = counter.signs.setdefault(state, [])
            if not seen or not np.array_equal(seen[-1], sig):
                seen.append(sig)
            return trial(state, kappa)

        def counted_commit(state, *args, **kwargs):
            seen = counter.signs.pop(state, [])
            counter.step[state] = [int(np.count_nonzero(b != a)) for a, b in zip(seen, seen[1:])]
            return commit(state, *args, **kwargs)

        self.cls.trial, self.cls.commit = counted_trial, counted_commit
        return self

    def take(self) -> list[int]:
        """Switches at each new evaluation point of the last step, summed over the states
        (e.g. the warp's and the weft's), and forget them."""
        rows = list(self.step.values())
        self.step = {}
        n = max((len(r) for r in rows), default=0)
        return [sum(r[i] for r in rows if i < len(r)) for i in range(n)]
