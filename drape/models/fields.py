"""Model output fields under one naming: point data, cell data, flat scalar columns.

A model's :meth:`~drape.models.protocol.StructuralModel.fields` returns arrays per point or per
cell; the writer, the history probes and the analyses all read them through these two
functions, so every model writes the same names.
"""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np

__all__ = ["split_fields", "flat_fields"]

_POINT_HINTS = ("displacement", "velocity", "acceleration")


def split_fields(fields: Mapping[str, Any], n_points: int, n_cells: int):
    """Sort model output arrays into VTU point data and cell data.

    A model may return ``{"point_data": {...}, "cell_data": {...}}`` explicitly; otherwise an
    array of length ``n_points`` is point data and one of length ``n_cells`` cell data
    (names like ``displacement`` win the tie when both counts are equal).

    Examples
    --------
    >>> import numpy as np
    >>> pd, cd = split_fields({"displacement": np.zeros((4, 3)), "m": np.ones(2)}, 4, 2)
    >>> sorted(pd), sorted(cd)
    (['displacement'], ['m'])
    """
    if "point_data" in fields or "cell_data" in fields:
        pd = {k: np.asarray(v) for k, v in fields.get("point_data", {}).items()}
        cd = {k: np.asarray(v) for k, v in fields.get("cell_data", {}).items()}
        return pd, cd
    point_data, cell_data = {}, {}
    for name, value in fields.items():
        arr = np.asarray(value)
        n = arr.shape[0] if arr.ndim else -1
        is_point = n == n_points and (n != n_cells or name.startswith(_POINT_HINTS))
        if is_point:
            point_data[name] = arr
        elif n == n_cells:
            cell_data[name] = arr
        else:
            raise ValueError(
                f"output field {name!r} has leading dimension {n}: expected "
                f"{n_points} (points) or {n_cells} (cells)"
            )
    return point_data, cell_data


_COMPONENTS = {3: ("xx", "yy", "xy"), 2: ("xx", "yy")}


def flat_fields(fields: Mapping[str, Any], mesh) -> dict:
    """Model fields as one flat ``name -> array`` dict of scalars and point vectors.

    The arrays are sorted by :func:`split_fields`; cell data given as ``(n_cells, 3)`` tensors
    (``curvature``, ``moment``) or ``(n_cells, 2)`` pairs (``friction_moment``) are split into
    ``_xx``, ``_yy`` (``_xy``) scalars, so that every model writes the same names.

    Examples
    --------
    >>> from skfem import MeshTri
    >>> f = flat_fields({"point_data": {"displacement": np.zeros((4, 3))},
    ...                  "cell_data": {"moment": np.ones((2, 3))}}, MeshTri())
    >>> sorted(f)
    ['displacement', 'moment_xx', 'moment_xy', 'moment_yy']
    """
    point_data, cell_data = split_fields(fields, mesh.p.shape[1], mesh.t.shape[1])
    flat = dict(point_data)
    for name, arr in cell_data.items():
        if arr.ndim == 2 and arr.shape[1] in _COMPONENTS:
            for i, suffix in enumerate(_COMPONENTS[arr.shape[1]]):
                flat[f"{name}_{suffix}"] = arr[:, i]
        else:
            flat[name] = arr
    return flat
