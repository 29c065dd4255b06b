"""Read a measured (scanned) Cusick drape like a simulated one.

``python -m drape.measure SCAN [SCAN ...]`` (:mod:`drape.cli.measure`) measures scans with
:func:`measure_scan` and prints :func:`format_table`.

A scan (any surface mesh meshio reads, :mod:`drape.analyses.scan`) goes through the very analysis a
simulated drape goes through, :func:`drape.analyses.drape_coefficient.drape_analysis` with its default node
detection: the shadow is the union of the projected triangles and the disc, the drape
coefficient its share of the hanging annulus, the nodes the lobes of its outline ``r(phi)``
read from the disc centre.  Only the centre differs: a simulated specimen hangs from a disc
at the origin, a scanned one from wherever the scanner put it, so the centre is found from
the scan (:func:`drape.analyses.scan.find_disc_top`) or given.  The descriptors are
:meth:`drape.analyses.drape_coefficient.CusickResult.summary`, the keys a simulated run's ``summary.json`` has,
among them the outline's harmonic amplitudes (:mod:`drape.analyses.outline`), which compare two drapes
whatever their orientation on the disc.

Before it is measured a surface is checked to be a drape (:mod:`drape.analyses.scan`,
:mod:`drape.analyses.scan_checks`): one that is not is refused with one line
(:class:`~drape.analyses.scan.ScanError`); one measured in spite of a flaw (a small hole, a
reach a few millimetres past the specimen, turned upside down) carries a warning line in
:attr:`Measurement.warnings`. The stated sizes must be a Cusick tester's
(:data:`SIZE_RANGES`): a bare number is metres.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from constitutive.units import ureg
from drape.analyses.drape_coefficient import CusickError, CusickResult, drape_analysis, plot_top_view
from drape.analyses.scan import ScanError, check_extent, check_finite, check_units, read_scan
from drape.analyses.scan_checks import (
    check_area,
    check_arrays,
    check_centre,
    check_coverage,
    check_disc,
    check_holes,
    locate_disc,
)

__all__ = ["SPECIMEN_DIAMETER", "DISC_DIAMETER", "TOP_BAND", "SIZE_RANGES", "Measurement",
           "length_m", "plausible_size", "check_sizes", "measure_surface", "measure_scan",
           "format_table", "unique_names", "write_outputs"]

#: BS 5058 set-up: a 30 cm specimen on an 18 cm disc (m).
SPECIMEN_DIAMETER = 0.30
DISC_DIAMETER = 0.18
#: Harmonics shown in the table (k = 1 ..); all of them are in the JSON.
TABLE_HARMONICS = 8
#: Height band of the flat disc top (m): a registered scan's disc is flat to well under it; a
#: stiff fabric stays within a millimetre of the top past the disc's edge, which would bias the
#: centre towards its flattest side.
TOP_BAND = 3e-4
#: Plausible sizes (m) of what a Cusick tester holds, by what they are: a size outside is a
#: slip of the unit (a bare number is metres).
SIZE_RANGES = {"specimen diameter": (0.10, 1.0), "disc diameter": (0.05, 0.5),
               "top band": (1e-6, 0.02)}


@dataclass
class Measurement:
    """One drape read by :func:`measure_surface`.

    Attributes
    ----------
    name : str
    result : CusickResult
        DC, nodes, outline and shadow, as for a simulated drape.
    centre_from : str
        ``"disc top"`` (estimated) or ``"given"``.
    disc_top : drape.analyses.scan.DiscTop or None
        The flat top found on the disc (None when the centre was given).
    n_vertices, n_triangles : int
    warnings : list of str
        What was measured in spite of a flaw, one line each.
    """

    name: str
    result: CusickResult
    centre_from: str
    disc_top: object
    n_vertices: int
    n_triangles: int
    warnings: list = field(default_factory=list)

    def descriptors(self) -> dict:
        """JSON-ready: the simulated drape's summary keys, the centre used and the outline."""
        top = self.disc_top
        return {
            "name": self.name,
            "centre_m": [float(c) for c in self.result.centre],
            "centre_from": self.centre_from,
            "disc_top_radius_m": None if top is None else top.radius,
            "disc_top_level_m": None if top is None else top.level,
            "specimen_radius_m": self.result.specimen_radius,
            "disc_radius_m": self.result.disc_radius,
            "n_vertices": self.n_vertices,
            "n_triangles": self.n_triangles,
            **self.result.summary(),
            "outline_angles_deg": [float(a) for a in np.degrees(self.result.angles)],
            "outline_radius_m": [float(r) for r in self.result.radius],
            "warnings": list(self.warnings),
        }


