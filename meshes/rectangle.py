"""Structured triangle meshes of rectangles and fabric strips (SI, metres).

Examples
--------
>>> mesh = strip(0.20, 0.025, 16, 2)
>>> sorted(mesh.boundaries)
['bottom', 'clamped', 'free_end', 'left', 'right', 'top']
>>> float(mesh.p[0, mesh.facets[:, mesh.boundaries["free_end"]]].min())
0.2
"""
from __future__ import annotations

import numpy as np
from skfem import MeshTri

from .quality import check_mesh

__all__ = ["rectangle", "strip", "graded_nodes", "positive", "positive_int"]

_DIAGONALS = ("alternate", "right", "left")


def positive(name: str, value) -> float:
    """``value`` as a float, or ValueError naming ``name`` if not finite and > 0."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"'{name}' must be a positive number, got {value!r}") from None
    if not np.isfinite(v) or v <= 0:
        raise ValueError(f"'{name}' must be a positive number, got {value!r}")
    return v


def positive_int(name: str, value, minimum: int = 1) -> int:
    """``value`` as an int, or ValueError naming ``name`` if not an integer >= minimum."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"'{name}' must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _grid_triangles(nx: int, ny: int, diagonals: str) -> np.ndarray:
    """Triangles (3, 2 nx ny) of an (nx+1) x (ny+1) node grid numbered x-fastest."""
    i, j = np.meshgrid(np.arange(nx), np.arange(ny), indexing="xy")
    i, j = i.ravel(), j.ravel()
    a = i + j * (nx + 1)
    b, c, d = a + 1, a + nx + 2, a + nx + 1
    if diagonals == "right":          # diagonal a-c everywhere
        rising = np.ones(a.shape, bool)
    elif diagonals == "left":         # diagonal b-d everywhere
        rising = np.zeros(a.shape, bool)
    else:                             # checkerboard: mirror-symmetric pattern
        rising = (i + j) % 2 == 0
    t1 = np.where(rising, [a, b, c], [a, b, d])
    t2 = np.where(rising, [a, c, d], [b, c, d])
    return np.hstack([t1, t2])


def rectangle(lx: float, ly: float, nx: int, ny: int, origin=(0.0, 0.0),
              diagonals: str = "alternate", min_angle: float = 5.0, x_nodes=None) -> MeshTri:
    """Structured triangulation of ``[x0, x0 + lx] × [y0, y0 + ly]``.

    Parameters
    ----------
    lx, ly
        Side lengths in metres.
    nx, ny
        Number of cells along x and y (each cell is split into two triangles).
    origin
        Lower-left corner ``(x0, y0)``.
    diagonals
        ``"alternate"`` (checkerboard, mirror-symmetric about the centre lines
        when nx, ny are even), ``"right"`` or ``"left"``.
    min_angle
        Smallest admissible triangle angle in degrees (checked).
    x_nodes
        Node abscissae from ``0`` to ``lx`` (increasing; e.g. :func:`graded_nodes`), instead of
        ``nx`` equal cells; ``nx`` is then ``len(x_nodes) - 1``.

    Returns
    -------
    skfem.MeshTri
        With boundaries ``left`` (x = x0), ``right``, ``bottom`` (y = y0), ``top``.

    Examples
    --------
    >>> m = rectangle(2.0, 1.0, 4, 2)
    >>> m.t.shape[1], [len(m.boundaries[k]) for k in ("left", "right", "bottom", "top")]
    (16, [2, 2, 4, 4])
    """
    lx, ly = positive("lx", lx), positive("ly", ly)
    nx, ny = positive_int("nx", nx), positive_int("ny", ny)
    if diagonals not in _DIAGONALS:
        raise ValueError(f"'diagonals' must be one of {_DIAGONALS}, got {diagonals!r}")
    x0, y0 = (float(v) for v in origin)
    xs = np.linspace(0.0, lx, nx + 1) if x_nodes is None else _checked_nodes(x_nodes, lx)
    nx = xs.size - 1
    x, y = np.meshgrid(x0 + xs,
                       y0 + np.linspace(0.0, ly, ny + 1), indexing="xy")
    # pin the far edges exactly (linspace already does; keep it explicit)
    x[:, -1], y[-1, :] = x0 + lx, y0 + ly
    mesh = MeshTri(np.vstack([x.ravel(), y.ravel()]), _grid_triangles(nx, ny, diagonals))
    tol = 1e-9 * max(lx, ly)
    mesh = mesh.with_boundaries({
        "left": lambda p: np.abs(p[0] - x0) < tol,
        "right": lambda p: np.abs(p[0] - (x0 + lx)) < tol,
        "bottom": lambda p: np.abs(p[1] - y0) < tol,
        "top": lambda p: np.abs(p[1] - (y0 + ly)) < tol,
    })
    check_mesh(mesh, ("left", "right", "bottom", "top"), min_angle=min_angle)
    return mesh


