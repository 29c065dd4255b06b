"""KES-FB instrument exports as CSV: read (units, branches), write, and a simulated export.
"""
from __future__ import annotations

import csv
import math
import re
from pathlib import Path

import numpy as np

from constitutive.datasets.thesis import (
    CURVATURE_KES,
    DATASET_NAMES,
    KES_RATE,
    MOMENT_KES,
    THESIS_POLYNOMIALS,
    BranchCurves,
    KESDataError,
    _factor_to_si,
    thesis_dataset,
)
from constitutive.kes import kes_profile, run_kes

__all__ = ['detect_branches', 'load_kes_csv', 'write_kes_csv', 'load_dataset', 'simulated_export']


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
    present (median ``|dκ/dt|`` on the constant-rate parts), else 0.5 cm⁻¹/s.

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
    prof = kes_profile(1e-3, accel_time=accel_time, k_max=k_max * CURVATURE_KES,
                       k_min=k_min * CURVATURE_KES, include_turning_points=False)
    loop = run_kes(law, prof)
    step = int(round(every / 1e-3))
    keep = np.arange(0, prof.t.size, step)
    rng = np.random.default_rng(seed)
    kappa = prof.kappa[keep] + rng.normal(0.0, noise_kappa * CURVATURE_KES, keep.size)
    moment = loop.moment[keep] + rng.normal(0.0, noise_moment * MOMENT_KES, keep.size)
    return prof.t[keep], kappa, moment
