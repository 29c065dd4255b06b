"""Reading a Peirce tester: a strip on a platform, pushed over its edge until the tip meets
the 41.5° line (ASTM D1388 option A; F. T. Peirce, J. Text. Inst. 21, T377, 1930).

The strip runs along x, its free end ahead. At each step the reading takes the strip's centre
line (the mean of each column of vertices across the width), the point of it above the
platform's edge, the overhang (the strip's length beyond that point, in the reference) and
the chord angle from that point down to the tip. The test ends where the chord angle is
41.5°; ASTM D1388 then reads the bending length as half the overhang.

Examples
--------
>>> import numpy as np
>>> angle = np.array([30.0, 40.0, 43.0])
>>> overhang = np.array([0.012, 0.015, 0.016])
>>> round(crossing(angle, overhang)["overhang"], 6)          # 41.5° a half of the way
0.0155
"""
from __future__ import annotations

import numpy as np

from drape.analyses.bending_length import ASTM_CHORD_ANGLE

__all__ = ["centre_line", "reading", "crossing", "ASTM_CHORD_ANGLE_DEG"]

ASTM_CHORD_ANGLE_DEG = float(np.rad2deg(ASTM_CHORD_ANGLE))


def centre_line(mesh, displacement):
    """Reference length coordinate of every column of vertices and the column's mean deformed
    position, sorted along the strip.

    Parameters
    ----------
    mesh : skfem.MeshTri
        The flat strip along x.
    displacement : ndarray, shape (n_points, 3)

    Returns
    -------
    X : ndarray, shape (n_columns,)
    position : ndarray, shape (n_columns, 3)
    """
    x = mesh.p[0]
    span = max(float(np.ptp(x)), 1e-300)
    X, column = np.unique(np.round(x / span, 9), return_inverse=True)
    points = np.column_stack([mesh.p.T, np.zeros(mesh.p.shape[1])]) + displacement
    count = np.bincount(column, minlength=len(X))
    position = np.stack([np.bincount(column, points[:, k], len(X)) for k in range(3)], 1)
    return X * span, position / count[:, None]


def reading(mesh, displacement, edge_x: float) -> dict:
    """Overhang and chord angle of a strip lying on a platform whose edge is at ``x = edge_x``.

    Returns
    -------
    dict
        ``overhang`` [m]: reference length from the centre line's point above the edge to the
        tip (0 while the tip is behind the edge); ``chord_angle`` [deg]: angle below the
        horizontal of the chord from that point to the tip (NaN while nothing overhangs).
    """
    X, position = centre_line(mesh, displacement)
    x = position[:, 0]
    ahead = np.flatnonzero(x >= edge_x)
    if ahead.size == 0 or ahead[0] == 0:         # nothing overhangs, or nothing is on the platform
        return {"overhang": 0.0, "chord_angle": float("nan")}
    k = ahead[0]                                   # the first column past the edge
    share = (edge_x - x[k - 1]) / (x[k] - x[k - 1])
    X_edge = X[k - 1] + share * (X[k] - X[k - 1])
    z_edge = position[k - 1, 2] + share * (position[k, 2] - position[k - 1, 2])
    tip = position[-1]
    angle = np.rad2deg(np.arctan2(z_edge - tip[2], tip[0] - edge_x))
    return {"overhang": float(X[-1] - X_edge), "chord_angle": float(angle)}


def crossing(chord_angle, overhang, angle_deg: float = ASTM_CHORD_ANGLE_DEG):
    """Where the chord angle first reaches ``angle_deg``, linearly between the two steps around.

    Parameters
    ----------
    chord_angle, overhang : array_like
        The reading at every step, in time order.

    Returns
    -------
    dict or None
        ``index`` (the first step at or past the angle), ``share`` (where between it and the
        step before), ``overhang`` there; None if the angle is never reached.
    """
    angle = np.asarray(chord_angle, dtype=float)
    overhang = np.asarray(overhang, dtype=float)
    reached = np.flatnonzero(np.nan_to_num(angle, nan=-np.inf) >= angle_deg)
    if reached.size == 0:
        return None
    k = int(reached[0])
    if k == 0 or not np.isfinite(angle[k - 1]):
        return {"index": k, "share": 1.0, "overhang": float(overhang[k])}
    share = (angle_deg - angle[k - 1]) / (angle[k] - angle[k - 1])
    return {"index": k, "share": float(share),
            "overhang": float(overhang[k - 1] + share * (overhang[k] - overhang[k - 1]))}
