"""Cusick drape test: drape coefficient, nodes (folds) and the drape meter's top view.

The drape meter (BS 5058, ISO 9073-9) shines light from above on a circular
specimen of radius ``R`` held between two discs of radius ``r_d`` and measures the
area of its shadow.  The drape coefficient is the fraction of the hanging annulus
that the shadow still covers,

.. math:: DC = (A_{shadow} - A_{disc}) / (A_{specimen} - A_{disc}),

with the nominal areas ``A_specimen = pi R**2`` and ``A_disc = pi r_d**2``.  Here the
shadow is the union (:func:`shapely.unary_union`) of the deformed triangles
projected on the x-y plane, together with the disc itself; overlapping folds
therefore count once.

Nodes are the lobes of the shadow's outline.  The outline is read as the
boundary radius ``r(phi)`` (the farthest shadow point along each ray from the
centre), and nodes are the peaks of this periodic signal whose prominence
exceeds both a fraction of its peak-to-peak amplitude and an absolute floor (a
fraction of the overhang ``R - r_d``), so that a nearly flat outline with
numerical ripples counts zero nodes.  The depth of a node is its peak radius
minus the mean of the two troughs beside it (for ``r = r0 + A cos(n phi)`` every
depth is ``2 A``).  The outline's harmonic amplitudes (:mod:`drape.analyses.outline`) describe it
whatever the drape's orientation on the disc, and :mod:`drape.analyses.scan_measure` reads a scanned drape
through these same functions.

Simulating the test (``cases/cusick_*.toml``, run by :mod:`drape.run.runner` with
``[case] analysis = "cusick"``): the large-rotation Kirchhoff-Love shell on
:func:`meshes.cusick_annulus`, clamped on the ``disc`` edge, warp along x and weft
along y, gravity ramped on smoothly, a seeded out-of-plane perturbation
(:mod:`drape.models.perturbation`) so that the unstable axisymmetric state can buckle
into folds, Rayleigh mass damping plus the law's own viscosity and friction; the
run stops when the static out-of-balance force stays below a fraction of the weight
for a few steps (:mod:`drape.run.settling`), and :func:`cusick_post` analyses the settled shape.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import shapely
from scipy.signal import find_peaks

from drape.analyses.outline import outline_harmonics, outline_irregularity

__all__ = ["CusickError", "CusickResult", "shadow_polygon", "boundary_radius", "find_nodes",
           "drape_coefficient", "skirt_tension", "drape_analysis", "plot_top_view", "cusick_post"]


class CusickError(ValueError):
    """Invalid input to the Cusick drape analysis."""


def _check_radii(specimen_radius: float, disc_radius: float) -> None:
    if not (np.isfinite(disc_radius) and disc_radius > 0.0):
        raise CusickError(f"disc_radius = {disc_radius!r}: must be a positive length in metres")
    if not (np.isfinite(specimen_radius) and specimen_radius > disc_radius):
        raise CusickError(
            f"specimen_radius = {specimen_radius!r}: must exceed disc_radius = {disc_radius!r}"
        )


def shadow_polygon(points, triangles, disc_radius: float | None = None,
                   centre=(0.0, 0.0), disc_segments: int = 512):
    """Shadow of a deformed triangle mesh seen from above (+z), with the disc.

    Parameters
    ----------
    points : array_like, shape (N, 2) or (N, 3)
        Deformed node coordinates; only x and y are used.
    triangles : array_like of int, shape (T, 3)
        Connectivity.
    disc_radius : float, optional
        Radius of the supporting disc added to the shadow (the drape meter sees it).
    centre : tuple of float
        Disc centre in the x-y plane.
    disc_segments : int
        Number of segments of the disc polygon.

    Returns
    -------
    shapely.Polygon or shapely.MultiPolygon

    Examples
    --------
    Two triangles folded onto each other shadow a single triangle:

    >>> pts = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [0.0, 1.0]])
    >>> round(shadow_polygon(pts, [[0, 1, 2], [0, 1, 3]]).area, 12)
    0.5
    """
    xy = np.asarray(points, dtype=float)
    tri = np.asarray(triangles)
    if xy.ndim != 2 or xy.shape[1] not in (2, 3):
        raise CusickError(f"points has shape {xy.shape}: must be (N, 2) or (N, 3)")
    if tri.ndim != 2 or tri.shape[1] != 3:
        raise CusickError(f"triangles has shape {tri.shape}: must be (T, 3)")
    if not np.all(np.isfinite(xy)):
        raise CusickError("points: contains non-finite coordinates (diverged solution?)")
    # A triangle soup sampled element by element (KirchhoffLoveShell.deformed_surface)
    # repeats each shared point to round-off only; GEOS's overlay of such near-coincident
    # edges can drop slivers (a 7 mm notch on a flat hem). Snapping to 1e-9 of the size
    # makes shared points coincide exactly, as they do in a mesh.
    scale = np.ptp(xy[:, :2], axis=0).max() if len(xy) else 1.0
    grid = 1e-9 * scale if scale > 0 else 1.0
    c = np.round(xy[tri][:, :, :2] / grid) * grid
    # edge-on triangles (zero projected area) add nothing but can upset GEOS
    area2 = np.abs((c[:, 1, 0] - c[:, 0, 0]) * (c[:, 2, 1] - c[:, 0, 1])
                   - (c[:, 2, 0] - c[:, 0, 0]) * (c[:, 1, 1] - c[:, 0, 1]))
    c = c[area2 > 1e-14 * scale**2]
    polys = list(shapely.polygons(np.concatenate([c, c[:, :1]], axis=1)))
    if disc_radius is not None:
        # circumscribed polygon: it covers the true circle, hence the mesh's inscribed hole
        # (an inscribed disc polygon would leave sliver holes at the hole's corners)
        q = max(disc_segments // 4, 4)
        disc = shapely.Point(*centre).buffer(disc_radius / np.cos(np.pi / (4 * q)), quad_segs=q)
        polys.append(disc)
    return _drop_slivers(shapely.unary_union(polys))


def _drop_slivers(shadow, rel_area: float = 1e-7):
    """Fill interior rings below ``rel_area`` of the shadow: round-off slits along shared
    edges of the union, not holes in the fabric."""
    tol = rel_area * shadow.area
    parts = []
    for g in getattr(shadow, "geoms", [shadow]):
        if g.geom_type != "Polygon":
            continue
        holes = [h for h in g.interiors if shapely.Polygon(h).area > tol]
        parts.append(shapely.Polygon(g.exterior, holes))
    return parts[0] if len(parts) == 1 else shapely.MultiPolygon(parts)


def boundary_radius(shadow, centre=(0.0, 0.0), n_samples: int = 720, r_max: float | None = None):
    """Outline radius ``r(phi)`` of the shadow: the farthest shadow point along each ray.

    Parameters
    ----------
    shadow : shapely geometry
    centre : tuple of float
    n_samples : int
        Number of equally spaced ray angles in [0, 2 pi).
    r_max : float, optional
        Ray length; defaults to twice the farthest shadow vertex.

    Returns
    -------
    angles, radius : ndarray, shape (n_samples,)

    Examples
    --------
    >>> sq = shapely.box(-1.0, -1.0, 1.0, 1.0)
    >>> phi, r = boundary_radius(sq, n_samples=8)
    >>> np.round(r, 6).tolist()
    [1.0, 1.414214, 1.0, 1.414214, 1.0, 1.414214, 1.0, 1.414214]
    """
    cx, cy = centre
    if r_max is None:
        xy = shapely.get_coordinates(shadow)
        r_max = 2.0 * np.max(np.hypot(xy[:, 0] - cx, xy[:, 1] - cy))
    angles = np.arange(n_samples) * (2.0 * np.pi / n_samples)
    ends = np.stack([cx + r_max * np.cos(angles), cy + r_max * np.sin(angles)], axis=1)
    starts = np.broadcast_to([cx, cy], ends.shape)
    rays = shapely.linestrings(np.stack([starts, ends], axis=1))
    hits = shapely.intersection(rays, shadow)
    xy, idx = shapely.get_coordinates(hits, return_index=True)
    radius = np.zeros(n_samples)
    np.maximum.at(radius, idx, np.hypot(xy[:, 0] - cx, xy[:, 1] - cy))
    return angles, radius


def find_nodes(radius, rel_prominence: float = 0.15, min_prominence: float = 0.0,
               max_mode: int | None = 20):
    """Nodes (folds) of a periodic outline radius ``r(phi)`` and their depths.

    The outline is first low-passed to Fourier modes ``<= max_mode`` (real drapes show
    2-10 nodes; the corners of the polygonal hem are a mesh-scale ripple at mode
    ``n_circumferential`` and must not count).  A peak of the filtered signal counts as
    a node when its prominence is at least
    ``max(rel_prominence * (max(r) - min(r)), min_prominence)``; the signal is treated as
    periodic (tiled three times; peaks kept from the middle copy).  Depths are measured
    on the unfiltered outline: the highest radius between the node's two troughs minus
    the mean of those troughs (the lowest radii between neighbouring nodes).

    Parameters
    ----------
    radius : array_like, shape (M,)
        Outline radius at equally spaced angles over one full turn.
    rel_prominence : float
        Fraction of the peak-to-peak amplitude a node must stand out by.
    min_prominence : float
        Absolute floor (same unit as ``radius``).
    max_mode : int or None
        Highest Fourier mode kept for detection (None: no filtering).

    Returns
    -------
    peaks : ndarray of int
        Sample indices of the node crests, ascending.
    depths : ndarray
        Crest radius minus the mean of the troughs on either side.

    Examples
    --------
    >>> phi = np.linspace(0.0, 2.0 * np.pi, 360, endpoint=False)
    >>> peaks, depths = find_nodes(0.12 + 0.02 * np.cos(6 * phi))
    >>> len(peaks), np.round(depths, 6).tolist()[:2]
    (6, [0.04, 0.04])
    """
    r = np.asarray(radius, dtype=float)
    m = r.size
    if r.ndim != 1 or m < 8:
        raise CusickError(f"radius: need a 1-D periodic signal of >= 8 samples, got shape {r.shape}")
    if not 0.0 <= rel_prominence < 1.0:
        raise CusickError(f"rel_prominence = {rel_prominence!r}: must lie in [0, 1)")
    if max_mode is not None and max_mode < 1:
        raise CusickError(f"max_mode = {max_mode!r}: must be >= 1 (or None)")
    rf = r
    if max_mode is not None and max_mode < m // 2:
        spec = np.fft.rfft(r)
        spec[max_mode + 1:] = 0.0
        rf = np.fft.irfft(spec, m)
    threshold = max(rel_prominence * np.ptp(rf), min_prominence)
    if threshold <= 0.0:
        threshold = np.finfo(float).tiny  # a constant outline has no nodes
    peaks, _ = find_peaks(np.tile(rf, 3), prominence=threshold)
    peaks = np.sort(peaks[(peaks >= m) & (peaks < 2 * m)] - m)
    if peaks.size == 0:
        return peaks, np.zeros(0)
    # trough after each crest: lowest raw radius on the arc to the next crest (periodic)
    span = (np.roll(peaks, -1) - peaks) % m
    span[span == 0] = m  # a single node: the trough lies on the rest of the turn
    trough_at = np.array([(p + np.argmin(np.take(r, np.arange(p, p + s + 1), mode="wrap"))) % m
                          for p, s in zip(peaks, span)])
    troughs = r[trough_at]
    # crest: highest raw radius between the trough before and the trough after
    before = np.roll(trough_at, 1)
    width = (trough_at - before) % m
    width[width == 0] = m
    crests = np.array([np.max(np.take(r, np.arange(b, b + w + 1), mode="wrap"))
                       for b, w in zip(before, width)])
    depths = crests - 0.5 * (troughs + np.roll(troughs, 1))
    return peaks, depths


def drape_coefficient(shadow_area: float, specimen_radius: float, disc_radius: float) -> float:
    """``DC = (A_shadow - A_disc) / (A_specimen - A_disc)`` with nominal circle areas.

    Examples
    --------
    >>> drape_coefficient(np.pi * 0.15**2, 0.15, 0.09)
    1.0
    >>> drape_coefficient(np.pi * 0.09**2, 0.15, 0.09)
    0.0
    """
    _check_radii(specimen_radius, disc_radius)
    a_spec, a_disc = np.pi * specimen_radius**2, np.pi * disc_radius**2
    return float((shadow_area - a_disc) / (a_spec - a_disc))


def skirt_tension(weight: float, specimen_radius: float, disc_radius: float) -> float:
    """Mean meridional tension [N/m] of a Cusick specimen's hanging skirt, over its area.

    Hanging from the disc's edge, the material at radius ``r`` carries the weight of the
    annulus outside it, ``T(r) = w (R² − r²) / (2 r)`` per unit of its reference width (the
    hem carries none, the disc's edge the whole overhang). Its mean over the annulus
    ``r_d < r < R`` is ``w (2R + r_d)(R − r_d) / (3 (R + r_d))``: the operating point on the
    fabric's tensile curve at which the shell's linear membrane is taken
    (:mod:`constitutive.tensile`).

    Parameters
    ----------
    weight : float
        w = ρ_A g, the fabric's weight per area [N/m²].
    specimen_radius, disc_radius : float
        R and r_d [m].

    Examples
    --------
    >>> round(skirt_tension(1.0, 0.127, 0.0635) / 0.0635, 6)   # R = 2 r_d: 5 r_d / 9
    0.555556
    """
    _check_radii(specimen_radius, disc_radius)
    R, a = specimen_radius, disc_radius
    return float(weight * (2.0 * R + a) * (R - a) / (3.0 * (R + a)))


@dataclass
class CusickResult:
    """Outcome of :func:`drape_analysis` (SI units)."""

    drape_coefficient: float
    shadow: object
    specimen_radius: float
    disc_radius: float
    centre: tuple
    angles: np.ndarray
    radius: np.ndarray
    node_indices: np.ndarray
    node_depths: np.ndarray
    extra: dict = field(default_factory=dict)

    @property
    def n_nodes(self) -> int:
        """Number of nodes (folds)."""
        return int(self.node_indices.size)

    @property
    def node_angles(self) -> np.ndarray:
        """Angles of the node crests (rad)."""
        return self.angles[self.node_indices]

    def summary(self) -> dict:
        """JSON-ready scalars: DC, node count, depths (m), angles (deg) and the outline's
        harmonic amplitudes ``a_0 .. a_20`` (m, :func:`drape.analyses.outline.outline_harmonics`)
        and what of them lies outside the fold pattern (m, :func:`~drape.analyses.outline.outline_irregularity`)."""
        harmonics = outline_harmonics(self.radius)
        return {
            "drape_coefficient": self.drape_coefficient,
            "drape_coefficient_percent": 100.0 * self.drape_coefficient,
            "n_nodes": self.n_nodes,
            "node_depths_m": [float(d) for d in self.node_depths],
            "node_depth_mean_m": float(np.mean(self.node_depths)) if self.n_nodes else 0.0,
            "node_angles_deg": [float(np.degrees(a)) for a in self.node_angles],
            "shadow_area_m2": float(self.shadow.area),
            "outline_radius_min_m": float(self.radius.min()),
            "outline_radius_max_m": float(self.radius.max()),
            "outline_harmonics_m": [float(a) for a in harmonics],
            "outline_irregularity_m": outline_irregularity(harmonics, self.n_nodes),
            **self.extra,
        }


def drape_analysis(points, triangles, specimen_radius: float, disc_radius: float,
                   centre=(0.0, 0.0), n_samples: int = 720, rel_prominence: float = 0.15,
                   min_prominence_fraction: float = 0.02, max_mode: int | None = 20) -> CusickResult:
    """Drape coefficient and nodes of a deformed Cusick specimen.

    Parameters
    ----------
    points : array_like, shape (N, 2) or (N, 3)
        Deformed node coordinates (reference + displacement), metres.
    triangles : array_like of int, shape (T, 3)
    specimen_radius, disc_radius : float
        Nominal radii (m).
    centre : tuple of float
    n_samples : int
        Rays used to read the outline radius.
    rel_prominence : float
        See :func:`find_nodes`.
    min_prominence_fraction : float
        Absolute node-prominence floor as a fraction of the overhang ``R - r_d``.
    max_mode : int or None
        Low-pass of the outline before node detection, see :func:`find_nodes`.

    Returns
    -------
    CusickResult

    Examples
    --------
    A flat 2 x 2 square around a disc of radius 0.5: DC = (4 - pi/4) / (pi - pi/4):

    >>> pts = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    >>> res = drape_analysis(pts, [[0, 1, 2], [0, 2, 3]], 1.0, 0.5)
    >>> round(res.drape_coefficient, 4), res.n_nodes
    (1.3643, 4)
    """
    _check_radii(specimen_radius, disc_radius)
    shadow = shadow_polygon(points, triangles, disc_radius, centre)
    angles, radius = boundary_radius(shadow, centre, n_samples)
    peaks, depths = find_nodes(radius, rel_prominence,
                               min_prominence_fraction * (specimen_radius - disc_radius), max_mode)
    dc = drape_coefficient(shadow.area, specimen_radius, disc_radius)
    return CusickResult(dc, shadow, specimen_radius, disc_radius, tuple(centre), angles, radius,
                        peaks, depths)


def plot_top_view(result: CusickResult, path, title: str | None = None):
    """Drape-meter style top view: specimen outline, shadow, disc, DC and node count.

    Parameters
    ----------
    result : CusickResult
    path : str or Path
        PNG file to write.
    title : str, optional

    Returns
    -------
    Path
    """
    from matplotlib.figure import Figure  # without pyplot: the caller's backend is left alone
    from matplotlib.patches import Circle

    path = Path(path)
    cx, cy = result.centre
    cm = 100.0  # plot in centimetres, as the drape meter's scale does
    fig = Figure(figsize=(6, 6))
    ax = fig.subplots()
    geoms = getattr(result.shadow, "geoms", [result.shadow])
    for g in geoms:
        ext = np.asarray(g.exterior.coords) * cm
        ax.fill(ext[:, 0], ext[:, 1], color="0.25", zorder=1)
        for hole in g.interiors:
            h = np.asarray(hole.coords) * cm
            ax.fill(h[:, 0], h[:, 1], color="white", zorder=2)
    ax.add_patch(Circle((cx * cm, cy * cm), result.specimen_radius * cm, fill=False, ls="--",
                        color="tab:blue", lw=1.2, zorder=3, label="specimen (flat)"))
    ax.add_patch(Circle((cx * cm, cy * cm), result.disc_radius * cm, color="0.75", ec="k",
                        zorder=4, label="disc"))
    if result.n_nodes:
        a = result.node_angles
        r = result.radius[result.node_indices]
        ax.plot((cx + r * np.cos(a)) * cm, (cy + r * np.sin(a)) * cm, "o", color="tab:red",
                ms=5, zorder=5, label="nodes")
    lim = 1.1 * result.specimen_radius * cm
    ax.set_xlim(cx * cm - lim, cx * cm + lim)
    ax.set_ylim(cy * cm - lim, cy * cm + lim)
    ax.set_aspect("equal")
    ax.set_xlabel("x (warp) [cm]")
    ax.set_ylabel("y (weft) [cm]")
    ax.text(0.02, 0.98, f"DC = {100 * result.drape_coefficient:.1f} %\nnodes = {result.n_nodes}",
            transform=ax.transAxes, va="top", fontsize=12,
            bbox=dict(boxstyle="round", fc="white", alpha=0.8))
    ax.legend(loc="lower right", fontsize=8)
    if title:
        ax.set_title(title)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    return path


def _nodal_displacement(mesh, displacement) -> np.ndarray:
    u = np.asarray(displacement, dtype=float)
    n = mesh.p.shape[1]
    if u.shape == (3, n):
        u = u.T
    if u.shape != (n, 3):
        raise CusickError(f"displacement has shape {u.shape}: need (N, 3) or (3, N) with N = {n}")
    return u


_DETECTION_OPTIONS = {"n_samples": int, "rel_prominence": float,
                      "min_prominence_fraction": float, "max_mode": lambda v: v}


def cusick_post(mesh, displacement, cusick: dict, out_dir=None, name: str = "cusick",
                surface=None) -> dict:
    """Runner hook: analyse a settled Cusick drape and write the top view.

    Parameters
    ----------
    mesh : skfem.MeshTri
        Reference (flat) mesh.
    displacement : array_like, shape (N, 3) or (3, N)
        Nodal displacement.
    cusick : dict
        The case's ``[cusick]`` table; uses ``specimen_diameter`` and ``disc_diameter`` (m)
        and optionally ``rel_prominence``, ``min_prominence_fraction``, ``n_samples``, ``max_mode``.
    out_dir : str or Path, optional
        Where ``<name>_top_view.png`` goes.
    name : str
    surface : tuple (points (N, 3), triangles (T, 3)), optional
        The deformed surface sampled finer than the vertices (e.g.
        ``KirchhoffLoveShell.deformed_surface``): its shadow is measured instead of the
        vertex triangles'. ``displacement`` is still checked against ``mesh``.

    Returns
    -------
    dict
        :meth:`CusickResult.summary` (plus ``top_view_png`` when written).
    """
    for key in ("specimen_diameter", "disc_diameter"):
        if key not in cusick:
            raise CusickError(f"[cusick] {key}: missing (diameter in metres)")
    u = _nodal_displacement(mesh, displacement)
    vertices = np.column_stack([mesh.p.T[:, :2], np.zeros(mesh.p.shape[1])]) + u
    pts, tri = (vertices, mesh.t.T) if surface is None else surface
    # only the options the table sets: drape_analysis's defaults are the one detection rule,
    # shared with a measured drape (drape.analyses.scan_measure)
    options = {k: cast(cusick[k]) for k, cast in _DETECTION_OPTIONS.items() if k in cusick}
    res = drape_analysis(pts, tri, 0.5 * float(cusick["specimen_diameter"]),
                         0.5 * float(cusick["disc_diameter"]), **options)
    out = res.summary()
    if surface is not None:
        # what the vertex triangles alone would give: the gap is the mesh's drawing error
        vertex_shadow = shadow_polygon(vertices, mesh.t.T, res.disc_radius)
        out["drape_coefficient_vertices_percent"] = 100.0 * drape_coefficient(
            vertex_shadow.area, res.specimen_radius, res.disc_radius)
    if out_dir is not None:
        png = plot_top_view(res, Path(out_dir) / f"{name}_top_view.png", title=name)
        out["top_view_png"] = str(png)
    return out