def _checked_nodes(x_nodes, lx: float) -> np.ndarray:
    xs = np.asarray(x_nodes, dtype=float)
    if xs.ndim != 1 or xs.size < 2 or not np.all(np.isfinite(xs)) or np.any(np.diff(xs) <= 0):
        raise ValueError("'x_nodes' must be increasing finite abscissae, at least two")
    if abs(xs[0]) > 1e-12 * lx or abs(xs[-1] - lx) > 1e-12 * lx:
        raise ValueError(f"'x_nodes' must run from 0 to lx = {lx!r}, got {xs[0]!r} to {xs[-1]!r}")
    return xs


def graded_nodes(length: float, n: int, start: float, end: float, n_zone: int) -> np.ndarray:
    """Node abscissae on ``[0, length]``: ``n_zone`` equal cells on ``[start, end]``, cells of
    about ``length / n`` outside it.

    For a strip that bends sharply where it passes an edge (a Peirce tester's platform): the
    zone that passes the edge gets fine cells, the rest keeps the mesh's own.

    Examples
    --------
    >>> x = graded_nodes(0.022, 44, 0.0035, 0.0095, 60)
    >>> len(x) - 1, round(float(np.diff(x).min()), 6), round(float(np.diff(x).max()), 6)
    (92, 0.0001, 0.0005)
    """
    length = positive("length", length)
    n, n_zone = positive_int("n", n), positive_int("n_zone", n_zone)
    if not 0.0 <= start < end <= length:
        raise ValueError(f"the fine zone [{start!r}, {end!r}] must lie in [0, {length!r}] "
                         "with start < end")
    h = length / n
    parts = [np.linspace(start, end, n_zone + 1)]
    if start > 0.0:
        parts.insert(0, np.linspace(0.0, start, max(1, round(start / h)) + 1)[:-1])
    if end < length:
        parts.append(np.linspace(end, length, max(1, round((length - end) / h)) + 1)[1:])
    return np.concatenate(parts)


def strip(length: float, width: float, n_length: int, n_width: int = 1,
          origin=(0.0, 0.0), diagonals: str = "alternate", min_angle: float = 5.0,
          x_nodes=None) -> MeshTri:
    """Fabric strip along x, clamped at ``x = x0`` (cantilever, KES-FB strip).

    Same as :func:`rectangle` (``n_length`` × ``n_width`` cells; keep the cells
    near-square: a 2 × 0.02 m strip with 1 cell across needs
    ``min_angle`` below atan(width/n_width ÷ cell length)) plus the boundaries ``clamped`` (the ``x = x0``
    end, same facets as ``left``) and ``free_end`` (``x = x0 + length``). ``x_nodes`` as in
    :func:`rectangle`.

    Examples
    --------
    >>> m = strip(0.1, 0.02, 10, 2)
    >>> bool(np.array_equal(m.boundaries["clamped"], m.boundaries["left"]))
    True
    """
    mesh = rectangle(length, width, n_length, n_width, origin, diagonals, min_angle, x_nodes)
    return mesh.with_boundaries({"clamped": mesh.boundaries["left"],
                                 "free_end": mesh.boundaries["right"]})
