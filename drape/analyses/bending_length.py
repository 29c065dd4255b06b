"""Peirce / ASTM D1388 cantilever bending-length summary of a deformed strip.

In the cantilever test a strip of overhang ``l`` bends under its own weight;
the chord from the clamp edge to the tip makes the angle ``θ`` with the
horizontal.  Peirce's formula turns ``(l, θ)`` into the bending length

    c = l (cos(θ/2) / (8 tan θ))^(1/3)

and the flexural rigidity per unit width ``G = W c³`` (``W`` the weight per
unit area, N/m²).  ASTM D1388 fixes ``θ = 41.5°`` and reads ``c = l/2`` there
(the exact elastica value for ``W l³/B = 8``; Peirce's empirical formula gives
``0.509 l``).

Examples
--------
>>> round(float(bending_length(0.04, np.deg2rad(41.5)) / 0.04), 3)
0.509
>>> round(flexural_rigidity(1.682, 0.0072) * 1e7, 2)     # N·m
6.28
"""

from __future__ import annotations

import numpy as np

from constitutive.kes import kes_values, run_kes

#: ASTM D1388 chord angle [rad] at which c = l/2.
ASTM_CHORD_ANGLE = np.deg2rad(41.5)


class PeirceInputError(ValueError):
    """Invalid input to the Peirce summary."""


def bending_length(overhang, chord_angle):
    """Peirce bending length ``c = l (cos(θ/2)/(8 tan θ))^(1/3)`` [m].

    Parameters
    ----------
    overhang : float
        Overhang length ``l`` [m].
    chord_angle : float
        Chord angle ``θ`` [rad], in (0, π/2).
    """
    theta = float(chord_angle)
    if not 0.0 < theta < 0.5 * np.pi:
        raise PeirceInputError(f"chord_angle must lie in (0, pi/2) rad, got {theta}")
    if overhang <= 0:
        raise PeirceInputError(f"overhang must be positive, got {overhang}")
    return overhang * (np.cos(0.5 * theta) / (8.0 * np.tan(theta))) ** (1.0 / 3.0)


def flexural_rigidity(weight_per_area, c):
    """Peirce flexural rigidity ``G = W c³`` [N·m] from ``W`` [N/m²] and ``c`` [m]."""
    return weight_per_area * c ** 3


def chord_angle(horizontal, drop):
    """Angle [rad] of the chord to the tip below the horizontal."""
    return float(np.arctan2(drop, horizontal))


def strip_geometry(mesh, displacement, clamped="clamped", free="free"):
    """Overhang, tip position and tip direction data of a deformed strip.

    Parameters
    ----------
    mesh : skfem.MeshTri
        Reference strip with boundaries ``clamped`` and ``free`` (opposite edges).
    displacement : ndarray, shape (n_points, 3)
        Vertex displacements.

    Returns
    -------
    dict with ``overhang`` [m], ``direction`` (unit in-plane vector clamp → tip),
    ``tip_horizontal`` and ``tip_drop`` [m] of the free edge's mean position
    relative to the clamp edge's mean reference position.
    """
    bnd = mesh.boundaries or {}
    for name in (clamped, free):
        if name not in bnd:
            raise PeirceInputError(f"mesh has no boundary '{name}' (has {sorted(bnd)})")
    vc = np.unique(mesh.facets[:, bnd[clamped]])
    vf = np.unique(mesh.facets[:, bnd[free]])
    xc = mesh.p[:, vc].mean(axis=1)
    xf = mesh.p[:, vf].mean(axis=1)
    d = xf - xc
    overhang = float(np.linalg.norm(d))
    d = d / overhang
    tip = np.append(mesh.p[:, vf], np.zeros((1, len(vf))), axis=0).T + displacement[vf]
    rel = tip.mean(axis=0) - np.append(xc, 0.0)
    return dict(overhang=overhang, direction=d, tip_horizontal=float(rel[:2] @ d),
                tip_drop=float(-rel[2]), free_vertices=vf)


