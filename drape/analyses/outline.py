"""Harmonic amplitudes of a drape's outline: descriptors that do not depend on where the folds
sit round the disc.

The outline radius ``r(phi)`` of a Cusick shadow (:func:`drape.analyses.drape_coefficient.boundary_radius`) is a
periodic signal, ``r(phi) = a_0 + sum_k a_k cos(k phi + phase_k)``.  Turning the specimen
about the disc axis by an angle ``alpha`` only shifts every phase (by ``k alpha``), so the
amplitudes ``a_k`` compare two drapes whatever their orientation: ``a_0`` is the mean radius,
``a_1`` an offset of the outline from the centre, and the fold count ``n`` shows as a peak at
``k = n`` (``r = r0 + A cos(n phi)`` gives ``a_n = A``, and every node is ``2 A`` deep).

What is left once the fold pattern (``a_n`` and its overtones ``a_2n, a_3n, ...``) and the
offset ``a_1`` are taken out measures how unequal the folds are in depth and spacing: the
outline's irregularity (:func:`outline_irregularity`). A drape of ``n`` equal, evenly spaced
folds has none, whatever their shape.
"""
from __future__ import annotations

import numpy as np

__all__ = ["N_HARMONICS", "outline_harmonics", "outline_irregularity"]

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


def outline_irregularity(amplitudes, n_nodes: int) -> float:
    """Root-sum-square of the harmonic amplitudes outside an ``n_nodes``-fold pattern.

    The harmonics ``k >= 2`` that are not multiples of ``n_nodes``: a periodic pattern of
    ``n`` equal folds has amplitudes only at ``k = n, 2n, ...``, so what remains is the
    outline's departure from it (unequal depths, uneven spacing). ``a_0`` (the mean radius)
    and ``a_1`` (the outline's offset from the centre: placement, not shape) are left out.

    Parameters
    ----------
    amplitudes : array_like, shape (k_max + 1,)
        ``a_0 .. a_k_max`` as :func:`outline_harmonics` gives them.
    n_nodes : int
        The drape's node count; 0 (no folds) or 1 takes every ``k >= 2``.

    Returns
    -------
    float
        In the unit of ``amplitudes``.

    Examples
    --------
    Six equal folds with a three-lobed departure of 4 mm:

    >>> phi = np.linspace(0.0, 2.0 * np.pi, 720, endpoint=False)
    >>> r = 0.13 + 0.010 * np.cos(6 * phi) + 0.003 * np.cos(12 * phi) + 0.004 * np.cos(3 * phi)
    >>> round(outline_irregularity(outline_harmonics(r), 6), 12)
    0.004
    """
    a = np.asarray(amplitudes, dtype=float)
    k = np.arange(a.size)
    off = k >= 2
    if n_nodes >= 2:
        off &= k % int(n_nodes) != 0
    return float(np.sqrt(np.sum(a[off] ** 2)))
