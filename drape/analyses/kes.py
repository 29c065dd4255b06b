"""KES-FB pure bending of a strip: B and 2HB of the simulated moment–curvature loop.

The strip is bent uniformly (``[load.kes]``), so the mean curvature and moment over the cells
are the material's values; :func:`finish` compares the finite-element loop with the loop of the
constitutive driver (:func:`constitutive.kes.run_kes`) sampled at the same times.
"""
from __future__ import annotations

import numpy as np

from constitutive.kes import kes_profile, kes_values, run_kes
from constitutive.units import to_kes
from drape.analyses.base import plain

NAME = "kes"


def _mean(fields: dict, name: str) -> float:
    if name not in fields:
        raise KeyError(f"the model gives no field {name!r}")
    return float(np.mean(fields[name]))


def probe(ctx, fields: dict) -> dict:
    """Mean warp curvature and moment of the strip (history columns ``kappa``, ``moment``)."""
    return {"kappa": _mean(fields, "curvature_xx"), "moment": _mean(fields, "moment_xx")}


def finish(ctx) -> dict:
    """B and 2HB of the simulated loop (:func:`constitutive.kes.kes_values`), SI and KES units.

    Beside them: the same values from the constitutive driver on the warp law, and the largest
    moment difference between the two along the loop relative to the largest moment.
    """
    t = np.array([row["t"] for row in ctx.history])
    kappa = np.array([row["kappa"] for row in ctx.history])
    moment = np.array([row["moment"] for row in ctx.history])
    values = kes_values(kappa, moment)
    drive = ctx.case.load.kes
    profile = kes_profile(t=np.clip(t, 0.0, drive.duration()), **drive.profile_kwargs())
    loop = run_kes(ctx.material.warp, profile)
    driver = kes_values(loop.kappa, loop.moment)
    return {"B": values.B, "HB2": values.HB2,
            "B_kes_gf_cm2_per_cm": to_kes(values.B, "B"),
            "HB2_kes_gf_cm_per_cm": to_kes(values.HB2, "HB2"),
            "sides": plain(values),
            "driver_B": driver.B, "driver_HB2": driver.HB2,
            "max_moment_difference_rel": float(np.max(np.abs(moment - loop.moment))
                                               / np.max(np.abs(loop.moment)))}
