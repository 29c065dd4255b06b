"""The misfit between a fabric's scans and the drapes simulated at one parameter point.

Each descriptor's difference of means is measured in the scans' own scatter between
specimens, so the misfit is a sum of squared standardised differences (χ²-like):

    J = z_DC² + z_nodes² + (1/K) Σ_k z_{a_k}²,   k = 2 .. 20,

    z_DC = (mean DC_sim − mean DC_scan) / s_DC,   s_DC = max(sd DC_scan, 1 point),
    z_nodes = (mean n_sim − mean n_scan) / s_n,   s_n = max(sd n_scan, 0.5),
    z_{a_k} = (mean a_k,sim − mean a_k,scan) / s_a,k,   s_a,k = √(sd a_k,scan² + (1 mm)²).

The floors keep one scan (sd 0) or specimens that happen to agree from weighting a difference
no drape tester resolves (DC is read to about a point; a node count to one node, so half a
node is its standard error; an outline to about a millimetre). The spectrum term is the
mean over the harmonics, so the outline's shape counts as one descriptor beside DC and
nodes; a_0 (mean radius, which DC already sets) and a_1 (the outline's offset from the
centre, a set-up error) are left out. J ≤ 1 means that the point's drapes lie within the
scans' own scatter; the optimiser maximises ``-√J``, a root-sum-square distance in units of
that scatter: its flanks are nearly linear in the parameters (DC changes smoothly with them),
which a Gaussian process follows far better than the steep valley of J itself (on a model of
the DC curve the optimiser found the target bending length in 8 steps with ``-√J`` where
``-log(1 + J)`` sometimes stopped at the box's edge).
"""
from __future__ import annotations

import math

import numpy as np

from drape.identification.target import Drapes

__all__ = ["DC_FLOOR", "NODES_FLOOR", "HARMONIC_FLOOR", "FIRST_HARMONIC", "Misfit", "misfit",
           "score", "misfit_of_score"]

DC_FLOOR = 1.0          # DC points
NODES_FLOOR = 0.5       # nodes
HARMONIC_FLOOR = 1e-3   # m
FIRST_HARMONIC = 2


class Misfit(dict):
    """``{"J": ..., "z_DC": ..., "z_nodes": ..., "spectrum": ...}``."""

    @property
    def J(self) -> float:
        return self["J"]


def misfit(scans: Drapes, simulated: Drapes) -> Misfit:
    """The misfit J of ``simulated`` drapes against ``scans`` (see the module docstring).

    >>> from drape.identification.target import Drape
    >>> a = tuple([0.12] + [0.0] * 20)
    >>> scans = Drapes((Drape("s1", 50.0, 6, a), Drape("s2", 54.0, 6, a)))
    >>> m = misfit(scans, Drapes((Drape("m", 55.0, 7, a),)))
    >>> round(m["z_DC"], 3), m["z_nodes"], m["spectrum"], round(m.J, 3)
    (1.061, 2.0, 0.0, 5.125)
    """
    s_dc = max(scans.dc_std(), DC_FLOOR)
    s_n = max(scans.nodes_std(), NODES_FLOOR)
    z_dc = (simulated.dc.mean() - scans.dc.mean()) / s_dc
    z_n = (simulated.nodes.mean() - scans.nodes.mean()) / s_n
    k = slice(FIRST_HARMONIC, None)
    sd_a = scans.harmonics[:, k].std(axis=0, ddof=1) if len(scans) > 1 else 0.0
    s_a = np.sqrt(sd_a ** 2 + HARMONIC_FLOOR ** 2)
    z_a = (simulated.harmonics[:, k].mean(axis=0) - scans.harmonics[:, k].mean(axis=0)) / s_a
    spectrum = float(np.mean(z_a ** 2))
    return Misfit(J=float(z_dc ** 2 + z_n ** 2 + spectrum), z_DC=float(z_dc), z_nodes=float(z_n),
                  spectrum=spectrum)


def score(J: float) -> float:
    """What the optimiser maximises: ``-√J``.

    >>> score(0.0), round(float(misfit_of_score(score(3.0))), 12)
    (-0.0, 3.0)
    """
    return -math.sqrt(J)


def misfit_of_score(s):
    """The inverse of :func:`score` (arrays too; a surrogate's mean above 0 means J = 0)."""
    return np.minimum(np.asarray(s), 0.0) ** 2
