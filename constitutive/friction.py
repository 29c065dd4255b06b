"""Bliman–Sorine second-order dry friction as a state object (thesis Sec. 3.3).

In the path variable ``s = ∫|κ̇| dt`` the operator of Eqs. 3.1 and 3.4 is two
first-order (Dahl) states with lengths ``a1 = ε_f η`` and ``a2 = ε_f``::

    dy/ds = (σ − y) / a,    σ = sign(κ̇),    M_f = f1 y1 − f2 y2.

(From 3.4: ``x1 = f1 y1`` and ``x2 = −f2 y2``.) Over a monotone increment Δκ the
update is exact, ``y ← σ + (y − σ) exp(−|Δκ|/a)``, so the result does not depend
on the step size as long as the path between two samples is monotone.  From
rest on a monotone path this is the closed form 3.17 / 4.2; after a reversal
only the state form is right.

Units are SI: f1, f2 in N·m/m (= N), ε_f in 1/m (a path length measured in
curvature), η dimensionless.

>>> p = FrictionParams(f1=2.0, f2=1.0, eps_f=0.5, eta=0.5)
>>> st = FrictionState(p, shape=(3,))
>>> M, dM = st.trial(np.array([0.0, 0.1, -0.1]))
>>> np.round(M, 4)
array([ 0.    ,  0.4781, -0.4781])
>>> st.commit(np.array([0.0, 0.1, -0.1]))
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "ParameterError",
    "FrictionParams",
    "FrictionState",
    "restored_array",
    "dahl_path",
    "friction_path",
    "closed_form_from_rest",
]


class ParameterError(ValueError):
    """A model parameter breaks a rule (the message names both)."""


def _as_param(value, name):
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ParameterError(f"{name} = {value!r} must be finite")
    return float(arr) if arr.ndim == 0 else arr


def _check(name, value, ok, rule):
    """Raise ParameterError naming ``name`` and ``rule`` where ``ok`` is False."""
    ok = np.asarray(ok)
    if not np.all(ok):
        arr = np.asarray(value, dtype=float)
        if arr.ndim == 0:
            shown = f"{float(arr):g}"
        else:
            idx = tuple(int(i) for i in np.argwhere(~np.broadcast_to(ok, arr.shape))[0])
            shown = f"{arr[idx]:g} (at index {idx} of an array)"
        raise ParameterError(f"{name} = {shown} breaks {rule}")


@dataclass(frozen=True, eq=False)
class FrictionParams:
    """Parameters of the second-order friction operator (SI), validated.

    Each may be a scalar or an array; arrays must broadcast against the
    shape of the state that uses them (e.g. shape ``(n, 1)`` to run ``n``
    parameter sets along one path).

    Parameters
    ----------
    f1, f2 : float or array
        Friction moment amplitudes [N·m/m]; ``f1 − f2`` is the kinetic friction.
    eps_f : float or array
        Slow friction length in curvature [1/m] (``a2 = eps_f``).
    eta : float or array
        Ratio of the fast to the slow length (``a1 = eps_f * eta``).

    Raises
    ------
    ParameterError
        If the dissipativity conditions 3.18–3.19 fail:
        ``f1 > f2 >= 0``, ``eps_f > 0``, ``0 < eta < 1``, or the fast length
        ``eps_f * eta`` underflows (its stick tangent ``f1/a1`` would be infinite).

    Examples
    --------
    >>> FrictionParams(f1=1.0, f2=0.5, eps_f=10.0, eta=0.5).a1
    5.0
    >>> FrictionParams(f1=1.0, f2=0.5, eps_f=10.0, eta=1.2)
    Traceback (most recent call last):
    ...
    constitutive.friction.ParameterError: eta = 1.2 breaks 0 < eta < 1 (dissipativity, thesis 3.19)
    """

    f1: float | np.ndarray
    f2: float | np.ndarray
    eps_f: float | np.ndarray
    eta: float | np.ndarray

    def __post_init__(self):
        for name in ("f1", "f2", "eps_f", "eta"):
            object.__setattr__(self, name, _as_param(getattr(self, name), name))
        _check("f2", self.f2, np.asarray(self.f2) >= 0, "f1 > f2 >= 0 (dissipativity, thesis 3.18)")
        ok = np.asarray(self.f1) > np.asarray(self.f2)
        if not np.all(ok):
            f1, f2 = np.broadcast_arrays(self.f1, self.f2)
            i = tuple(np.argwhere(~ok)[0]) if ok.ndim else ()
            raise ParameterError(f"f1 = {float(f1[i]):g} with f2 = {float(f2[i]):g} breaks f1 > f2 >= 0 "
                                 "(dissipativity, thesis 3.18)")
        _check("eps_f", self.eps_f, np.asarray(self.eps_f) > 0, "eps_f > 0 (dissipativity, thesis 3.19)")
        eta = np.asarray(self.eta)
        _check("eta", self.eta, (eta > 0) & (eta < 1), "0 < eta < 1 (dissipativity, thesis 3.19)")
        # the stick tangent is f1/a1: a fast length that underflows makes it infinite
        a1 = np.asarray(self.eps_f * self.eta)
        _check("eps_f * eta", a1, a1 >= np.finfo(float).tiny,
               f"eps_f * eta >= {np.finfo(float).tiny:.3g} (the fast Dahl length a1; the stick tangent is f1/a1)")

    @property
    def a1(self):
        """Fast Dahl length ``eps_f * eta`` [1/m]."""
        return self.eps_f * self.eta

    @property
    def a2(self):
        """Slow Dahl length ``eps_f`` [1/m]."""
        return self.eps_f

    @property
    def shape(self):
        """Broadcast shape of the parameter arrays (``()`` for scalars)."""
        return np.broadcast_shapes(*(np.shape(getattr(self, n)) for n in ("f1", "f2", "eps_f", "eta")))

    def __repr__(self):
        return (f"FrictionParams(f1={self.f1!r}, f2={self.f2!r}, "
                f"eps_f={self.eps_f!r}, eta={self.eta!r})")


class FrictionState:
    """Committed friction state of an array of material points.

    Parameters
    ----------
    params : FrictionParams
        Parameters, broadcastable to ``shape``.
    shape : tuple of int
        Shape of the material-point array, e.g. ``(n_elements, n_qp)``.

    Attributes
    ----------
    kappa, y1, y2 : ndarray
        Committed curvature [1/m] and Dahl states (at rest: all zero).

    Notes
    -----
    ``trial`` never mutates, so a Newton iteration may evaluate any number
    of trial curvatures before a single ``commit``.

    Examples
    --------
    >>> st = FrictionState(FrictionParams(1.0, 0.0, 1.0, 0.5), shape=(2,))
    >>> M, dM = st.trial(np.array([0.0, 0.0]))
    >>> M, dM                      # stick tangent at rest: f1 / a1
    (array([0., 0.]), array([2., 2.]))
    """

    def __init__(self, params: FrictionParams, shape=()):
        self.params = params
        self.shape = tuple(int(n) for n in shape) if np.iterable(shape) else (int(shape),)
        if np.broadcast_shapes(self.shape, params.shape) != self.shape:
            raise ParameterError(
                f"friction parameters of shape {params.shape} do not broadcast to the state shape {self.shape}")
        self.kappa = np.zeros(self.shape)
        self.y1 = np.zeros(self.shape)
        self.y2 = np.zeros(self.shape)
        self._inv_a1 = 1.0 / np.asarray(params.a1)
        self._inv_a2 = 1.0 / np.asarray(params.a2)
        self._cache = None

    def _update(self, kappa, tangent):
        """Exact update of both Dahl states over ``kappa − self.kappa``.

        With y the updated state and σ = sign(Δκ), ``dy/dκ = (1 − σ y_n) e/a``
        equals ``(1 − σ y)/a``; at Δκ = 0 (stick) it is ``(1 + |y_n|)/a``, the
        larger one-sided value (σ = −sign(y_n)).
        """
        dk = np.asarray(kappa, dtype=float) - self.kappa
        sig = np.sign(dk)
        mabs = -np.abs(dk)
        out = []
        for y_n, inv_a in ((self.y1, self._inv_a1), (self.y2, self._inv_a2)):
            e = np.exp(mabs * inv_a)
            y = (y_n - sig) * e
            y += sig
            if tangent:
                stick = sig == 0
                dy = 1.0 - sig * y
                if stick.any():
                    dy += stick * np.abs(y)
                dy *= inv_a
                out.append((y, dy))
            else:
                out.append((y, None))
        return out

    def trial(self, kappa):
        """Friction moment and its consistent tangent at a trial curvature.

        Parameters
        ----------
        kappa : array_like
            Trial curvature [1/m], shape ``self.shape``.

        Returns
        -------
        M_f, dM_f : ndarray
            Moment [N·m/m] and ``dM_f/dκ`` [N·m] (one-sided stick value where
            ``kappa`` equals the committed curvature).
        """
        (y1, dy1), (y2, dy2) = self._update(kappa, True)
        p = self.params
        # not state: lets the usual commit at the last trial curvature skip the update
        self._cache = (np.array(kappa, dtype=float, copy=True), y1, y2)
        return p.f1 * y1 - p.f2 * y2, p.f1 * dy1 - p.f2 * dy2

    def stick_tangent(self):
        """``dM_f/dκ`` of a point that sticks at its committed curvature.

        The one-sided value ``f1 (1 + |y1|)/a1 − f2 (1 + |y2|)/a2`` of :meth:`trial`
        at Δκ = 0: a tangent that does not change within a step, the friction
        counterpart of an initial-stiffness tangent.

        >>> st = FrictionState(FrictionParams(1.0, 0.0, 1.0, 0.5), shape=(1,))
        >>> st.stick_tangent()
        array([2.])
        """
        p = self.params
        return p.f1 * (1.0 + np.abs(self.y1)) * self._inv_a1 - p.f2 * (1.0 + np.abs(self.y2)) * self._inv_a2

    def moment(self, kappa):
        """Friction moment alone at a trial curvature (no mutation)."""
        (y1, _), (y2, _) = self._update(kappa, False)
        return self.params.f1 * y1 - self.params.f2 * y2

    def commit(self, kappa):
        """Accept ``kappa`` as the new committed curvature."""
        kappa = np.broadcast_to(np.asarray(kappa, dtype=float), self.shape)
        c = self._cache
        if c is not None and c[0].shape == kappa.shape and np.array_equal(c[0], kappa):
            y1, y2 = c[1], c[2]               # the last trial was at this curvature: reuse it
        else:
            (y1, _), (y2, _) = self._update(kappa, False)
        self.y1 = np.broadcast_to(y1, self.shape).copy() if np.shape(y1) != self.shape else y1
        self.y2 = np.broadcast_to(y2, self.shape).copy() if np.shape(y2) != self.shape else y2
        self.kappa = kappa.copy()
        self._cache = None

    def state_dict(self) -> dict:
        """The committed state as arrays: curvature ``kappa`` and the Dahl states ``y1``, ``y2``.

        >>> st = FrictionState(FrictionParams(1.0, 0.5, 1.0, 0.5), shape=(2,))
        >>> st.commit(np.array([0.3, -1.0]))
        >>> again = FrictionState(st.params, shape=(2,))
        >>> again.load_state_dict(st.state_dict())
        >>> bool(np.array_equal(again.moment([0.5, 0.5]), st.moment([0.5, 0.5])))
        True
        """
        return {"kappa": self.kappa.copy(), "y1": self.y1.copy(), "y2": self.y2.copy()}

    def load_state_dict(self, state: dict) -> None:
        """Restore a committed state written by :meth:`state_dict` (same shape)."""
        arrays = {key: restored_array(f"friction state {key}", state, key, self.shape)
                  for key in ("kappa", "y1", "y2")}
        self.kappa, self.y1, self.y2 = arrays["kappa"], arrays["y1"], arrays["y2"]
        self._cache = None

    def work(self, kappa):
        """Exact work ``∫ M_f dκ`` from the committed to the trial curvature, per point.

        Each Dahl state moves monotonically over the increment, so
        ``∫ y dκ = |Δκ| + (σ y_n − 1) a (1 − exp(−|Δκ|/a))`` with ``σ = sign Δκ``.

        >>> st = FrictionState(FrictionParams(1.0, 0.0, 1.0, 0.5), shape=(1,))
        >>> k = np.array([40.0])                   # far into slip: y1 → 1
        >>> bool(abs(st.work(k)[0] - (40.0 - 0.5)) < 1e-12)     # f1 (Δκ − a1)
        True
        """
        p = self.params
        dk = np.asarray(kappa, dtype=float) - self.kappa
        return p.f1 * _dahl_work(self.y1, dk, p.a1) - p.f2 * _dahl_work(self.y2, dk, p.a2)

    def copy(self):
        """Independent copy (same parameters, copied state arrays)."""
        new = FrictionState.__new__(FrictionState)
        new.params, new.shape, new._inv_a1, new._inv_a2 = self.params, self.shape, self._inv_a1, self._inv_a2
        new.kappa, new.y1, new.y2 = self.kappa.copy(), self.y1.copy(), self.y2.copy()
        new._cache = None
        return new


def restored_array(what: str, state: dict, key: str, shape) -> np.ndarray:
    """``state[key]`` as a float array of ``shape``; a missing key or another shape is a
    ``ValueError`` naming ``what`` (a checkpoint of another model or mesh)."""
    if key not in state:
        raise ValueError(f"{what}: missing from the saved state")
    arr = np.array(state[key], dtype=float)
    if arr.shape != tuple(shape):
        raise ValueError(f"{what}: saved with shape {arr.shape}, expected {tuple(shape)}")
    return arr

def _dahl_work(y, dk, a):
    """``∫ y dκ`` over a monotone increment ``dk`` of a Dahl state starting at ``y``."""
    sigma = np.sign(dk)
    return np.abs(dk) + (sigma * y - 1.0) * a * (1.0 - np.exp(-np.abs(dk) / a))


def dahl_path(kappa, a, y0=0.0):
    """Exact Dahl state along a sampled curvature path.

    Between consecutive samples the path is taken as monotone; over each
    monotone run the state has the closed form
    ``y = σ + (y_start − σ) exp(−(s − s_start)/a)`` (s the path length), so the
    only Python loop is over the runs (three for a KES-FB cycle).

    Parameters
    ----------
    kappa : array_like, shape (n,)
        Curvature samples [1/m].
    a : float or array_like
        Dahl length(s) [1/m]; an array of shape ``(n_a, 1)`` evaluates
        ``n_a`` lengths at once.
    y0 : float or array_like
        State at the first sample, broadcastable to ``np.shape(a)``.

    Returns
    -------
    y : ndarray, shape ``broadcast(shape(a), (n,))``

    Examples
    --------
    >>> k = np.array([0.0, 1.0, 2.0, 1.0])
    >>> np.round(dahl_path(k, 1.0), 4)
    array([ 0.    ,  0.6321,  0.8647, -0.314 ])
    >>> dahl_path(k, np.array([[1.0], [2.0]])).shape
    (2, 4)
    """
    kappa = np.asarray(kappa, dtype=float)
    if kappa.ndim != 1:
        raise ValueError(f"kappa must be one-dimensional (a path), got shape {kappa.shape}")
    a = np.asarray(a, dtype=float)
    n = kappa.size
    out_shape = np.broadcast_shapes(a.shape, (n,))
    y = np.empty(out_shape)
    y[..., :1] = np.broadcast_to(y0, a.shape) if a.ndim else y0
    if n < 2:
        return y
    dk = np.diff(kappa)
    sign = np.sign(dk)
    # a zero increment leaves y unchanged whatever σ is: give it the sign of the run it sits in
    if not sign.all():
        idx = np.where(sign != 0, np.arange(sign.size), 0)
        np.maximum.accumulate(idx, out=idx)
        sign = sign[idx]
    starts = np.concatenate(([0], np.flatnonzero(np.diff(sign)) + 1))
    ends = np.concatenate((starts[1:], [sign.size]))
    adk = np.abs(dk)
    for b, e in zip(starts, ends):
        sig = sign[b]
        s = np.cumsum(adk[b:e])
        y[..., b + 1:e + 1] = sig + (y[..., b:b + 1] - sig) * np.exp(-s / a)
    return y


def friction_path(params: FrictionParams, kappa, y1_0=0.0, y2_0=0.0):
    """Friction moment along a sampled path (exact, see :func:`dahl_path`).

    Parameter arrays of shape ``(n_p, 1)`` give ``n_p`` moment histories
    (output shape ``(n_p, n)``).

    Examples
    --------
    >>> p = FrictionParams(f1=2.0, f2=1.0, eps_f=0.5, eta=0.5)
    >>> np.round(friction_path(p, np.linspace(0.0, 0.1, 3)), 4)
    array([0.    , 0.2674, 0.4781])
    """
    y1 = dahl_path(kappa, params.a1, y1_0)
    y2 = dahl_path(kappa, params.a2, y2_0)
    f1, f2 = params.f1, params.f2
    return f1 * y1 - f2 * y2


def closed_form_from_rest(params: FrictionParams, s, sigma=1.0):
    """Thesis Eq. 3.17 / 4.2 on a monotone path from rest.

    ``M_f = σ (f1 − f2) + σ (f2 exp(−s/ε_f) − f1 exp(−s/(ε_f η)))`` with ``s``
    the path length travelled (valid only before the first reversal).

    Examples
    --------
    >>> p = FrictionParams(f1=2.0, f2=1.0, eps_f=0.5, eta=0.5)
    >>> round(float(closed_form_from_rest(p, 0.1)), 4)
    0.4781
    """
    s = np.asarray(s, dtype=float)
    p = params
    return sigma * (p.f1 - p.f2) + sigma * (p.f2 * np.exp(-s / p.eps_f) - p.f1 * np.exp(-s / (p.eps_f * p.eta)))