def length_m(text, positive: bool = True) -> float:
    """A length in metres from ``"30cm"``, ``"300 mm"`` or a bare number (metres); with
    ``positive`` (the default) zero and negative lengths are refused.

    Examples
    --------
    >>> length_m("30cm"), length_m("300 mm"), length_m("0.3"), length_m(0.3)
    (0.3, 0.3, 0.3, 0.3)
    >>> length_m("-2 mm", positive=False)
    -0.002
    """
    try:
        q = ureg.Quantity(text) if isinstance(text, str) else ureg.Quantity(float(text))
        value = q.magnitude if q.dimensionless else q.to("m").magnitude
        value = float(f"{float(value):.15g}")  # drop pint's round-off in the 16th digit
    except Exception as exc:  # pint raises several kinds for a string it cannot read
        raise ValueError(f"{text!r} is not a length (e.g. 30cm, 300 mm, 0.3 for metres): {exc}")
    if not np.isfinite(value) or (positive and value <= 0.0):
        raise ValueError(f"{text!r}: a length must be {'positive' if positive else 'finite'}")
    return value


def plausible_size(kind: str, value: float) -> float:
    """``value`` (m) if it is a plausible size of ``kind`` (a key of :data:`SIZE_RANGES`).

    Examples
    --------
    >>> plausible_size("specimen diameter", 0.3)
    0.3
    >>> plausible_size("specimen diameter", 30)
    Traceback (most recent call last):
    ...
    ValueError: 30 m is no specimen diameter: 10 cm to 1 m (a bare number is metres: write 30cm)
    """
    low, high = SIZE_RANGES[kind]
    if low <= value <= high:
        return value
    meant = [f"{value:g}{unit}" for unit, f in (("cm", 1e-2), ("mm", 1e-3))
             if low <= value * f <= high]
    hint = f": write {' or '.join(meant)}" if meant else ""
    raise ValueError(f"{value:g} m is no {kind}: {_size(low)} to {_size(high)} (a bare number "
                     f"is metres{hint})")


def _size(length: float) -> str:
    for unit, factor in (("m", 1.0), ("cm", 1e-2), ("mm", 1e-3), ("µm", 1e-6)):
        if length >= factor:
            return f"{length / factor:g} {unit}"
    return f"{length:g} m"


def check_sizes(specimen_radius: float, disc_radius: float, top_band: float = TOP_BAND) -> None:
    """Refuse sizes no Cusick tester has (:data:`SIZE_RANGES`) and a specimen no larger than
    its disc.

    Raises
    ------
    drape.analyses.scan.ScanError
    """
    try:
        plausible_size("specimen diameter", 2 * specimen_radius)
        plausible_size("disc diameter", 2 * disc_radius)
        plausible_size("top band", top_band)
    except (TypeError, ValueError) as exc:
        raise ScanError(str(exc)) from None
    if specimen_radius <= disc_radius:
        raise ScanError(f"specimen {2 * specimen_radius:g} m must be larger than the disc "
                        f"{2 * disc_radius:g} m")


def measure_surface(points, triangles, specimen_radius: float = SPECIMEN_DIAMETER / 2,
                    disc_radius: float = DISC_DIAMETER / 2, centre=None, name: str = "scan",
                    top_band: float = TOP_BAND) -> Measurement:
    """Descriptors of a draped surface in the drape meter's frame (metres, skirt towards -z).

    Parameters
    ----------
    points : array_like, shape (N, 3)
    triangles : array_like of int, shape (T, 3)
    specimen_radius, disc_radius : float
        Nominal radii (m).
    centre : tuple of float, optional
        Disc centre (x, y) in metres; estimated from the flat top when not given.
    name : str
    top_band : float
        Height band (m) of the flat disc top the centre is estimated from
        (:func:`drape.analyses.scan.find_disc_top`).

    Returns
    -------
    Measurement

    Raises
    ------
    drape.analyses.scan.ScanError
        Sizes no Cusick tester has; coordinates not finite or not in metres; no drape
        (:mod:`drape.analyses.scan_checks`: too little area, no disc top or one of another
        size than the disc's, part of the skirt missing, holes); larger than the specimen.
    """
    check_sizes(specimen_radius, disc_radius, top_band)
    points = np.asarray(points, dtype=float)
    triangles = np.asarray(triangles)
    with np.errstate(all="ignore"):     # absurd coordinates are refused in words below
        return _measured(points, triangles, specimen_radius, disc_radius, centre, name, top_band)


