"""Measured KES-FB bending loops: the thesis's polynomials and CSV exports.

Two sources of "measured" moment–curvature loops feed the fit
(:mod:`constitutive.fit`):

* Deng's digitised KES-FB curves [Den94] as printed in the thesis, Appendix B.4:
  one quartic polynomial in curvature per path (Tables B.1–B.12), for the four
  datasets ``fabric1-warp``, ``fabric1-weft``, ``fabric2-warp``,
  ``fabric2-weft`` (:func:`thesis_dataset`).
* CSV exports of a KES-FB instrument: rows of curvature, moment and
  optionally time (:func:`load_kes_csv`).

Both become a :class:`BranchCurves`: the measured moment as a function of
curvature on each of the three paths of the test (0 loading, 1 unloading +
reverse loading, 2 reverse unloading), the turning curvatures K+ and K−, and the
test rate.  :meth:`BranchCurves.sample` lays the measured moment along the
nine-region machine profile (:func:`constitutive.kes.kes_profile`) every 1 ms,
which is how the thesis evaluates its residual (4.17): model and data are
compared at the same instants, the data being looked up on the path the
machine is on.

Turning points of the thesis datasets.  The thesis prints no K±.  The three
path polynomials of a loop must be continuous where the machine turns, so K+ is
the real root of ``P_loading − P_unloading`` and K− the real root of
``P_unloading − P_reverse_unloading`` nearest ±2.5 cm⁻¹ (the KES-FB standard
turning curvature).  They come out as

=============  =======  =======
dataset        K+       K−
=============  =======  =======
fabric1-warp   1.910    −1.949
fabric1-weft   2.323    −2.320
fabric2-warp   2.253    −2.241
fabric2-weft   2.276    −2.270
=============  =======  =======

(cm⁻¹).  The thesis's text agrees where it quotes curvatures (fabric 2 warp:
"a good fit for the region from −2.25 cm⁻¹ to −1.5 cm⁻¹ on the reverse
unloading portion").  Fabric 1 warp is the odd one: Table B.2's constant term
+2.950e-3 puts the unloading path *above* the loading path at κ = 0 (a
clockwise, energy-producing loop near the origin), whereas every other
dataset has a negative unloading moment at κ = 0 as friction requires; with
the opposite sign the turning points would be +2.285/−2.245.  A misprint is
likely, but the tables are kept exactly as printed here.

Measured CSV points are treated the same way: each path's points become a
piecewise-linear M(κ) (duplicates averaged), K± are the extreme curvatures
of the detected paths, and the machine profile between them supplies κ, κ̇, κ̈
at 1 ms — measured curvatures are noisy and differentiating them twice
would be worse than trusting the machine's programmed motion.

Units: SI inside (curvature 1/m, moment per width N·m/m = N, time s); the
polynomials are stored exactly as printed (cm⁻¹ → gf·cm/cm) and converted on
evaluation.

Examples
--------
>>> data = thesis_dataset("fabric1-weft")
>>> round(data.k_plus / 100, 3), round(data.k_minus / 100, 3)
(2.323, -2.32)
>>> loop = data.sample(accel_time=0.1)
>>> loop.kappa.shape == loop.moment.shape == loop.branch.shape
True
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from constitutive import units as _units
from constitutive.kes import kes_profile

__all__ = [
    "THESIS_POLYNOMIALS",
    "DATASET_NAMES",
    "PathPolynomials",
    "KESLoop",
    "BranchCurves",
    "KESDataError",
    "turning_points",
    "thesis_dataset",
    "detect_branches",
    "load_kes_csv",
    "write_kes_csv",
    "load_dataset",
]

# ---------------------------------------------------------------------------
# unit factors (the KES <-> SI conversion itself lives in constitutive.units)
# ---------------------------------------------------------------------------
CURVATURE_KES = _units.factor("curvature")  # 1/cm in 1/m
MOMENT_KES = _units.factor("moment")  # gf·cm/cm in N·m/m


def _factor_to_si(unit, quantity):
    """SI value of one ``unit`` (any pint unit string) of ``quantity``.

    Instrument-style exponents are accepted too: ``cm-1`` and ``cm2`` mean
    ``cm**-1`` and ``cm**2``.

    >>> _factor_to_si("cm-1", "curvature"), _factor_to_si("gf.cm/cm", "moment")
    (100.0, 0.00980665)
    """
    unit = re.sub(r"(?<=[A-Za-z])(-?\d+)\b", r"**\1", unit.strip())
    try:
        q = _units.ureg.Quantity(1.0, _units.parse_unit(unit))
    except Exception:  # pint raises several unrelated types for unparsable strings
        raise ValueError("is not a unit pint understands") from None
    try:
        return float(q.to(_units.SI_UNITS[quantity]).magnitude)
    except Exception:
        raise ValueError(f"is not a {quantity} unit (needs the dimension of "
                         f"{_units.SI_UNITS[quantity]})") from None

# ---------------------------------------------------------------------------
# Thesis Appendix B.4: quartic polynomial fits to Deng's digitised curves.
# Coefficients exactly as printed, highest power first (x^4 ... x^0),
# x = curvature [cm^-1], value = moment [gf·cm/cm].
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class PathPolynomials:
    """The three path polynomials of one thesis dataset (KES units).

    Attributes
    ----------
    loading, unloading, reverse_unloading : tuple of float
        Coefficients of x^4 … x^0, exactly as printed.
    tables : tuple of str
        The thesis tables they come from.
    """

    loading: tuple
    unloading: tuple
    reverse_unloading: tuple
    tables: tuple

    def paths(self):
        """The three coefficient tuples in path order 0, 1, 2."""
        return (self.loading, self.unloading, self.reverse_unloading)


THESIS_POLYNOMIALS = {
    "fabric1-warp": PathPolynomials(
        loading=(-1.034e-18, -2.744e-5, 3.898e-5, 1.212e-2, 1.716e-18),  # Table B.1
        unloading=(2.956e-4, 1.022e-3, -7.164e-4, 6.131e-3, 2.950e-3),  # Table B.2
        reverse_unloading=(-2.287e-3, -6.208e-3, -6.022e-3, 3.605e-3, 1.923e-3),  # Table B.3
        tables=("B.1", "B.2", "B.3"),
    ),
    "fabric1-weft": PathPolynomials(
        loading=(-9.201e-19, -2.028e-4, 3.779e-18, 8.059e-3, -3.219e-18),  # Table B.4
        unloading=(2.240e-4, 4.910e-4, -4.607e-4, 3.165e-3, -1.368e-3),  # Table B.5
        reverse_unloading=(-4.661e-4, -1.096e-3, -4.812e-4, 3.982e-3, 8.17e-4),  # Table B.6
        tables=("B.4", "B.5", "B.6"),
    ),
    "fabric2-warp": PathPolynomials(
        loading=(4.697e-18, -1.114e-3, -9.870e-18, 2.558e-2, 9.126e-21),  # Table B.7
        unloading=(1.193e-3, 1.706e-3, -3.808e-3, 9.244e-3, -6.849e-3),  # Table B.8
        reverse_unloading=(-5.485e-3, -1.789e-2, -1.911e-2, 3.703e-3, 5.482e-3),  # Table B.9
        tables=("B.7", "B.8", "B.9"),
    ),
    "fabric2-weft": PathPolynomials(
        loading=(-7.839e-19, -2.793e-4, 2.155e-18, 6.759e-3, -9.275e-19),  # Table B.10
        unloading=(1.996e-4, 4.785e-4, -1.003e-3, 4.132e-3, -3.115e-3),  # Table B.11
        reverse_unloading=(-2.112e-3, -6.842e-3, -8.550e-3, -3.615e-4, 1.329e-3),  # Table B.12
        tables=("B.10", "B.11", "B.12"),
    ),
}
DATASET_NAMES = tuple(THESIS_POLYNOMIALS)

KES_RATE = 0.5  # cm^-1/s, the KES-FB2 standard bending rate [Kaw80]
BRANCH_NAMES = ("loading", "unloading/reverse loading", "reverse unloading")


class KESDataError(ValueError):
    """Bad measured data; ``line`` is the 1-based CSV line number (or None)."""

    def __init__(self, message, line=None, path=None):
        self.line = line
        self.path = path
        where = f"line {line}: " if line is not None else ""
        super().__init__(where + message)


# ---------------------------------------------------------------------------
# Sampled loops
# ---------------------------------------------------------------------------


@dataclass
class KESLoop:
    """A KES-FB loop sampled along the machine profile (SI units).

    Attributes
    ----------
    name : str
    time, kappa, kappa_rate, kappa_accel : ndarray
        Machine profile samples [s, 1/m, 1/(m·s), 1/(m·s²)].
    moment : ndarray
        Measured moment per unit width at the same instants [N·m/m].
    branch : ndarray of int
        Path index of each sample: 0 loading, 1 unloading + reverse loading,
        2 reverse unloading.
    accel_time, rate : float
        Profile parameters used [s, 1/(m·s)].
    decelerate_at_end : bool
    """

    name: str
    time: np.ndarray
    kappa: np.ndarray
    kappa_rate: np.ndarray
    kappa_accel: np.ndarray
    moment: np.ndarray
    branch: np.ndarray
    accel_time: float
    rate: float
    decelerate_at_end: bool = True


@dataclass
class BranchCurves:
    """Measured moment as a function of curvature on each path of a KES loop.

    Parameters
    ----------
    name : str
    k_plus, k_minus : float
        Turning curvatures [1/m].
    rate : float
        Constant curvature rate of the test [1/(m·s)].
    branch_moment : callable
        ``branch_moment(branch, kappa) -> moment`` in SI, ``branch`` in {0, 1, 2}.
    points : tuple of ndarray, optional
        The raw measured (kappa, moment, branch) points, for plotting.
    source : str
        Where the data come from (for reports).
    """

    name: str
    k_plus: float
    k_minus: float
    rate: float
    branch_moment: object
    points: tuple | None = None
    source: str = ""
    _cache: dict = field(default_factory=dict, repr=False)

    def sample(self, accel_time, decelerate_at_end=True, dt=1e-3):
        """Lay the measured moment along the machine profile every ``dt``.

        Parameters
        ----------
        accel_time : float
            Acceleration time T of each ramp [s].
        decelerate_at_end : bool
            False gives the thesis's "no deceleration at end" variant.
        dt : float
            Sampling interval [s]; the thesis uses 1 ms.

        Returns
        -------
        KESLoop
        """
        key = (float(accel_time), bool(decelerate_at_end), float(dt))
        if key in self._cache:
            return self._cache[key]
        prof = kes_profile(dt, rate=self.rate, accel_time=accel_time, k_max=self.k_plus,
                           k_min=self.k_minus, decelerate_at_end=decelerate_at_end)
        t, kappa, rate, accel = prof.t, prof.kappa, prof.kappa_dot, prof.kappa_ddot
        branch = prof.phase - 1
        moment = np.empty_like(kappa)
        for b in range(3):
            sel = branch == b
            moment[sel] = self.branch_moment(b, kappa[sel])
        loop = KESLoop(self.name, t, kappa, rate, accel, moment, branch,
                       float(accel_time), float(self.rate), bool(decelerate_at_end))
        self._cache[key] = loop
        return loop


# ---------------------------------------------------------------------------
# Thesis datasets
# ---------------------------------------------------------------------------


def _real_root_nearest(coeffs, target):
    roots = np.roots(coeffs)
    real = roots[np.abs(roots.imag) < 1e-9 * max(1.0, np.abs(roots).max())].real
    if real.size == 0:
        raise KESDataError(f"neighbouring path polynomials never meet (target {target})")
    return float(real[np.argmin(np.abs(real - target))])


def turning_points(polys, near=2.5):
    """K+ and K− [cm⁻¹] where neighbouring path polynomials meet.

    K+ is the real root of ``loading − unloading`` nearest ``+near`` and K− the
    real root of ``unloading − reverse_unloading`` nearest ``−near``: the
    measured moment is continuous where the machine reverses.

    >>> kp, km = turning_points(THESIS_POLYNOMIALS["fabric2-warp"])
    >>> round(kp, 3), round(km, 3)
    (2.253, -2.241)
    """
    load, unload, rev = (np.asarray(p, dtype=float) for p in polys.paths())
    return _real_root_nearest(load - unload, near), _real_root_nearest(unload - rev, -near)


def thesis_dataset(name):
    """One of Deng's loops as the thesis's polynomials (Tables B.1–B.12).

    Parameters
    ----------
    name : {'fabric1-warp', 'fabric1-weft', 'fabric2-warp', 'fabric2-weft'}

    Returns
    -------
    BranchCurves
        Measured moment per path in SI, K± from :func:`turning_points`, rate
        0.5 cm⁻¹/s.
    """
    if name not in THESIS_POLYNOMIALS:
        raise KESDataError(f"dataset {name!r} is not one of {', '.join(DATASET_NAMES)}")
    polys = THESIS_POLYNOMIALS[name]
    kp, km = turning_points(polys)
    coeffs = [np.asarray(p, dtype=float) for p in polys.paths()]

    def branch_moment(branch, kappa):
        return np.polyval(coeffs[branch], np.asarray(kappa) / CURVATURE_KES) * MOMENT_KES

    return BranchCurves(name, kp * CURVATURE_KES, km * CURVATURE_KES, KES_RATE * CURVATURE_KES,
                        branch_moment,
                        source=f"Lahey (2002) Tables {', '.join(polys.tables)} (Deng 1994 data)")


# ---------------------------------------------------------------------------
# CSV export of a KES-FB instrument
# ---------------------------------------------------------------------------

_COLUMNS = ("curvature", "moment", "time")
_DEFAULT_UNITS = {
    "kes": {"curvature": "1/cm", "moment": "gf*cm/cm", "time": "s"},
    "si": {"curvature": "1/m", "moment": "N*m/m", "time": "s"},
}
_HEADER_RE = re.compile(r"^\s*([A-Za-z_]+)\s*(?:[\[(](.*)[\])])?\s*$")


def _unit_factor(unit, quantity, line, path):
    try:
        return _factor_to_si(unit, quantity)
    except ValueError as exc:
        raise KESDataError(f"{quantity} unit {unit!r}: {exc}", line, path) from None


def _parse_header(cells, units, line, path):
    names, unit_of = [], {}
    for cell in cells:
        m = _HEADER_RE.match(cell)
        name = m.group(1).lower() if m else cell.strip()
        if name not in _COLUMNS:
            raise KESDataError(f"unknown column {cell.strip()!r}; expected curvature, "
                               f"moment[, time]", line, path)
        if name in names:
            raise KESDataError(f"column {name!r} appears twice", line, path)
        names.append(name)
        if m and m.group(2):
            unit_of[name] = m.group(2).strip()
    for needed in ("curvature", "moment"):
        if needed not in names:
            raise KESDataError(f"missing column {needed!r}", line, path)
    factors = {n: _unit_factor(unit_of.get(n, _DEFAULT_UNITS[units][n]), n, line, path)
               for n in names}
    return names, factors


def load_kes_csv(path, units="kes", smooth=None, name=None):
    """Read a KES-FB export (curvature, moment[, time]) into :class:`BranchCurves`.

    File format: ``#`` comment lines anywhere; an optional header line naming
    the columns ``curvature``, ``moment`` and optionally ``time`` in any order,
    each optionally with a unit in brackets (``curvature [1/cm]``,
    ``moment [gf*cm/cm]``, ``time [s]``, any pint unit of the right dimension);
    without a header the columns are curvature, moment[, time].  Columns without
    a unit take the units of ``units``: ``"kes"`` (cm⁻¹, gf·cm/cm, s, the
    default) or ``"si"`` (1/m, N·m/m, s).  Commas, semicolons, tabs or blanks
    separate fields.

    The rows must form one KES cycle 0 → K+ → K− → 0; the paths are found by
    :func:`detect_branches`.  The test rate is taken from the time column when
    present (median |dκ/dt| on the constant-rate parts), else 0.5 cm⁻¹/s.

    Raises
    ------
    KESDataError
        Naming the line: ``line 17: moment 'abc' is not a number``.
    """
    path = Path(path)
    if units not in _DEFAULT_UNITS:
        raise KESDataError(f"units must be 'kes' or 'si', got {units!r}")
    try:
        text = path.read_text()
    except OSError as exc:
        raise KESDataError(f"cannot read {path}: {exc.strerror}", path=path) from None
    rows, lines, names, factors = [], [], None, None
    for lineno, raw in enumerate(text.splitlines(), start=1):
        stripped = raw.strip()
        if not stripped or stripped.startswith("#"):
            continue
        cells = _split(stripped)
        if names is None and not _looks_numeric(cells[0]):
            names, factors = _parse_header(_split_header(stripped), units, lineno, path)
            continue
        if names is None:  # headerless file
            if len(cells) not in (2, 3):
                raise KESDataError(f"expected 2 or 3 columns (curvature, moment[, time]), "
                                   f"got {len(cells)}", lineno, path)
            names = list(_COLUMNS[:len(cells)])
            factors = {n: _unit_factor(_DEFAULT_UNITS[units][n], n, lineno, path) for n in names}
        if len(cells) != len(names):
            raise KESDataError(f"expected {len(names)} columns ({', '.join(names)}), "
                               f"got {len(cells)}", lineno, path)
        values = []
        for col, cell in zip(names, cells):
            try:
                v = float(cell)
            except ValueError:
                raise KESDataError(f"{col} {cell!r} is not a number", lineno, path) from None
            if not math.isfinite(v):
                raise KESDataError(f"{col} {cell!r} is not finite", lineno, path)
            values.append(v * factors[col])
        rows.append(values)
        lines.append(lineno)
    if len(rows) < 10:
        raise KESDataError(f"{path}: {len(rows)} data rows; a KES loop needs at least 10",
                           path=path)
    data = np.asarray(rows)
    col = {n: data[:, i] for i, n in enumerate(names)}
    if "time" in col:
        dt = np.diff(col["time"])
        bad = np.flatnonzero(dt <= 0)
        if bad.size:
            i = bad[0] + 1
            raise KESDataError(f"time {col['time'][i]:g} s does not increase (previous row "
                               f"{col['time'][i - 1]:g} s)", lines[i], path)
    kappa, moment = col["curvature"], col["moment"]
    branch = detect_branches(kappa, smooth=smooth)
    rate = _measured_rate(kappa, col.get("time"))
    return _curves_from_points(name or path.stem, kappa, moment, branch, rate, source=str(path))


def _split(line):
    """Fields of a data line: comma, semicolon or tab separated, else blanks."""
    if re.search(r"[,;\t]", line):
        cells = [c.strip() for c in re.split(r"[,;\t]", line)]
        while cells and cells[-1] == "":  # tolerate a trailing separator
            cells.pop()
        return cells
    return line.split()


def _split_header(line):
    """Header fields; blank-separated headers may carry units: ``curvature [1/cm]``."""
    if re.search(r"[,;\t]", line):
        return _split(line)
    return re.findall(r"[^\s\[(]+\s*(?:\[[^\]]*\]|\([^)]*\))?", line)


def _looks_numeric(cell):
    try:
        float(cell)
        return True
    except ValueError:
        return cell.strip().lower() in ("nan", "inf", "-inf")


def _measured_rate(kappa, time):
    if time is None:
        return KES_RATE * CURVATURE_KES
    rate = np.abs(np.diff(kappa) / np.diff(time))
    # the constant-rate parts dominate a KES cycle; the median ignores ramps and noise
    return float(np.median(rate))


def detect_branches(kappa, smooth=None, tol=None):
    """Path index (0, 1, 2) of each measured point of a 0 → K+ → K− → 0 cycle.

    A reversal is accepted only once the curvature has retreated from its
    running extreme by more than ``tol`` (default 5 % of the curvature range),
    so measurement noise — which makes dκ change sign between neighbouring
    points — does not create spurious paths.  The curvature is first smoothed
    with a running median of ``smooth`` points (default: 1 % of the points,
    odd, at least 1).

    Parameters
    ----------
    kappa : array_like
        Measured curvature, in measurement order.
    smooth : int, optional
    tol : float, optional
        Reversal threshold in the units of ``kappa``.

    Returns
    -------
    ndarray of int
        0 up to the K+ turning point (inclusive), 1 to K− (inclusive), 2 after.

    Raises
    ------
    KESDataError
        If the points do not form exactly one positive-first KES cycle.

    Examples
    --------
    >>> k = np.concatenate([np.linspace(0, 2.5, 6), np.linspace(2.0, -2.5, 10),
    ...                     np.linspace(-2.0, 0, 5)])
    >>> k = k + 0.01 * np.sin(np.arange(k.size) * 2.0)  # noise
    >>> detect_branches(k).tolist() == [0] * 6 + [1] * 10 + [2] * 5
    True
    """
    kappa = np.asarray(kappa, dtype=float)
    n = kappa.size
    if smooth is None:
        smooth = max(1, int(0.01 * n) | 1)
    k = _running_median(kappa, smooth)
    span = float(k.max() - k.min())
    if span <= 0:
        raise KESDataError("curvature never changes; not a KES loop")
    tol = 0.05 * span if tol is None else float(tol)
    turns, direction, i_ext = [], 0, 0
    for i in range(1, n):
        if direction == 0:  # still at rest: wait for a clear first move
            if k[i] - k[0] > tol:
                direction, i_ext = 1, i
            elif k[0] - k[i] > tol:
                raise KESDataError("the loop starts with negative curvature; a KES cycle "
                                   "bends to K+ first (flip the signs of both columns)")
        elif direction * (k[i] - k[i_ext]) > 0:  # still moving away: new extreme
            i_ext = i
        elif direction * (k[i_ext] - k[i]) > tol:  # retreated beyond noise: a reversal
            turns.append(i_ext)
            direction, i_ext = -direction, i
    if direction == 0:
        raise KESDataError("curvature never rises above the noise threshold; not a KES loop")
    if len(turns) != 2:
        raise KESDataError(f"found {len(turns)} reversal(s) of the curvature rate; a KES "
                           "cycle 0 -> K+ -> K- -> 0 has exactly 2")
    # the smoothed extreme locates the turn; take the raw extreme nearby
    half = max(1, smooth)
    i_p = _local_arg(kappa, turns[0], half, np.argmax)
    i_m = _local_arg(kappa, turns[1], half, np.argmin)
    branch = np.zeros(n, dtype=int)
    branch[i_p + 1:] = 1
    branch[i_m + 1:] = 2
    return branch


def _local_arg(x, i, half, arg):
    lo, hi = max(0, i - half), min(x.size, i + half + 1)
    return lo + int(arg(x[lo:hi]))


def _running_median(x, width):
    if width <= 1:
        return x.copy()
    from scipy.ndimage import median_filter

    return median_filter(x, size=width, mode="nearest")


def _curves_from_points(name, kappa, moment, branch, rate, source):
    """BranchCurves interpolating measured points per path (SI)."""
    k_plus = float(kappa[branch == 0].max())
    k_minus = float(kappa[branch == 1].min())
    tables = []
    for b in range(3):
        kb, mb = kappa[branch == b], moment[branch == b]
        order = np.argsort(kb, kind="stable")
        kb, mb = kb[order], mb[order]
        # average duplicate curvatures so np.interp sees a function
        uniq, inv = np.unique(kb, return_inverse=True)
        mean = np.bincount(inv, weights=mb) / np.bincount(inv)
        tables.append((uniq, mean))

    def branch_moment(b, k):
        kb, mb = tables[b]
        return np.interp(k, kb, mb)

    return BranchCurves(name, k_plus, k_minus, rate, branch_moment,
                        points=(kappa, moment, branch), source=source)


def write_kes_csv(path, kappa, moment, time=None, comment="", units="kes"):
    """Write a KES-FB style CSV (curvature, moment[, time]) readable by :func:`load_kes_csv`.

    ``kappa``, ``moment``, ``time`` are SI; they are written in ``units``.
    """
    u = _DEFAULT_UNITS[units]
    fk = 1.0 / _factor_to_si(u["curvature"], "curvature")
    fm = 1.0 / _factor_to_si(u["moment"], "moment")
    with open(path, "w", newline="") as fh:
        for line in comment.splitlines():
            fh.write(f"# {line}\n".replace("# \n", "#\n"))
        w = csv.writer(fh)
        header = [f"curvature [{u['curvature']}]", f"moment [{u['moment']}]"]
        if time is not None:
            header.append("time [s]")
        w.writerow(header)
        for i in range(len(kappa)):
            row = [f"{kappa[i] * fk:.5f}", f"{moment[i] * fm:.6e}"]
            if time is not None:
                row.append(f"{time[i]:.3f}")
            w.writerow(row)


def load_dataset(name_or_path, units="kes"):
    """A thesis dataset by name, or a KES CSV export by path."""
    if name_or_path in THESIS_POLYNOMIALS:
        return thesis_dataset(name_or_path)
    p = Path(name_or_path)
    if p.suffix.lower() in (".csv", ".txt") or p.exists():
        return load_kes_csv(p, units=units)
    raise KESDataError(f"{name_or_path!r} is neither a thesis dataset "
                       f"({', '.join(DATASET_NAMES)}) nor an existing CSV file")


# ---------------------------------------------------------------------------
# Example export (simulated): python -m constitutive.datasets example OUT.csv
# ---------------------------------------------------------------------------


def simulated_export(law, *, every=0.05, accel_time=0.5, k_max=2.5, k_min=-2.5,
                     noise_kappa=0.005, noise_moment=2e-4, seed=0):
    """A KES-FB-like export of a simulated law, with measurement noise (SI out).

    The law runs through :func:`constitutive.kes.run_kes` on a 1 ms profile
    (K± in cm⁻¹ here); every ``every`` seconds a row is kept and Gaussian noise
    of standard deviation ``noise_kappa`` [cm⁻¹] and ``noise_moment``
    [gf·cm/cm] is added.

    Returns
    -------
    time, kappa, moment : ndarray
    """
    from constitutive.kes import run_kes

    prof = kes_profile(1e-3, accel_time=accel_time, k_max=k_max * CURVATURE_KES,
                       k_min=k_min * CURVATURE_KES, include_turning_points=False)
    loop = run_kes(law, prof)
    step = int(round(every / 1e-3))
    keep = np.arange(0, prof.t.size, step)
    rng = np.random.default_rng(seed)
    kappa = prof.kappa[keep] + rng.normal(0.0, noise_kappa * CURVATURE_KES, keep.size)
    moment = loop.moment[keep] + rng.normal(0.0, noise_moment * MOMENT_KES, keep.size)
    return prof.t[keep], kappa, moment


def _main(argv=None):
    import argparse

    p = argparse.ArgumentParser(
        prog="python -m constitutive.datasets",
        description="Thesis datasets (K± and tables) and a simulated example KES-FB CSV export.")
    sub = p.add_subparsers(dest="cmd", required=True)
    sub.add_parser("list", help="list the thesis datasets with their turning points")
    ex = sub.add_parser("example", help="write a simulated, noisy KES-FB export (Fabric 1 weft, "
                        "thesis Table 4.7 parameters)")
    ex.add_argument("out", help="CSV file to write")
    ex.add_argument("--seed", type=int, default=0)
    args = p.parse_args(argv)
    if args.cmd == "list":
        for n in DATASET_NAMES:
            kp, km = turning_points(THESIS_POLYNOMIALS[n])
            print(f"{n:14s} K+ = {kp:6.3f}  K- = {km:6.3f} cm^-1   "
                  f"Tables {', '.join(THESIS_POLYNOMIALS[n].tables)}")
        return 0
    from constitutive.fit import thesis_law

    law = thesis_law("fabric1-weft")
    t, k, m = simulated_export(law, seed=args.seed)
    write_kes_csv(args.out, k, m, t, comment=(
        "SIMULATED example of a KES-FB pure-bending export - not a measurement.\n"
        "Generated by `python -m constitutive.datasets example` (fabric-drape): the thesis's\n"
        "Fabric 1 weft law (Lahey 2002, Table 4.7: k1 4.548e-3, k3 1.619e-4, d 2.141e-3,\n"
        "f1 0.2173, f2 0.2161, eps_f 0.7316, eta 0.9876; m = 0) run through the KES-FB profile\n"
        "0 -> +2.5 -> -2.5 -> 0 1/cm at 0.5 1/cm/s, T = 0.5 s; one row every 50 ms;\n"
        f"Gaussian noise sd 0.005 1/cm on curvature and 2e-4 gf*cm/cm on moment (seed {args.seed}).\n"
        "Columns: curvature, moment per unit width, time."))
    print(f"wrote {args.out} ({t.size} rows)")
    return 0


if __name__ == "__main__":
    raise SystemExit(_main())
