"""When a dynamic run has come to rest: the ``[stop]`` rule of a case.

A drape or cantilever run ends at ``t_end`` unless the fabric settles first. Settled means the
static problem is in balance: the out-of-balance force of the committed configuration,

    r(u) = f_int(u) + f_friction(u) − f_ext(t)        (no inertia, no Rayleigh or law viscosity),

restricted to the free dofs, has a norm below ``stop.out_of_balance`` times the weight for
``stop.steps`` consecutive converged steps after the loads stopped changing. The weight is
``model.force_scale(t)``: for the shell the norm of the full self-weight force vector (plus
edge loads, if any), for the plate the norm of its external load vector at the load's value at
``t`` (gravity and pressure; once the loads stop changing, their final value).

Why not the kinetic energy: a fabric held back by the law's viscosity ``d κ̇`` (or by air drag
at a long time step) creeps towards equilibrium with a tiny speed, so its kinetic energy is
small long before it gets there. The static out-of-balance is the force still driving that
creep; it measures the distance from equilibrium itself, whatever slows the motion down.
"""
from __future__ import annotations

import math

import numpy as np

from drape.case.timeline import changes_end
from drape.models.protocol import free_dofs

__all__ = ["Settling", "out_of_balance"]


def out_of_balance(model, u, t: float) -> float:
    """Norm of the static out-of-balance force at ``u`` on the free dofs [N].

    ``internal + friction − external`` at time ``t``: the model's force with zero velocity and
    acceleration (``model.evaluate``, no tangent), so neither inertia nor Rayleigh damping nor
    the law's viscous and curvature-inertia terms take part. The friction moment is that of the
    committed state at ``u`` (the trial curvature equals the committed one). Homogeneous Dirichlet dofs
    (``model.fixed_dofs``) and imposed ones (``model.prescribed(t)``) carry reactions and are
    left out.

    Parameters
    ----------
    model : drape.models.protocol.StructuralModel
    u : ndarray
        Committed displacement dofs.
    t : float
        Time [s] at which the loads are read.

    Returns
    -------
    float

    Examples
    --------
    >>> import numpy as np
    >>> from types import SimpleNamespace as NS
    >>> from drape.models.protocol import Evaluation
    >>> springs = NS(fixed_dofs=np.array([0]), prescribed=lambda t: None,     # k = 1, c = 1, f = 1
    ...              evaluate=lambda u, v, a, t, tangent=None: Evaluation(a, u + v - 1.0))
    >>> out_of_balance(springs, np.array([5.0, 1.0, 4.0]), 0.0)   # dof 0 is fixed
    3.0
    """
    u = np.asarray(u, dtype=float)
    zero = np.zeros_like(u)
    force = np.asarray(model.evaluate(u, zero, zero, t).force, dtype=float)
    imposed = model.prescribed(t)
    free = free_dofs(force.size, model.fixed_dofs, () if imposed is None else imposed[0])
    return float(np.linalg.norm(force[free]))


class Settling:
    """``[stop]`` rule: static out-of-balance below a fraction of the weight for ``steps`` steps.

    Call it once per converged step (after the model committed it); it returns True once the
    run has settled. :attr:`ratio` is the last out-of-balance over the weight (None before the
    loads stopped changing), :attr:`count` the consecutive steps that met the rule (kept by a
    checkpoint).

    Parameters
    ----------
    case : drape.case.case.Case
        ``stop.out_of_balance`` (0: never stop early), ``stop.steps``, ``stop.after`` (default:
        when the loads stop changing). A quasi-static run never stops early: it is in balance
        at every step by construction.

    Notes
    -----
    A model without weight (``force_scale`` = 0, e.g. a strip bent only by imposed rotations)
    has nothing to compare the out-of-balance with and never settles by this rule.

    Examples
    --------
    >>> import numpy as np
    >>> from types import SimpleNamespace as NS
    >>> from drape.models.protocol import Evaluation
    >>> spring = NS(fixed_dofs=np.zeros(0, int), prescribed=lambda t: None, force_scale=lambda t: 1.0,
    ...             evaluate=lambda u, v, a, t, tangent=None: Evaluation(a, u - 1.0))
    >>> case = NS(stop=NS(out_of_balance=1e-3, after=0.0, steps=2), load=NS(end_time=lambda: 0.0),
    ...           solver=NS(quasi_static=False))
    >>> rule = Settling(case)
    >>> [rule(spring, np.array([u]), t) for t, u in [(0.1, 0.99), (0.2, 0.9999), (0.3, 1.0), (0.4, 1.0)]]
    [False, False, True, True]
    >>> print(rule.reason(0.4))
    static out-of-balance 0.0e+00 of the weight < 0.001 for 2 steps at t = 0.4 s
    """

    def __init__(self, case):
        stop = case.stop
        self.fraction = 0.0 if case.solver.quasi_static else float(stop.out_of_balance)
        self.after = stop.after if stop.after is not None else changes_end(case)
        self.needed = stop.steps
        self.count = 0
        self.ratio = None

    @property
    def active(self) -> bool:
        """Whether the rule can end the run."""
        return self.fraction > 0.0

    def __call__(self, model, u, t: float) -> bool:
        self.ratio = None
        if not self.active or t < self.after:
            return False
        weight = float(model.force_scale(t))
        self.ratio = out_of_balance(model, u, t) / weight if weight > 0.0 else math.inf
        self.count = self.count + 1 if self.ratio < self.fraction else 0
        return self.count >= self.needed

    def reason(self, t: float) -> str:
        """Why the run stopped, for ``summary.json``."""
        return (f"static out-of-balance {self.ratio:.1e} of the weight < {self.fraction:g} "
                f"for {self.needed} steps at t = {t:g} s")
