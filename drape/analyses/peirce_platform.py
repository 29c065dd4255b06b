"""The Peirce tester as it is worked: a strip on a platform pushed over its edge (ASTM D1388).

The case has a ``strip`` along +x, its free end ahead, and a contact body named ``platform``
whose front face (its largest x, moved along its path) is the edge. The strip and the
platform move relative to each other (the platform drawn back under a strip held at its rear
end, or the strip pushed); every step records the overhang beyond the edge and the chord
angle to the tip (:mod:`drape.analyses.platform_reading`). The test reads the overhang where
the chord angle first reaches 41.5° and gives the bending length as half of it (and by
Peirce's formula at 41.5°, 0.509 of it, as the clamped cantilever's analysis reports), the
flexural rigidity ``G = W c³`` and ``G / B_KES``, as :mod:`drape.analyses.peirce` does for a
clamped cantilever.
"""
from __future__ import annotations

import numpy as np

from constitutive.units import G0
from drape.analyses.base import AnalysisInputError
from drape.analyses.bending_length import ASTM_CHORD_ANGLE, bending_length
from drape.analyses.platform_reading import ASTM_CHORD_ANGLE_DEG, crossing, reading

NAME = "peirce_platform"

#: The contact body whose front face is the tester's edge.
PLATFORM = "platform"


def _platform(ctx):
    contact = getattr(ctx.model, "contact", None)
    bodies = [] if contact is None else list(contact.scene.bodies)
    for body in bodies:
        if body.name == PLATFORM:
            return body
    raise AnalysisInputError(f"case.analysis = '{NAME}' needs a [[contact.body]] named "
                             f"'{PLATFORM}' (has: {', '.join(b.name for b in bodies) or 'none'})")


def edge_x(ctx, t: float) -> float:
    """x of the platform's edge (its front face) at time ``t`` [m]."""
    body = _platform(ctx)
    front = float(np.asarray(body.surface.vertices)[:, 0].max())
    return front + float(body.offset(t)[0])


def probe(ctx, fields: dict) -> dict:
    """History columns ``overhang_m`` and ``chord_angle_deg`` of the step just converged (the
    model's ``load_time`` is its time)."""
    if ctx.case.mesh.kind != "strip":
        raise AnalysisInputError(f"case.analysis = '{NAME}' needs mesh.kind = 'strip'")
    r = reading(ctx.mesh, np.asarray(fields["displacement"]), edge_x(ctx, ctx.model.load_time))
    return {"overhang_m": r["overhang"], "chord_angle_deg": r["chord_angle"]}


def finish(ctx) -> dict:
    """The overhang at 41.5° and the bending length, rigidity and ``G / B_KES`` from it; when the
    tip never reached the line, ``reached = False`` and the largest chord angle.

    Only the steps from the first keyframe of the platform's path on count (all steps when it
    stands still): the strip is let down onto the platform first, and the line is read as it is
    moved over the edge."""
    # the test is read while the strip moves over the edge: from the start of the platform's
    # path, after the strip has come to rest under its weight (a transient may overshoot)
    path = getattr(_platform(ctx), "path", None)
    start = float(path.times[0]) if path is not None else 0.0
    rows = [r for r in ctx.history if "chord_angle_deg" in r and r["t"] >= start]
    angle = np.array([r["chord_angle_deg"] for r in rows], dtype=float)
    overhang = np.array([r["overhang_m"] for r in rows], dtype=float)
    out = {"max_chord_angle_deg": float(np.nanmax(angle)) if np.isfinite(angle).any() else None,
           "line_deg": ASTM_CHORD_ANGLE_DEG}
    hit = crossing(angle, overhang)
    if hit is None:
        return {"reached": False, **out}
    t = np.array([r["t"] for r in rows], dtype=float)
    k, share = hit["index"], hit["share"]
    c = 0.5 * hit["overhang"]
    W = float(ctx.material.areal_mass) * G0
    G = W * c ** 3
    kes = getattr(ctx.material, "kes", None) or {}
    B_kes = kes.get("B_warp")
    if B_kes is None:          # no measured sheet: the warp law's simulated KES-FB loop
        B_kes = ctx.material.simulated_kes()["warp"].B
    return {"reached": True, **out,
            "time_s": float(t[k] if k == 0 else t[k - 1] + share * (t[k] - t[k - 1])),
            "overhang_m": hit["overhang"], "bending_length_m": c,
            "bending_length_peirce_m": float(bending_length(hit["overhang"], ASTM_CHORD_ANGLE)),
            "flexural_rigidity_Nm": G,
            "B_kes_Nm": float(B_kes), "G_over_B_kes": float(G / B_kes)}
