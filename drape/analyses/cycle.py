"""A gravity load cycle: probe displacements at every point of the load history table.

At a zero level after loading, what is left is the residual deformation: held by friction in a
quasi-static run (plus unrecovered viscous creep in a dynamic one).
"""
from __future__ import annotations

import numpy as np

NAME = "cycle"

_PROBES = ("tip_", "centre_", "uz_")


def finish(ctx) -> dict:
    """``levels``: the probes at each history point reached; ``residual_after_unloading``: those
    at zero levels after the first non-zero one."""
    gravity = ctx.case.load.gravity
    rows = ctx.history
    times = np.array([row["t"] for row in rows])
    points = []
    for t, level in gravity.history:
        if t > times[-1] + 1e-9 * max(1.0, abs(t)):
            break
        row = rows[int(np.argmin(np.abs(times - t)))]
        points.append({"t": row["t"], "gravity_factor": gravity.factor * level,
                       **{k: v for k, v in row.items() if k.startswith(_PROBES)}})
    loaded = False
    residual = []
    for point in points:
        if loaded and point["gravity_factor"] == 0:
            residual.append(point)
        loaded = loaded or point["gravity_factor"] != 0
    return {"levels": points, "residual_after_unloading": residual}