def peirce_summary(mesh, displacement, weight_per_area, tip_slope=None, B_kes=None,
                   clamped="clamped", free="free"):
    """Summary of the cantilever test: tip drop and angles, Peirce c, G and G/B_KES.

    Parameters
    ----------
    mesh : skfem.MeshTri
    displacement : ndarray, shape (n_points, 3)
    weight_per_area : float
        ``W = ρ_A g`` [N/m²].
    tip_slope : ndarray, shape (3,), optional
        Tangent ``a = d(x + u)/dX`` along the strip at the tip (mean over the
        free edge); gives the tip angle.
    B_kes : float, optional
        The material's KES bending rigidity [N·m] for the ratio ``G / B_KES``.

    Returns
    -------
    dict of floats (SI, angles in degrees).

    Examples
    --------
    >>> import numpy as np
    >>> from skfem import MeshTri
    >>> m = MeshTri.init_tensor(np.linspace(0, 0.04, 5), np.linspace(0, 0.025, 2))
    >>> m = m.with_boundaries({"clamped": lambda x: x[0] < 1e-9, "free": lambda x: x[0] > 0.04 - 1e-9})
    >>> d = np.zeros((m.p.shape[1], 3))
    >>> d[:, 2] = -np.tan(np.deg2rad(41.5)) * m.p[0]; d[:, 0] = 0.0
    >>> s = peirce_summary(m, d, weight_per_area=1.0)
    >>> round(s["chord_angle_deg"], 6), round(s["bending_length_m"] / 0.04, 4)
    (41.5, 0.5093)
    """
    geo = strip_geometry(mesh, displacement, clamped, free)
    theta = chord_angle(geo["tip_horizontal"], geo["tip_drop"])
    out = dict(overhang_m=geo["overhang"], tip_drop_m=geo["tip_drop"],
               tip_horizontal_m=geo["tip_horizontal"], chord_angle_deg=float(np.rad2deg(theta)))
    if tip_slope is not None:
        t = np.asarray(tip_slope, dtype=float)
        horiz = float(t[:2] @ geo["direction"])
        out["tip_angle_deg"] = float(np.rad2deg(np.arctan2(-t[2], horiz)))
    if 0.0 < theta < 0.5 * np.pi:
        c = bending_length(geo["overhang"], theta)
        G = flexural_rigidity(weight_per_area, c)
        out.update(bending_length_m=float(c), flexural_rigidity_Nm=float(G))
        if B_kes is not None:
            out.update(B_kes_Nm=float(B_kes), G_over_B_kes=float(G / B_kes))
    return out


def shell_peirce_summary(model, u, B_kes=None, clamped="clamped", free="free"):
    """:func:`peirce_summary` of a :class:`drape.models.shell.KirchhoffLoveShell` state.

    The tip slope is read from the Argyris gradient dofs at the free-edge vertices.
    ``B_kes`` defaults to the material's measured KES B of the strip's direction
    (``material.kes["B_warp"]`` / ``["B_weft"]``), else to the B of the law's
    simulated KES-FB loop.
    """
    mesh = model.mesh
    disp = model.nodal_displacement(u)
    geo = strip_geometry(mesh, disp, clamped, free)
    vf = geo["free_vertices"]
    d = geo["direction"]
    grad = np.stack([u[3 * model.basis.nodal_dofs[1 + i][vf][:, None] + np.arange(3)]
                     for i in range(2)], axis=1)           # (nv, 2, 3): u_,x and u_,y
    slope = np.append(d, 0.0) + np.einsum("vak,a->k", grad, d) / len(vf)
    W = model.rho_A * model.g * model.load_scale * model.gravity(model.load_time)
    if B_kes is None:
        along_warp = abs(d[0]) >= abs(d[1])
        kes = getattr(model.material, "kes", None) or {}
        B_kes = kes.get("B_warp" if along_warp else "B_weft")
        if B_kes is None:
            B_kes = _kes_b(model.warp_law if along_warp else model.weft_law)
    return peirce_summary(mesh, disp, W, slope, B_kes, clamped, free)


def _kes_b(law):
    """KES B of a law: its simulated KES-FB loop's mean slope over 0.5–1.5 cm⁻¹ [N·m]."""
    loop = run_kes(law)
    B, _ = kes_values(loop.kappa, loop.moment)
    return float(B)
