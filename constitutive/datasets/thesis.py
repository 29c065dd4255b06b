"""Deng's KES-FB loops as the thesis's path polynomials (B.1–B.12), and the loop containers.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from constitutive import units as _units
from constitutive.kes import kes_profile

__all__ = ['CURVATURE_KES', 'MOMENT_KES', 'THESIS_POLYNOMIALS', 'DATASET_NAMES', 'KES_RATE', 'PathPolynomials', 'KESLoop', 'BranchCurves', 'KESDataError', 'turning_points', 'thesis_dataset']


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
