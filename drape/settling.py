"""When a dynamic run has come to rest: the ``[stop]`` rule of a case.

A drape or cantilever run ends at ``t_end`` unless the fabric settles first. Settled means the
kinetic energy stayed below a threshold for a number of consecutive converged steps after the
loads stopped changing. The threshold is absolute (``stop.kinetic_energy`` [J]) or a fraction
of ``ρ_A g A L``, the work the self-weight does over the fabric's span (``stop.kinetic_fraction``).
"""
from __future__ import annotations

import numpy as np

from constitutive.units import G0

__all__ = ["Settling", "settling_threshold", "mesh_areas"]


class Settling:
    """[stop] rule: kinetic energy below the threshold for ``steps`` consecutive steps.

    Parameters
    ----------
    case : drape.case.Case
    threshold : float or None
        Kinetic energy [J] (:func:`settling_threshold`); None never stops.

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> case = NS(stop=NS(after=0.0, steps=2), load=NS(end_time=lambda: 0.0))
    >>> rule = Settling(case, 1e-6)
    >>> [rule(t, e) for t, e in [(0.1, 1e-7), (0.2, 1e-5), (0.3, 1e-7), (0.4, 1e-7)]]
    [False, False, False, True]
    """

    def __init__(self, case, threshold: float | None):
        self.threshold = threshold
        stop = case.stop
        self.after = stop.after if stop.after is not None else case.load.end_time()
        self.needed = stop.steps
        self.count = 0

    def __call__(self, t: float, kinetic: float) -> bool:
        if self.threshold is None or t < self.after:
            return False
        self.count = self.count + 1 if kinetic < self.threshold else 0
        return self.count >= self.needed


def settling_threshold(case, mesh, material) -> float | None:
    """Kinetic-energy threshold [J] of ``[stop]``: absolute, or a fraction of ρ_A g A L.

    A is the fabric's (mesh) area, L its span: strip/rectangle length, Cusick overhang (then
    ρ_A g A L is ``drape.cusick.kinetic_energy_threshold``'s reference), else the largest extent.
    """
    stop = case.stop
    if stop.kinetic_energy is not None:
        return stop.kinetic_energy
    if stop.kinetic_fraction is None:
        return None
    spec = case.mesh
    if spec.kind == "cusick":
        span = 0.5 * (spec.specimen_diameter - spec.disc_diameter)
    elif spec.kind in ("strip", "rectangle"):
        span = spec.length
    else:
        span = float(np.ptp(mesh.p, axis=1).max())
    area = float(np.sum(mesh_areas(mesh)))
    return stop.kinetic_fraction * float(material.areal_mass) * G0 * area * span


def mesh_areas(mesh) -> np.ndarray:
    """Triangle areas of an ``skfem.MeshTri`` (:func:`meshes.quality.triangle_areas`, unsigned).

    >>> from skfem import MeshTri
    >>> float(mesh_areas(MeshTri()).sum())
    1.0
    """
    from meshes.quality import triangle_areas
    return np.abs(triangle_areas(mesh.p, mesh.t))
