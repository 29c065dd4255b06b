"""Cusick drape-test specimen: an annulus clamped on its inner circle (SI, metres).

The specimen (standard diameters 0.24, 0.30, 0.36 m) rests on a disc of
0.18 m; only the overhanging annulus is meshed.  The mesh is a structured polar
grid whose nodes lie exactly on the disc and hem circles (the boundary is the
inscribed polygon), so refinement by ``refine`` keeps all boundary nodes on the
circles (unlike ``MeshTri.refined``, which would put new nodes on chords).

Examples
--------
>>> mesh = cusick_annulus(n_radial=4, n_circumferential=32)
>>> sorted(mesh.boundaries)
['disc', 'hem']
>>> r = np.hypot(*mesh.p)
>>> round(float(r.min()), 12), round(float(r.max()), 12)
(0.09, 0.15)
"""
from __future__ import annotations

import math

import numpy as np
from skfem import MeshTri

from .quality import check_mesh
from .rectangle import positive, positive_int

__all__ = ["cusick_annulus", "twice_a_prime"]


def cusick_annulus(specimen_diameter: float = 0.30, disc_diameter: float = 0.18,
                   n_radial: int | None = None, n_circumferential: int | None = None,
                   target_size: float = 0.01, refine: int = 0,
                   centre=(0.0, 0.0), radial_grading: float = 1.0) -> MeshTri:
    """Structured triangle mesh of the overhanging annulus of a Cusick specimen.

    Parameters
    ----------
    specimen_diameter, disc_diameter
        Diameters in metres (specimen > disc > 0).
    n_radial
        Cells across the overhang; default ``ceil(overhang / target_size)``.
    n_circumferential
        Cells around the circle (even, >= 8); default: the number twice a prime
        nearest to mid-radius circumference / ``target_size`` (:func:`twice_a_prime`).
        The grid repeats every two sectors and k folds fit it exactly only when k divides
        the count: 72 sectors favour 2, 3, 4, 6, 8, 9 and 12 folds, 74 = 2 · 37 none from
        3 to 36.
    target_size
        Nominal element size in metres used for the defaults.
    refine
        Number of uniform refinements for convergence studies: both counts are
        multiplied by ``2**refine`` (nodes stay on the circles).
    centre
        Centre of the disc.
    radial_grading
        Width of the outermost ring over that of the innermost (>= 1; 1: uniform). The
        ring widths grow geometrically from the disc, where a limp fabric bends from
        horizontal to hanging within about one bending length (a boundary layer the
        mesh must resolve). Refinement keeps the ratio, so the family stays similar.

    Returns
    -------
    skfem.MeshTri
        With boundaries ``disc`` (inner circle, to be clamped) and ``hem``
        (outer circle, free).

    Examples
    --------
    >>> coarse = cusick_annulus(n_radial=3, n_circumferential=24)
    >>> fine = cusick_annulus(n_radial=3, n_circumferential=24, refine=1)
    >>> fine.t.shape[1] == 4 * coarse.t.shape[1]
    True
    >>> graded = cusick_annulus(n_radial=3, n_circumferential=24, radial_grading=4.0)
    >>> rings = np.unique(np.hypot(*graded.p).round(9))
    >>> np.round(np.diff(rings) * 100, 3).tolist()     # cm: 6 cm overhang, ratio 4 = 2**2
    [0.857, 1.714, 3.429]
    """
    D = positive("specimen_diameter", specimen_diameter)
    d = positive("disc_diameter", disc_diameter)
    if D <= d:
        raise ValueError(f"'specimen_diameter' ({D}) must exceed 'disc_diameter' ({d})")
    h = positive("target_size", target_size)
    refine = positive_int("refine", refine, minimum=0)
    grading = float(radial_grading)
    if not (math.isfinite(grading) and grading >= 1.0):
        raise ValueError(f"'radial_grading' = {radial_grading!r} must be a number >= 1 (1: uniform rings)")
    r_in, r_out = d / 2, D / 2
    if n_radial is None:
        n_radial = max(1, math.ceil((r_out - r_in) / h - 1e-9))
    if n_circumferential is None:
        n_circumferential = twice_a_prime(math.pi * (r_in + r_out) / h)
    nr = positive_int("n_radial", n_radial) * 2**refine
    nc = positive_int("n_circumferential", n_circumferential, minimum=8) * 2**refine
    if nc % 2:
        raise ValueError(f"'n_circumferential' must be even (symmetric diagonals), got {nc}")
    cx, cy = (float(v) for v in centre)
    q = grading ** (1.0 / (nr - 1)) if nr > 1 else 1.0
    widths = q ** np.arange(nr)
    radius = r_in + (r_out - r_in) * np.concatenate([[0.0], np.cumsum(widths) / widths.sum()])
    radius[0], radius[-1] = r_in, r_out
    theta = 2 * np.pi * np.arange(nc) / nc
    R, T = np.meshgrid(radius, theta, indexing="ij")          # (nr+1, nc), ring-major
    p = np.vstack([cx + (R * np.cos(T)).ravel(), cy + (R * np.sin(T)).ravel()])
    i, j = np.meshgrid(np.arange(nr), np.arange(nc), indexing="ij")
    i, j = i.ravel(), j.ravel()
    a = i * nc + j                      # (r_i, θ_j)
    b = i * nc + (j + 1) % nc           # (r_i, θ_j+1)
    c = b + nc                          # (r_i+1, θ_j+1)
    e = a + nc                          # (r_i+1, θ_j)
    rising = (i + j) % 2 == 0           # checkerboard diagonals
    t = np.hstack([np.where(rising, [a, b, c], [a, b, e]),
                   np.where(rising, [a, c, e], [b, c, e])])
    mesh = MeshTri(p, t)
    r_split = 0.5 * (r_in + r_out)      # boundary facet midpoints lie near r_in or r_out
    mesh = mesh.with_boundaries({
        "disc": lambda x: np.hypot(x[0] - cx, x[1] - cy) < r_split,
        "hem": lambda x: np.hypot(x[0] - cx, x[1] - cy) > r_split,
    })
    check_mesh(mesh, ("disc", "hem"))
    return mesh


def twice_a_prime(n: float) -> int:
    """The even number 2p, p a prime >= 5, nearest to ``n`` (the smaller one on a tie).

    A sector count of 2p is divisible by no fold count between 3 and p - 1, so the
    polar grid prefers none of them.

    >>> twice_a_prime(75.4), twice_a_prime(8), twice_a_prime(30)
    (74, 10, 26)
    """
    def is_prime(p):
        return p >= 2 and all(p % q for q in range(2, math.isqrt(p) + 1))

    primes = [p for p in range(5, max(7, int(n) // 2 + 3) * 2) if is_prime(p)]
    return 2 * min(primes, key=lambda p: (abs(2 * p - n), p))
