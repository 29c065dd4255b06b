"""Sign conventions shared by the bending laws and both structural models.

Curvature
    ``κ_αβ = CURVATURE_SIGN · w_,αβ`` in the small-deflection plate, and its large-rotation
    form ``κ_αβ = CURVATURE_SIGN · x_,αβ · n`` in the Kirchhoff–Love shell (the second
    fundamental form of the deformed mid-surface minus that of the flat reference). With the
    sign +1 a positive κ bends the fabric face-up (concave towards +z, the normal side); a
    cantilever sagging under gravity bends face-down (κ_xx < 0). The law's face-down
    coefficients (``k1_neg``, ``k3_neg``) act on κ < 0. One switch for plate and shell alike.

Twist
    The elastic energy per unit area is ``½ B1 κ11² + ½ B2 κ22² + D_t κ12²`` (κ12 the tensor
    component, ``w_,xy``; an isotropic Kirchhoff plate with ν = 0 has ``D_t = D``). Its
    tensor twisting moment is ``M12 = ∂W/∂(2 κ12) = D_t κ12`` (:func:`twisting_moment`), the
    ``M_xy = D (1 − ν) κ_xy`` of plate theory (Timoshenko & Woinowsky-Krieger, *Theory of
    Plates and Shells*, 1959, §21).

Standard gravity
    ``g = 9.80665 m/s²`` is :data:`constitutive.units.G0`, used for the self-weight and for the
    gram-force of the KES units.
"""
from __future__ import annotations

import numpy as np

__all__ = ["CURVATURE_SIGN", "twisting_moment"]

#: ``κ_αβ = CURVATURE_SIGN · w_,αβ``: positive κ bends the fabric face-up (concave towards +z).
CURVATURE_SIGN = 1.0


def twisting_moment(twist_rigidity, kappa_12):
    """Tensor twisting moment ``M12 = D_t κ12`` [N·m/m] of the twist curvature ``κ12 = w_,xy``.

    >>> float(twisting_moment(2e-6, 3.0))
    6e-06
    """
    return twist_rigidity * np.asarray(kappa_12)
