"""The barrier stiffness κ: a physical choice from the force a vertex carries.

IPC's adaptive stiffness (Li et al. 2020, §4.3; ``ipctk.initial_barrier_stiffness``) balances
the barrier's gradient against the elastic energy's at the start and grows κ while distances
shrink; it serves a stiffness that need not mean anything. For a fabric the force a contact
vertex carries is known beforehand (its share of the weight, or of the edge loads that press it
on a body), so κ is chosen such that one vertex pressed by that force rests at ``dmin + dhat/2``,
in the middle of the barrier's layer: heavier loads sink deeper, where the barrier stiffens
without bound, and the fabric never touches the body.
"""
from __future__ import annotations

import ipctk
import numpy as np

__all__ = ["barrier_stiffness"]


def barrier_stiffness(force_per_vertex: float, dhat: float, dmin: float = 0.0) -> float:
    """κ [N/m³] of ipctk's clamped-log barrier (on squared distances) such that a single vertex
    at distance ``dmin + dhat/2`` from a body is pushed off by ``force_per_vertex`` [N].

    Examples
    --------
    >>> import ipctk
    >>> kappa = barrier_stiffness(1e-3, dhat=1e-3, dmin=2e-4)
    >>> round(ipctk.barrier_force_magnitude((2e-4 + 5e-4) ** 2, ipctk.ClampedLogBarrier(), 1e-3, kappa, 2e-4), 12)
    0.001
    """
    if not (np.isfinite(force_per_vertex) and force_per_vertex > 0):
        raise ValueError(f"force_per_vertex must be > 0, got {force_per_vertex!r}")
    if not (np.isfinite(dhat) and dhat > 0) or not dmin >= 0:
        raise ValueError(f"dhat must be > 0 and dmin >= 0, got dhat = {dhat!r}, dmin = {dmin!r}")
    d = dmin + 0.5 * dhat
    unit = ipctk.barrier_force_magnitude(d * d, ipctk.ClampedLogBarrier(), dhat, 1.0, dmin)
    return float(force_per_vertex / abs(unit))
