"""Harmonic amplitudes of a drape's outline: descriptors that do not depend on where the folds
sit round the disc.

The outline radius ``r(phi)`` of a Cusick shadow (:func:`drape.analyses.drape_coefficient.boundary_radius`) is a
periodic signal, ``r(phi) = a_0 + sum_k a_k cos(k phi + phase_k)``.  Turning the specimen
about the disc axis by an angle ``alpha`` only shifts every phase (by ``k alpha``), so the
amplitudes ``a_k`` compare two drapes whatever their orientation: ``a_0`` is the mean radius,
``a_1`` an offset of the outline from the centre, and the fold count ``n`` shows as a peak at
``k = n`` (``r = r0 + A cos(n phi)`` gives ``a_n = A``, and every node is ``2 A`` deep).
"""
from __future__ import annotations

import numpy as np

__all__ = ["N_HARMONICS", "outline_harmonics"]

#: Highest harmonic reported: the modes node detection sees (``find_nodes``'s ``max_mode``).
N_HARMONICS = 20


def outline_harmonics(radius, k_max: int = N_HARMONICS) -> np.ndarray:
    """Amplitudes ``a_0 .. a_k_max`` of the Fourier series of a periodic outline radius.

    Parameters
    ----------
    radius : array_like, shape (M,)
        Outline radius at ``M`` equally spaced angles over one full turn.
    k_max : int
        Highest harmonic; must be below ``M / 2`` (the samples resolve no more).

    Returns
    -------
    ndarray, shape (k_max + 1,)
        ``a_0`` the mean radius, ``a_k = 2 |c_k|`` for ``k >= 1`` with ``c_k`` the
        discrete Fourier coefficient (same unit as ``radius``).

    Examples
    --------
    >>> phi = np.linspace(0.0, 2.0 * np.pi, 720, endpoint=False)
    >>> a = outline_harmonics(0.12 + 0.02 * np.cos(6 * phi + 1.0), k_max=8)
    >>> np.round(a, 12).tolist()
    [0.12, 0.0, 0.0, 0.0, 0.0, 0.0, 0.02, 0.0, 0.0]
    """
    r = np.asarray(radius, dtype=float)
    if r.ndim != 1 or not 0 <= k_max < r.size / 2:
        raise ValueError(f"outline_harmonics: need a 1-D outline of more than {2 * k_max} samples,"
                         f" got shape {r.shape}")
    c = np.fft.rfft(r)[: k_max + 1] / r.size
    amplitude = 2.0 * np.abs(c)
    amplitude[0] = abs(c[0].real)
    return amplitude