def _measured(points, triangles, specimen_radius, disc_radius, centre, name, top_band):
    """:func:`measure_surface` once the arrays are arrays: the checks in order, the analysis."""
    check_arrays(points, triangles)
    check_finite(points)
    check_units(points, specimen_radius, disc_radius)
    check_area(points, triangles, specimen_radius, disc_radius)
    warnings, top = [], None
    if centre is None:
        points, top, turned = locate_disc(points, disc_radius, top_band)
        warnings.append(turned)
        centre = top.centre
    else:
        centre = tuple(float(c) for c in centre)
        check_centre(points, centre)
    warnings.append(check_coverage(points, triangles, centre, disc_radius, top_band))
    if top is not None:
        check_disc(points, top, disc_radius)
    warnings.append(check_extent(points, centre, specimen_radius))
    try:
        result = drape_analysis(points, triangles, specimen_radius, disc_radius, centre=centre)
    except CusickError as exc:
        raise ScanError(str(exc)) from None
    warnings.append(check_holes(result))
    return Measurement(name, result, "disc top" if top is not None else "given", top,
                       len(points), len(triangles), [w for w in warnings if w])


def measure_scan(path, specimen_radius: float = SPECIMEN_DIAMETER / 2,
                 disc_radius: float = DISC_DIAMETER / 2, centre=None, scale: float = 1.0,
                 name: str | None = None, top_band: float = TOP_BAND) -> Measurement:
    """:func:`measure_surface` of a mesh file (:func:`drape.analyses.scan.read_scan`).

    Raises
    ------
    drape.analyses.scan.ScanError
        One line naming the file and what is wrong with it. Its warnings name it too.
    """
    path = Path(path)
    try:
        points, triangles = read_scan(path, scale)
        m = measure_surface(points, triangles, specimen_radius, disc_radius, centre,
                            name or path.stem, top_band)
    except ScanError as exc:
        raise ScanError(_naming(path, str(exc))) from None
    m.warnings = [_naming(path, w) for w in m.warnings]
    return m


def _naming(path: Path, message: str) -> str:
    return message if message.startswith(str(path)) else f"{path}: {message}"


def format_table(measurements) -> str:
    """One line per drape: DC, nodes, mean fold depth, the centre used, harmonics a_1 .. a_8."""
    width = max([len(m.name) for m in measurements] + [4])
    harmonics = "".join(f"{f'a{k}':>6}" for k in range(1, TABLE_HARMONICS + 1))
    lines = [f"{'scan':<{width}}  {'DC %':>6} {'nodes':>5} {'depth':>6}  {'centre x, y':>13}"
             f"{harmonics}",
             f"{'':<{width}}  {'':>6} {'':>5} {'mm':>6}  {'mm':>13}{'(mm)':>6}"]
    for m in measurements:
        s = m.result.summary()
        cx, cy = (1e3 * c for c in m.result.centre)
        amps = "".join(f"{1e3 * a:6.1f}" for a in s["outline_harmonics_m"][1:TABLE_HARMONICS + 1])
        lines.append(f"{m.name:<{width}}  {s['drape_coefficient_percent']:6.1f} {s['n_nodes']:5d} "
                     f"{1e3 * s['node_depth_mean_m']:6.1f}  {cx:6.1f},{cy:6.1f}{amps}")
    return "\n".join(lines)


def unique_names(paths) -> list[str]:
    """A name per scan: its file's stem, numbered from the second scan of the same stem on.

    >>> unique_names(["a/s1.ply", "b/s1.ply", "s2.obj"])
    ['s1', 's1-2', 's2']
    """
    names, seen = [], {}
    for p in paths:
        stem = Path(p).stem
        seen[stem] = seen.get(stem, 0) + 1
        names.append(stem if seen[stem] == 1 else f"{stem}-{seen[stem]}")
    return names


def write_outputs(out, measurements, report: dict) -> None:
    """``<name>_top.png`` of every measurement and ``measure.json`` (``report``) in ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    for m in measurements:
        plot_top_view(m.result, out / f"{m.name}_top.png", title=m.name)
    (out / "measure.json").write_text(json.dumps(report, indent=2))
