"""The displacement columns every run writes to ``history.csv``.

``uz_min``, ``uz_max`` over the vertices, and the displacement of one probe vertex: ``tip_*``
at the middle of a strip's free end, ``centre_*`` at a rectangle's centre.
"""
from __future__ import annotations

import numpy as np

__all__ = ["DisplacementProbe"]


class DisplacementProbe:
    """History columns of a displacement field ``(n_points, 3)``.

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> from skfem import MeshTri
    >>> probe = DisplacementProbe(NS(mesh=NS(kind="rectangle")), MeshTri().refined(1))
    >>> u = np.zeros((9, 3)); u[probe.vertex, 2] = -1.0
    >>> probe(u)
    {'uz_min': -1.0, 'uz_max': 0.0, 'centre_ux': 0.0, 'centre_uz': -1.0}
    """

    def __init__(self, case, mesh):
        kind = case.mesh.kind
        self.label = {"strip": "tip", "rectangle": "centre"}.get(kind)
        self.vertex = None
        if kind == "strip":
            target = np.array([mesh.p[0].max(), 0.5 * (mesh.p[1].min() + mesh.p[1].max())])
        elif kind == "rectangle":
            target = 0.5 * (mesh.p.min(axis=1) + mesh.p.max(axis=1))
        else:
            return
        self.vertex = int(np.argmin(np.linalg.norm(mesh.p.T - target, axis=1)))

    def __call__(self, displacement) -> dict:
        u = np.asarray(displacement)
        out = {"uz_min": float(u[:, 2].min()), "uz_max": float(u[:, 2].max())}
        if self.vertex is not None:
            i, label = self.vertex, self.label
            out.update({f"{label}_ux": float(u[i, 0]), f"{label}_uz": float(u[i, 2])})
        return out
