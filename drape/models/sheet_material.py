"""What a structural model reads from a material: one adapter for the plate and the shell.

A material is any object with ``areal_mass`` [kg/m²] and ``warp`` / ``weft``
(:class:`constitutive.law.BendingLaw`); ``twist_rigidity`` [N·m] and the membrane
(``membrane_stiffness()``, or ``E11, E22, nu12, G12`` [N/m]) are optional, and where a material
gives none the defaults of :mod:`constitutive.defaults` apply: the same values a material
file without them gets.

>>> from constitutive.law import BendingLaw
>>> class Cloth:
...     areal_mass, warp, weft = 0.2, BendingLaw(k1=4e-6), BendingLaw(k1=1e-6)
>>> parts = sheet_parts(Cloth())
>>> parts.twist, membrane_matrix(Cloth()).diagonal().tolist()
(2e-06, [10000.0, 10000.0, 50.0])
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from constitutive.defaults import DEFAULT_MEMBRANE, default_twist_rigidity

__all__ = ["SheetParts", "sheet_parts", "membrane_matrix"]


class SheetParts(NamedTuple):
    """A material's areal mass [kg/m²], warp and weft laws and twist rigidity D_t [N·m]."""

    areal_mass: float
    warp: object
    weft: object
    twist: float


def sheet_parts(material, error: type[Exception] = ValueError) -> SheetParts:
    """Areal mass, warp and weft laws and twist rigidity of ``material``, checked.

    ``error`` is the exception raised for a material that lacks one or breaks a rule (the
    model's own input error), naming the attribute.
    """
    try:
        rho = float(material.areal_mass)
        warp, weft = material.warp, material.weft
    except AttributeError as err:
        raise error(f"material lacks {err}: need areal_mass, warp and weft "
                    "(and optionally twist_rigidity), as a FabricMaterial has") from None
    twist = getattr(material, "twist_rigidity", None)
    twist = default_twist_rigidity(warp, weft) if twist is None else float(twist)
    if not rho >= 0.0:
        raise error(f"material.areal_mass must be >= 0, got {rho}")
    if not twist >= 0.0:
        raise error(f"material.twist_rigidity must be >= 0, got {twist}")
    return SheetParts(rho, warp, weft, twist)


def membrane_matrix(material, error: type[Exception] = ValueError):
    """Orthotropic plane-stress membrane stiffness (Voigt, N/m) of a material.

    Uses ``material.membrane_stiffness()`` if the material provides it, else the
    attributes ``E11, E22, nu12, G12`` (N/m; FabricMaterial), each missing one from
    :data:`constitutive.defaults.DEFAULT_MEMBRANE` (docs/theory.md §1).
    """
    if hasattr(material, "membrane_stiffness"):
        C = np.asarray(material.membrane_stiffness() if callable(material.membrane_stiffness)
                       else material.membrane_stiffness, dtype=float)
        if C.shape == (3, 3):
            return C

    def get(names, default):
        for n in names:
            value = getattr(material, n, None)
            if value is not None:
                return float(value)
        return float(default)

    E1 = get(("E11", "E1"), DEFAULT_MEMBRANE["E11"])
    E2 = get(("E22", "E2"), DEFAULT_MEMBRANE["E22"])
    nu12 = get(("nu12",), DEFAULT_MEMBRANE["nu12"])
    G12 = get(("G12",), DEFAULT_MEMBRANE["G12"])
    nu21 = nu12 * E2 / E1
    den = 1.0 - nu12 * nu21
    if den <= 0 or min(E1, E2, G12) <= 0:
        raise error("membrane stiffness must be positive definite "
                    f"(E1={E1}, E2={E2}, nu12={nu12}, G12={G12})")
    return np.array([[E1 / den, nu21 * E1 / den, 0.0],
                     [nu12 * E2 / den, E2 / den, 0.0],
                     [0.0, 0.0, G12]])
