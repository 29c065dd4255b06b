"""The KES-FB pure bending test: motion profile, driver and characteristic values.

Profile (thesis Sec. 4.2.1, App. B.3).  Three phases 0 → K+ → K− → 0, each
made of three regions: accelerate from rest over the time T with
``κ̈ = 6 v τ (T − τ)/T³`` (Eq. 4.9 is the v = 0.5 cm⁻¹/s case), run at the
constant rate v, decelerate symmetrically to rest at the target.  Each ramp
covers ``v T / 2`` of curvature.  In the "no deceleration at end" variant the
last phase keeps the rate v until κ = 0 (regions 1–8 only).

Characteristic values (docs/theory.md §3).  ``B``: mean slope of M(κ) over
0.5 ≤ |κ| ≤ 1.5 cm⁻¹; ``2HB``: loop width at |κ| = 1 cm⁻¹; each averaged over
the positive and negative sides.

All quantities SI: κ [1/m], t [s], M [N·m/m], B [N·m], 2HB [N·m/m].

>>> prof = kes_profile(dt=1e-3)
>>> float(prof.t[-1]), float(prof.kappa.max()), float(prof.kappa.min())
(21.5, 250.0, -250.0)
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from constitutive.friction import ParameterError, friction_path
from constitutive.law import BendingLaw

__all__ = [
    "DEFAULT_RATE", "DEFAULT_ACCEL_TIME", "DEFAULT_K_MAX", "DEFAULT_K_MIN",
    "KesProfile", "kes_profile", "KesLoop", "run_kes", "KesValues", "kes_values",
]

DEFAULT_RATE = 50.0          # 1/m/s  (0.5 cm⁻¹/s, Kawabata)
DEFAULT_ACCEL_TIME = 0.5     # s; an equipment constant the thesis does not print: our choice
DEFAULT_K_MAX = 250.0        # 1/m  (+2.5 cm⁻¹, standard KES-FB range)
DEFAULT_K_MIN = -250.0       # 1/m  (−2.5 cm⁻¹)


@dataclass(frozen=True, eq=False)
class KesProfile:
    """Sampled KES-FB motion: time, κ, κ̇, κ̈ and the region (1–9) of each sample."""

    t: np.ndarray
    kappa: np.ndarray
    kappa_dot: np.ndarray
    kappa_ddot: np.ndarray
    region: np.ndarray
    rate: float
    accel_time: float
    k_max: float
    k_min: float
    decelerate_at_end: bool
    phase_times: np.ndarray = field(repr=False)   # start of phases 1–3 and end of the test

    @property
    def phase(self):
        """Phase of each sample: 1 loading to K+, 2 to K−, 3 back to 0."""
        return (self.region - 1) // 3 + 1

    def __len__(self):
        return self.t.size


def _ramp(tau, v, T):
    """Acceleration ramp from rest: position, rate, acceleration at τ ∈ [0, T]."""
    T3 = T ** 3
    return (v * tau ** 3 * (T - 0.5 * tau) / T3,
            v * tau ** 2 * (3.0 * T - 2.0 * tau) / T3,
            6.0 * v * tau * (T - tau) / T3)


def _phase(tau, dist, v, T, decelerate):
    """Unsigned motion of one phase covering ``dist`` at local times ``tau``."""
    duration = dist / v + (T if decelerate else 0.5 * T)
    x_acc, v_acc, a_acc = _ramp(np.minimum(tau, T), v, T)
    x = np.where(tau < T, x_acc, 0.5 * v * T + v * (tau - T))
    rate = np.where(tau < T, v_acc, v)
    acc = np.where(tau < T, a_acc, 0.0)
    region = np.where(tau < T, 1, 2)
    if decelerate:
        r = np.clip(duration - tau, 0.0, T)
        x_dec, v_dec, a_dec = _ramp(r, v, T)
        dec = tau > duration - T
        x = np.where(dec, dist - x_dec, x)
        rate = np.where(dec, v_dec, rate)
        acc = np.where(dec, -a_dec, acc)
        region = np.where(dec, 3, region)
    return x, rate, acc, region


def kes_profile(dt=1e-3, *, t=None, rate=DEFAULT_RATE, accel_time=DEFAULT_ACCEL_TIME,
                k_max=DEFAULT_K_MAX, k_min=DEFAULT_K_MIN, decelerate_at_end=True,
                include_turning_points=True) -> KesProfile:
    """The nine-region KES-FB curvature history 0 → K+ → K− → 0.

    Parameters
    ----------
    dt : float
        Sampling interval [s] (ignored if ``t`` is given).
    t : array_like, optional
        Sample times [s] within ``[0, total duration]``.
    rate : float
        Constant curvature rate v [1/m/s] (default 0.5 cm⁻¹/s).
    accel_time : float
        Acceleration (and deceleration) time T [s].
    k_max, k_min : float
        Turning curvatures K+ > 0 > K− [1/m].
    decelerate_at_end : bool
        False: the last phase keeps the rate v until κ = 0 (no region 9).
    include_turning_points : bool
        Add the phase boundary times (rest at K+ and K−) to a ``dt`` grid so
        the path between two samples is always monotone.

    Returns
    -------
    KesProfile

    Raises
    ------
    ParameterError
        Non-positive rate or T, K+ ≤ 0 ≤ K−, or a phase too short to reach
        the rate v (needs ``|ΔK| ≥ v T``).

    Examples
    --------
    >>> p = kes_profile(dt=0.01, accel_time=1.0)
    >>> float(p.kappa[p.t == 1.0][0])      # each ramp covers v T / 2
    25.0
    >>> p.region[[0, 150, -1]]
    array([1, 2, 9])
    >>> q = kes_profile(dt=0.01, decelerate_at_end=False)
    >>> float(q.kappa_dot[-1]), int(q.region.max())
    (50.0, 8)
    """
    v, T = float(rate), float(accel_time)
    if not v > 0:
        raise ParameterError(f"rate = {rate} breaks rate > 0")
    if not T > 0:
        raise ParameterError(f"accel_time = {accel_time} breaks accel_time > 0")
    if not k_max > 0:
        raise ParameterError(f"k_max = {k_max} breaks k_max > 0")
    if not k_min < 0:
        raise ParameterError(f"k_min = {k_min} breaks k_min < 0")
    targets = [(0.0, float(k_max)), (float(k_max), float(k_min)), (float(k_min), 0.0)]
    decel = [True, True, bool(decelerate_at_end)]
    names = ["k_max", "k_max - k_min", "-k_min"]
    durations = []
    for (a, b), dec, name in zip(targets, decel, names):
        need = v * T if dec else 0.5 * v * T
        if abs(b - a) < need:
            raise ParameterError(
                f"{name} = {abs(b - a):g} 1/m breaks {name} >= {'v T' if dec else 'v T / 2'} = {need:g} 1/m "
                "(the ramps would not reach the constant rate)")
        durations.append(abs(b - a) / v + (T if dec else 0.5 * T))
    phase_times = np.concatenate(([0.0], np.cumsum(durations)))
    t_end = phase_times[-1]
    if t is None:
        n = int(np.floor(t_end / dt + 1e-9))
        t = dt * np.arange(n + 1)
        extra = [x for x in (phase_times[1:] if include_turning_points else phase_times[-1:])
                 if np.min(np.abs(t - x)) > 1e-9 * max(dt, 1.0)]
        t = np.sort(np.concatenate((t, extra)))
    t = np.asarray(t, dtype=float)
    if t.size and (t.min() < -1e-12 or t.max() > t_end * (1 + 1e-12)):
        raise ParameterError(f"t must lie within [0, {t_end:g}] s (the test duration)")
    ph = np.clip(np.searchsorted(phase_times, t, side="right") - 1, 0, 2)
    kappa = np.empty_like(t)
    kdot = np.empty_like(t)
    kddot = np.empty_like(t)
    region = np.empty(t.shape, dtype=int)
    for i, ((a, b), dec) in enumerate(zip(targets, decel)):
        sel = ph == i
        x, r, acc, reg = _phase(t[sel] - phase_times[i], abs(b - a), v, T, dec)
        s = np.sign(b - a)
        kappa[sel], kdot[sel], kddot[sel] = a + s * x, s * r, s * acc
        region[sel] = 3 * i + reg
    return KesProfile(t, kappa, kdot, kddot, region, v, T, float(k_max), float(k_min),
                      bool(decelerate_at_end), phase_times)


@dataclass(frozen=True, eq=False)
class KesLoop:
    """A simulated KES-FB loop and the separate contributions to its moment.

    ``moment = inertial + viscous + elastic + friction`` [N·m/m]; with array
    law parameters of shape ``(n_p, 1)`` every moment array is ``(n_p, n)``.
    """

    t: np.ndarray
    kappa: np.ndarray
    moment: np.ndarray
    friction: np.ndarray
    elastic: np.ndarray
    viscous: np.ndarray
    inertial: np.ndarray


def run_kes(law: BendingLaw, profile: KesProfile | None = None) -> KesLoop:
    """Run a bending law through a KES-FB profile from rest.

    The friction part uses the exact path solution
    (:func:`constitutive.friction.friction_path`), equal to stepping a
    :class:`~constitutive.law.BendingState` sample by sample.

    Examples
    --------
    >>> loop = run_kes(BendingLaw(k1=1e-4, d=1e-6), kes_profile(dt=1e-2))
    >>> B, HB2 = kes_values(loop.kappa, loop.moment)
    >>> round(B, 10), round(HB2, 10)                # 2HB = 2 d v for a viscous law
    (0.0001, 0.0001)
    """
    prof = kes_profile() if profile is None else profile
    k = prof.kappa
    elastic, _ = law.elastic(k)
    if law.friction is not None:
        friction = friction_path(law.friction, k)
    else:
        friction = np.zeros_like(elastic)
    viscous = np.asarray(law.d) * prof.kappa_dot
    inertial = np.asarray(law.m) * prof.kappa_ddot
    shape = np.broadcast_shapes(elastic.shape, friction.shape, viscous.shape, inertial.shape)
    parts = [np.broadcast_to(x, shape) for x in (friction, elastic, viscous, inertial)]
    return KesLoop(prof.t, k, parts[0] + parts[1] + parts[2] + parts[3], *parts)


@dataclass(frozen=True)
class KesValues:
    """KES characteristic values (SI); unpacks as ``B, HB2 = values``.

    ``B_pos``/``B_neg`` and ``HB2_pos``/``HB2_neg`` are the per-side values
    (``nan`` for a side not measured).
    """

    B: float
    HB2: float
    B_pos: float
    B_neg: float
    HB2_pos: float
    HB2_neg: float

    def __iter__(self):
        return iter((self.B, self.HB2))


def _branch_slope(kappa, moment, mask, what):
    if np.count_nonzero(mask) < 2:
        raise ValueError(f"kes_values: fewer than two samples on the {what} within the slope window")
    return float(np.polyfit(kappa[mask], moment[mask], 1)[0])


def _crossings(kappa, moment, level, direction):
    """Moment where segments moving in ``direction`` cross ``kappa == level``."""
    k0, k1 = kappa[:-1], kappa[1:]
    seg = (np.sign(k1 - k0) == direction) & ((k0 - level) * (k1 - level) <= 0) & (k0 != k1)
    w = (level - k0[seg]) / (k1[seg] - k0[seg])
    return moment[:-1][seg] * (1 - w) + moment[1:][seg] * w


def kes_values(kappa, moment, *, slope_window=(50.0, 150.0), width_at=100.0, sides="both") -> KesValues:
    """B and 2HB of a measured or simulated moment–curvature loop (SI).

    Branches are split by the sign of dκ.  On each side, ``B`` is the mean of
    the least-squares slopes of the increasing and decreasing branches over
    ``slope_window[0] ≤ |κ| ≤ slope_window[1]`` (least squares rather than a
    secant so that measured noise averages out; for a straight branch they
    agree); ``2HB`` is ``M_increasing − M_decreasing`` at ``|κ| = width_at``
    (interpolated, averaged over repeated passes).  The two sides are
    averaged.

    Parameters
    ----------
    kappa, moment : array_like, shape (n,)
        Samples in time order [1/m], [N·m/m].
    slope_window : (float, float)
        |κ| range for B [1/m] (default 0.5–1.5 cm⁻¹).
    width_at : float
        |κ| for 2HB [1/m] (default 1 cm⁻¹).
    sides : {"both", "positive", "negative"}
        Which sides to use.

    Returns
    -------
    KesValues
        ``B`` [N·m] and ``HB2`` (= 2HB) [N·m/m].

    Examples
    --------
    Linear spring plus Coulomb friction: B = k1, 2HB = 2 f_c.

    >>> p = kes_profile(dt=0.01)
    >>> M = 2e-4 * p.kappa + 3e-3 * np.sign(p.kappa_dot)
    >>> v = kes_values(p.kappa, M)
    >>> round(v.B, 12), round(v.HB2, 12)
    (0.0002, 0.006)
    """
    kappa = np.asarray(kappa, dtype=float)
    moment = np.asarray(moment, dtype=float)
    if kappa.shape != moment.shape or kappa.ndim != 1:
        raise ValueError(f"kappa and moment must be 1-D of equal length, got {kappa.shape} and {moment.shape}")
    if sides not in ("both", "positive", "negative"):
        raise ValueError(f"sides = {sides!r} must be 'both', 'positive' or 'negative'")
    lo, hi = slope_window
    direction = np.sign(np.gradient(kappa))
    res = {}
    for name, sgn in (("pos", 1.0), ("neg", -1.0)):
        if (sides == "positive" and sgn < 0) or (sides == "negative" and sgn > 0):
            res[name] = (np.nan, np.nan)
            continue
        ka = sgn * kappa
        window = (ka >= lo) & (ka <= hi)
        side = "positive" if sgn > 0 else "negative"
        slopes = [_branch_slope(kappa, moment, window & (direction == d),
                                f"{'increasing' if d > 0 else 'decreasing'}-κ branch, {side} side")
                  for d in (1.0, -1.0)]
        up = _crossings(kappa, moment, sgn * width_at, 1.0)
        down = _crossings(kappa, moment, sgn * width_at, -1.0)
        if up.size == 0 or down.size == 0:
            which = "increasing" if up.size == 0 else "decreasing"
            raise ValueError(f"kes_values: the {which}-κ branch never crosses κ = {sgn * width_at:g} 1/m")
        res[name] = (0.5 * (slopes[0] + slopes[1]), float(up.mean() - down.mean()))
    B = float(np.nanmean([res["pos"][0], res["neg"][0]]))
    HB2 = float(np.nanmean([res["pos"][1], res["neg"][1]]))
    return KesValues(B, HB2, res["pos"][0], res["neg"][0], res["pos"][1], res["neg"][1])
