"""A fabric sheet's defaults where its data give none: twist rigidity and membrane.

One source for both models and for :class:`constitutive.material.FabricMaterial`: the plate
and the shell read a material through :func:`drape.models.sheet_material.sheet_parts`, which
falls back on these, and a material file that leaves them out gets the same values.

>>> from constitutive.law import BendingLaw
>>> default_twist_rigidity(BendingLaw(k1=4e-6), BendingLaw(k1=1e-6))
2e-06
>>> DEFAULT_MEMBRANE["G12"]
50.0
"""
from __future__ import annotations

import math

from constitutive.tensile import DEFAULT_SECANT

__all__ = ["DEFAULT_MEMBRANE", "default_twist_rigidity"]

#: Membrane defaults (N/m): woven fabric, nearly inextensible along yarns, soft in shear.
DEFAULT_MEMBRANE = {"E11": DEFAULT_SECANT, "E22": DEFAULT_SECANT, "nu12": 0.0, "G12": 50.0}


def default_twist_rigidity(warp, weft) -> float:
    """Twist rigidity D_t = √(B_warp B_weft) [N·m] of the warp and weft laws' linear terms."""
    return math.sqrt(warp.k1 * weft.k1)
