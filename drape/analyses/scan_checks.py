"""Whether a scanned surface is a Cusick drape: its area, its disc, its coverage, its holes.

A surface can be read (:mod:`drape.analyses.scan`) and still not be a drape the analysis can
measure: a stray triangle, a mesh of degenerate ones, half a scan, a skirt with a hole in
it, a scan turned upside down, a disc stated with the wrong size. Each gives a drape
coefficient all the same, and a wrong one. The checks here refuse such a scan with one
line (:class:`~drape.analyses.scan.ScanError`), or return a warning line where the scan is
measured all the same:

- its triangles must cover at least :data:`MIN_AREA` of the specimen's hanging annulus
  (their area in space: a fabric does not shrink), else it is *not a drape*;
- the disc top is the highest part, the skirt hangs below it: a scan whose flat top lies at
  its bottom is turned over (``z -> -z``) with a warning, which changes neither the shadow
  nor the DC but finds the disc where it is;
- the flat top the centre is fitted to must be the stated disc's size: at most
  :data:`DISC_SMALLER` smaller, at most :data:`DISC_LARGER` larger (a stiff fabric lies flat a
  little past the disc's edge); a scan flat to its edge (nothing hangs) shows no disc edge
  and is not compared;
- the skirt must be there all round the disc: directions round the centre along which the
  scan has no skirt triangle are missing data; more than :data:`MISSING_REFUSED` of them
  refuse the scan, fewer are a warning;
- holes in the shadow (a part of the skirt the scanner did not see) lower the DC by their
  area: from :data:`HOLE_WARNED` DC points on a warning gives the DC with them filled, from
  :data:`HOLE_REFUSED` points on the scan is refused.
"""
from __future__ import annotations

import numpy as np
import shapely

from drape.analyses.scan import DiscTop, ScanError, find_disc_top

__all__ = ["MIN_AREA", "DISC_SMALLER", "DISC_LARGER", "MISSING_REFUSED", "HOLE_WARNED", "HOLE_REFUSED",
           "check_arrays", "check_area", "check_centre", "locate_disc", "check_disc", "skirt_directions",
           "check_coverage", "hole_points", "check_holes"]

#: Least area of a scan's triangles, as a fraction of the hanging annulus: a half scan has
#: about 0.8, a simulated annulus without the disc top 1.
MIN_AREA = 0.25
#: How much smaller and larger the flat top's radius may be than the stated disc's (a
#: fraction of it): the disc is flat under all of the fabric on it, and a stiff fabric lies
#: flat past the disc's edge, by about 5 mm at a bending length of 4 cm.
DISC_SMALLER = 0.10
DISC_LARGER = 0.20
#: A flat top reaching this share of the scan's reach is the whole scan: no disc edge shows.
FLAT_TO_EDGE = 0.95
#: How far past the disc's edge (a fraction of its radius) a flat triangle is skirt, not top.
SKIRT_BEYOND = 0.05
#: Share of the directions round the disc without skirt from which a scan is refused.
MISSING_REFUSED = 0.10
#: Holes in the shadow (DC points) warned of, and refused.
HOLE_WARNED = 0.1
HOLE_REFUSED = 1.0
#: Rays round the centre the coverage is read along (as many as the outline's).
N_DIRECTIONS = 720


def _cm(length: float) -> str:
    return f"{100.0 * length:.4g} cm"


def _annulus(specimen_radius: float, disc_radius: float) -> float:
    return float(np.pi * (specimen_radius**2 - disc_radius**2))


def check_arrays(points, triangles) -> None:
    """Refuse points that are not (N, 3) and triangles that are not (T, 3) indices of them."""
    if points.ndim != 2 or points.shape[1] != 3:
        raise ScanError(f"points have shape {points.shape}: must be (N, 3)")
    if triangles.ndim != 2 or triangles.shape[1] != 3 or not np.issubdtype(triangles.dtype,
                                                                            np.integer):
        raise ScanError(f"triangles have shape {triangles.shape}: must be (T, 3) vertex indices")
    if triangles.size and (triangles.min() < 0 or triangles.max() >= len(points)):
        raise ScanError("triangles refer to vertices the scan does not have")


