"""The tensor friction's update compiled: both Dahl tensors of every point in one pass.

:class:`constitutive.sheet_friction.SheetFrictionState` evaluates its fast and slow Dahl
tensors at every quadrature point of a drape, several times per Newton iteration. In NumPy
each of the update's dozen steps (the scaled increment, its norm, the exponential, the
3 × 3 tangent and its scaling to the curvature) is a pass over every point with a temporary
array of its own; here each point is updated once, in registers, by the same formulas
(:class:`constitutive.sheet_friction._DahlTensor`, the reference, which the tests hold the
kernel to within round-off).

Arrays are flat over the points: ``(n, 3)`` Voigt vectors and ``(n, 3, 3)`` tangents.
"""
from __future__ import annotations

import math

import numpy as np

from constitutive.compiled import njit

__all__ = ["dahl_pair"]


@njit(cache=True)
def _dahl(y_n, dz, y, dy, tangent):
    """One Dahl tensor at one point: state ``y`` after the scaled increment ``dz`` from ``y_n``
    and, with ``tangent``, ``dy/dz`` (the larger one-sided value ``(1 + |y_n|) I`` at ``dz = 0``)."""
    r = math.sqrt(dz[0] * dz[0] + dz[1] * dz[1] + dz[2] * dz[2])
    if r > 0.0:
        e0, e1, e2 = dz[0] / r, dz[1] / r, dz[2] / r
        decay = math.exp(-r)
        g = -math.expm1(-r) / r
    else:
        e0 = e1 = e2 = 0.0
        decay, g = 1.0, 0.0
    e = (e0, e1, e2)
    for i in range(3):
        y[i] = e[i] * (1.0 - decay) + y_n[i] * decay
    if not tangent:
        return
    if r > 0.0:
        for i in range(3):
            for j in range(3):
                eye = 1.0 if i == j else 0.0
                dy[i, j] = g * (eye - e[i] * e[j]) + decay * (e[i] - y_n[i]) * e[j]
    else:
        ny = math.sqrt(y_n[0] * y_n[0] + y_n[1] * y_n[1] + y_n[2] * y_n[2])
        for i in range(3):
            for j in range(3):
                dy[i, j] = (1.0 + ny) if i == j else 0.0


@njit(cache=True)
def dahl_pair(y1_n, y2_n, dkappa, sf1, sa1, sf2, sa2, y1, y2, M, D, tangent):
    """The fast (1) and slow (2) Dahl tensors of every point after the curvature increment.

    Parameters
    ----------
    y1_n, y2_n : (n, 3)
        Committed states, in each tensor's orthonormal coordinates.
    dkappa : (n, 3)
        Voigt curvature increment from the committed curvature.
    sf1, sa1, sf2, sa2 : (n, 3)
        Each tensor's Voigt scales of its moments (``sf``) and of its lengths (``sa``).
    y1, y2 : (n, 3) output
        The states after the increment.
    M : (n, 3) output
        Friction moment ``sf1 y1 − sf2 y2``.
    D : (n, 3, 3) output
        With ``tangent``, ``dM/dκ = sf1 (dy1/dz1) / sa1 − sf2 (dy2/dz2) / sa2``; untouched
        without.
    tangent : bool
    """
    dz = np.empty(3)
    dy1 = np.empty((3, 3))
    dy2 = np.empty((3, 3))
    for p in range(dkappa.shape[0]):
        for i in range(3):
            dz[i] = dkappa[p, i] / sa1[p, i]
        _dahl(y1_n[p], dz, y1[p], dy1, tangent)
        for i in range(3):
            dz[i] = dkappa[p, i] / sa2[p, i]
        _dahl(y2_n[p], dz, y2[p], dy2, tangent)
        for i in range(3):
            M[p, i] = sf1[p, i] * y1[p, i] - sf2[p, i] * y2[p, i]
        if tangent:
            for i in range(3):
                for j in range(3):
                    D[p, i, j] = sf1[p, i] * dy1[i, j] / sa1[p, j] - sf2[p, i] * dy2[i, j] / sa2[p, j]
