"""The residual of a fit (thesis 4.17) and the model moment along a measured loop.
"""
from __future__ import annotations

import numpy as np

from constitutive.datasets import MOMENT_KES
from constitutive.friction import friction_path

__all__ = ['residual_kes', 'model_moment', 'evaluate']


def residual_kes(model, data):
    """Thesis residual 4.17 in KES units: Σ (M_model − M_exp)², moments in gf·cm/cm.

    ``model`` and ``data`` are SI moments [N·m/m] at the same 1 ms samples.

    >>> residual_kes(np.array([MOMENT_KES]), np.array([0.0]))
    1.0
    """
    r = (np.asarray(model) - np.asarray(data)) / MOMENT_KES
    return float(np.dot(r, r))


def model_moment(law, loop):
    """Moment of ``law`` along the loop's profile, and its friction part (SI).

    Uses the exact state form of the friction (:func:`friction_path`), not the
    thesis's closed form 4.2, which is wrong after the first reversal.
    """
    elastic, _ = law.elastic(loop.kappa)
    mf = np.zeros_like(loop.kappa) if law.friction is None else friction_path(law.friction,
                                                                               loop.kappa)
    return law.m * loop.kappa_accel + law.d * loop.kappa_rate + elastic + mf, mf


def evaluate(law, loop):
    """Residual 4.17 (KES units) of a given law on a sampled loop."""
    return residual_kes(model_moment(law, loop)[0], loop.moment)


# ---------------------------------------------------------------------------
# The fit
# ---------------------------------------------------------------------------

# outer box in log coordinates: u = log10(eps_f / cm^-1) = log10 a2, w = log10(eta) = log10(a1/a2)