def check_area(points, triangles, specimen_radius: float, disc_radius: float) -> None:
    """Refuse triangles whose area is under :data:`MIN_AREA` of the hanging annulus (one
    triangle, degenerate ones): not a drape."""
    p = points[triangles]
    area = 0.5 * float(np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum())
    annulus = _annulus(specimen_radius, disc_radius)
    if not area >= MIN_AREA * annulus:
        raise ScanError(f"not a drape: its {len(triangles)} triangles cover {1e4 * area:.4g} cm², "
                        f"under {100 * MIN_AREA:g} % of the {1e4 * annulus:.4g} cm² a "
                        f"{_cm(2 * specimen_radius)} specimen hangs round the disc with")


def check_centre(points, centre) -> None:
    """Refuse a given centre outside the scan's extent (a bare number is metres)."""
    lo, hi = points[:, :2].min(axis=0), points[:, :2].max(axis=0)
    if not (np.all(np.isfinite(centre)) and np.all(lo <= centre) and np.all(centre <= hi)):
        raise ScanError(f"the given centre ({1e3 * centre[0]:.4g}, {1e3 * centre[1]:.4g}) mm lies "
                        f"outside the scan (x {1e3 * lo[0]:.4g} to {1e3 * hi[0]:.4g} mm, y "
                        f"{1e3 * lo[1]:.4g} to {1e3 * hi[1]:.4g} mm; a bare number is metres)")


def _hangs_down(points, top: DiscTop, disc_radius: float) -> bool:
    """Whether the skirt (beyond the disc) lies lower than the disc (within it), as a drape's."""
    r = np.hypot(points[:, 0] - top.centre[0], points[:, 1] - top.centre[1])
    inner, outer = points[r <= disc_radius, 2], points[r > 1.1 * disc_radius, 2]
    if not (len(inner) and len(outer)):
        return True     # nothing to compare: the other checks judge it
    return bool(np.median(outer) <= np.median(inner))


def _top(points, disc_radius: float, band: float):
    try:
        return find_disc_top(points, disc_radius, band), None
    except ScanError as exc:
        return None, exc


def locate_disc(points, disc_radius: float, band: float) -> tuple:
    """The disc's flat top, with the scan turned over if it lies upside down.

    Returns
    -------
    points : ndarray
        The scan, turned over (``z -> -z``) if its flat top lies at its bottom.
    top : drape.analyses.scan.DiscTop
    warning : str or None

    Raises
    ------
    ScanError
        No flat top either way up.
    """
    top, problem = _top(points, disc_radius, band)
    if top is not None and _hangs_down(points, top, disc_radius):
        return points, top, None
    turned = points * np.array([1.0, 1.0, -1.0])
    under, _ = _top(turned, disc_radius, band)
    if under is not None and _hangs_down(turned, under, disc_radius):
        return turned, under, ("upside down: the flat disc top lies at the bottom of the scan "
                               "and the skirt rises from it; measured turned over (z -> -z)")
    if top is None:
        raise problem
    return points, top, None


def check_disc(points, top: DiscTop, disc_radius: float) -> None:
    """Refuse a flat top more than :data:`DISC_SMALLER` smaller or :data:`DISC_LARGER` larger
    than the stated disc, unless the scan is flat to its edge (no disc edge shows)."""
    ratio = top.radius / disc_radius
    if 1.0 - DISC_SMALLER <= ratio <= 1.0 + DISC_LARGER:
        return
    reach = float(np.max(np.hypot(points[:, 0] - top.centre[0], points[:, 1] - top.centre[1])))
    if top.radius >= FLAT_TO_EDGE * reach:
        return
    raise ScanError(f"the flat disc top found is {_cm(2 * top.radius)} across, the stated disc "
                    f"{_cm(2 * disc_radius)} (the top may be {100 * DISC_SMALLER:g} % smaller or "
                    f"{100 * DISC_LARGER:g} % larger): pass --disc, or --centre to measure round "
                    f"a centre you give")


def _arcs(angles) -> tuple[np.ndarray, np.ndarray]:
    """Start and length of the smallest arc holding each row's angles (a full turn where the
    triangle holds the centre)."""
    a = np.sort(np.mod(angles, 2 * np.pi), axis=1)
    gaps = np.diff(np.concatenate([a, a[:, :1] + 2 * np.pi], axis=1), axis=1)
    widest = np.argmax(gaps, axis=1)
    rows = np.arange(len(a))
    start = a[rows, (widest + 1) % 3]
    length = 2 * np.pi - gaps[rows, widest]
    full = gaps[rows, widest] < np.pi
    return np.where(full, 0.0, start), np.where(full, 2 * np.pi, length)


def skirt_directions(points, triangles, centre, disc_radius: float, band: float,
                     n: int = N_DIRECTIONS) -> np.ndarray:
    """Which of ``n`` directions round ``centre`` the skirt is scanned in (bool, shape (n,)).

    A triangle is skirt when it hangs below the disc's top (more than ``band`` under the top
    level) or reaches :data:`SKIRT_BEYOND` past the disc's edge (a fabric flat past it); it
    covers the directions between its vertices, as seen from the centre. An inward fold
    under the disc's edge thus counts where it hangs, and the disc top, up to its edge, never.
    """
    xy = points[:, :2] - np.asarray(centre, dtype=float)
    r = np.hypot(xy[:, 0], xy[:, 1])
    level = float(np.percentile(points[:, 2], 99.5))
    skirt = ((r[triangles] > (1.0 + SKIRT_BEYOND) * disc_radius).any(axis=1)
             | (points[triangles, 2] < level - band).any(axis=1))
    start, length = _arcs(np.arctan2(xy[:, 1], xy[:, 0])[triangles[skirt]])
    step = 2 * np.pi / n
    first = np.ceil(start / step - 1e-9).astype(int)
    last = np.minimum(np.floor((start + length) / step + 1e-9).astype(int), first + n - 1)
    count = np.zeros(2 * n + 1)
    np.add.at(count, first[last >= first], 1)
    np.add.at(count, last[last >= first] + 1, -1)
    covered = np.cumsum(count)[: 2 * n]
    return (covered[:n] + covered[n:]) > 0


def _missing_at(covered) -> str:
    """The widest run of missing directions, as 'from A° to B°'."""
    n = len(covered)
    step = 360.0 / n
    best, where, run = 0, 0, 0
    for k in range(2 * n):
        run = run + 1 if not covered[k % n] else 0
        if run > best:
            best, where = min(run, n), k
    start = (where - best + 1) % n
    return f"from {start * step:.0f}° to {(start + best) * step:.0f}°"


def check_coverage(points, triangles, centre, disc_radius: float, band: float) -> str | None:
    """Refuse a scan without skirt in more than :data:`MISSING_REFUSED` of the directions
    round the disc; return a warning where it misses fewer (None: complete)."""
    covered = skirt_directions(points, triangles, centre, disc_radius, band)
    missing = 1.0 - covered.mean()
    if missing == 0.0:
        return None
    where = f"{360 * missing:.1f}° of the directions round the disc, widest {_missing_at(covered)}"
    if missing > MISSING_REFUSED:
        raise ScanError(f"not a drape: the scan has no skirt over {where} (a part of the scan "
                        f"missing; more than {360 * MISSING_REFUSED:g}° is refused)")
    return f"the scan has no skirt over {where}: its DC and nodes there are the bare disc's"


def hole_points(shadow, specimen_radius: float, disc_radius: float) -> float:
    """Area of the holes in a shadow, in DC points: what filling them would add (a part of the
    shadow lying inside another's hole fills that much of it)."""
    parts = getattr(shadow, "geoms", [shadow])
    filled = shapely.unary_union([shapely.Polygon(g.exterior) for g in parts
                                  if g.geom_type == "Polygon"])
    return 100.0 * max(float(filled.area - shadow.area), 0.0) / _annulus(specimen_radius,
                                                                          disc_radius)


def check_holes(result) -> str | None:
    """Refuse a shadow with holes of :data:`HOLE_REFUSED` DC points or more; return a warning
    with the DC they would add from :data:`HOLE_WARNED` points on (None: no such holes).

    ``result`` is the scan's :class:`drape.analyses.drape_coefficient.CusickResult`.
    """
    points = hole_points(result.shadow, result.specimen_radius, result.disc_radius)
    if points < HOLE_WARNED:
        return None
    dc = 100.0 * result.drape_coefficient
    said = (f"holes in the scan's shadow cover {points:.2g} DC points (DC {dc:.1f} %, "
            f"{dc + points:.1f} % with them filled)")
    if points >= HOLE_REFUSED:
        raise ScanError(f"not a drape: {said}: a part of the skirt missing from the scan, or a "
                        f"centre off the disc's (refused from {HOLE_REFUSED:g} point)")
    return said
