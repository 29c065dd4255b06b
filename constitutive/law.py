"""The hysteretic bending law of one fabric direction (Lahey 2002, Ch. 4; docs/theory.md §2).

The moment per unit width needed to impose a curvature history κ(t) is::

    M = m κ̈ + d κ̇ + k1 κ + k3 κ³ + M_f(κ-history)

with ``M_f`` the Bliman–Sorine friction moment (:mod:`constitutive.friction`),
which has the sign of κ̇ while sliding.  The thesis writes 4.1/4.4 with mixed
signs; this is the physically consistent form its data need.

Optional face-up/face-down asymmetry: ``k1_neg``, ``k3_neg`` replace ``k1``,
``k3`` for κ < 0 (positive κ bends the fabric face-up).  The elastic moment
stays continuous (both branches vanish at κ = 0).

Units are SI: κ [1/m], M [N·m/m], k1 [N·m], k3 [N·m³], d [N·m·s], m [N·m·s²].

>>> from constitutive.friction import FrictionParams
>>> law = BendingLaw(k1=1e-4, k3=1e-8, d=1e-6,
...                  friction=FrictionParams(f1=2e-3, f2=1e-3, eps_f=50.0, eta=0.5))
>>> state = law.new_state((2,))
>>> M, dM = state.trial(np.array([10.0, -10.0]))
>>> np.round(M * 1e3, 4)
array([ 1.4881, -1.4881])
>>> state.commit(np.array([10.0, -10.0]))
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from constitutive.friction import (
    FrictionParams,
    FrictionState,
    ParameterError,
    _as_param,
    _check,
    restored_array,
)

__all__ = ["BendingLaw", "BendingState", "FRICTION_TANGENTS", "check_friction_tangent"]


@dataclass(frozen=True, eq=False)
class BendingLaw:
    """Parameters of the bending law of one direction (SI), validated.

    Parameters
    ----------
    k1 : float or array
        Linear bending rigidity [N·m] (κ ≥ 0, and κ < 0 unless ``k1_neg``).
    k3 : float or array
        Cubic stiffness [N·m³]; ``k3 >= 0``.
    d : float or array
        Viscous coefficient [N·m·s]; ``d >= 0``.
    m : float or array
        Curvature-inertia coefficient [N·m·s²]; ``m >= 0``.
    friction : FrictionParams or None
        Dry-friction operator, ``None`` for none.
    k1_neg, k3_neg : float or array or None
        Face-down (κ < 0) values; ``None`` means symmetric.

    Examples
    --------
    >>> BendingLaw(k1=1e-4).elastic(np.array([-2.0, 3.0]))
    (array([-0.0002,  0.0003]), array([0.0001, 0.0001]))
    >>> float(BendingLaw(k1=1e-4, k3_neg=2e-8).elastic(-100.0)[0].round(6))
    -0.03
    >>> BendingLaw(k1=0.0)
    Traceback (most recent call last):
    ...
    constitutive.friction.ParameterError: k1 = 0 breaks k1 > 0 (positive bending rigidity)
    """

    k1: float | np.ndarray
    k3: float | np.ndarray = 0.0
    d: float | np.ndarray = 0.0
    m: float | np.ndarray = 0.0
    friction: FrictionParams | None = None
    k1_neg: float | np.ndarray | None = None
    k3_neg: float | np.ndarray | None = None

    def __post_init__(self):
        rules = {
            "k1": (lambda v: v > 0, "k1 > 0 (positive bending rigidity)"),
            "k3": (lambda v: v >= 0, "k3 >= 0 (moment must grow with curvature)"),
            "d": (lambda v: v >= 0, "d >= 0 (viscous term must dissipate)"),
            "m": (lambda v: v >= 0, "m >= 0 (non-negative curvature inertia)"),
            "k1_neg": (lambda v: v > 0, "k1_neg > 0 (positive face-down bending rigidity)"),
            "k3_neg": (lambda v: v >= 0, "k3_neg >= 0 (moment must grow with curvature)"),
        }
        for name, (ok, rule) in rules.items():
            value = getattr(self, name)
            if value is None:
                continue
            value = _as_param(value, name)
            object.__setattr__(self, name, value)
            _check(name, value, ok(np.asarray(value)), rule)
        if self.friction is not None and not isinstance(self.friction, FrictionParams):
            raise ParameterError(f"friction = {self.friction!r} must be FrictionParams or None")

    @property
    def symmetric(self) -> bool:
        """True if face-up and face-down stiffnesses are the same."""
        return self.k1_neg is None and self.k3_neg is None

    def scaled(self, factor: float) -> "BendingLaw":
        """The same fabric with every moment multiplied by ``factor`` (> 0).

        k1, k3, d, m and the friction moments f1, f2 scale; the friction lengths ε_f, η do
        not, so the loop keeps its shape in curvature and the bending length grows as
        ``factor**(1/3)``.

        >>> law = BendingLaw(k1=1e-6, d=1e-7, friction=FrictionParams(2e-4, 1e-4, 50.0, 0.5))
        >>> twice = law.scaled(2.0)
        >>> float(twice.k1), float(twice.friction.f1), float(twice.friction.eps_f)
        (2e-06, 0.0004, 50.0)
        """
        if not (np.isfinite(factor) and factor > 0):
            raise ParameterError(f"scale factor = {factor!r} breaks factor > 0")
        fr = self.friction
        if fr is not None:
            fr = dataclasses.replace(fr, f1=factor * fr.f1, f2=factor * fr.f2)
        moments = {k: factor * getattr(self, k) for k in ("k1", "k3", "d", "m", "k1_neg", "k3_neg")
                   if getattr(self, k) is not None}
        return dataclasses.replace(self, friction=fr, **moments)

    def elastic(self, kappa):
        """Elastic moment ``k1 κ + k3 κ³`` (face-down values for κ < 0) and tangent.

        Returns
        -------
        M_e, dM_e : ndarray
            [N·m/m] and [N·m]; at κ = 0 the tangent is the face-up ``k1``.
        """
        kappa, k1, k3 = self._branch(kappa)
        k2 = kappa * kappa
        return (k1 + k3 * k2) * kappa, k1 + 3.0 * k3 * k2

    def elastic_energy(self, kappa):
        """Stored energy ``∫₀^κ (k1 s + k3 s³) ds`` [N·m/m² · m = J/m²] (face-down values for κ < 0).

        >>> float(BendingLaw(k1=2.0, k3=4.0).elastic_energy(1.0))   # ½·2 + ¼·4
        2.0
        """
        kappa, k1, k3 = self._branch(kappa)
        return 0.5 * k1 * kappa**2 + 0.25 * k3 * kappa**4

    def _branch(self, kappa):
        """``(κ, k1, k3)`` with the face-down coefficients where κ < 0."""
        kappa = np.asarray(kappa, dtype=float)
        k1, k3 = self.k1, self.k3
        if not self.symmetric:
            neg = kappa < 0
            k1 = np.where(neg, self.k1 if self.k1_neg is None else self.k1_neg, k1)
            k3 = np.where(neg, self.k3 if self.k3_neg is None else self.k3_neg, k3)
        return kappa, k1, k3

    def new_state(self, shape=()) -> "BendingState":
        """A state at rest (κ = 0, friction unloaded) for material points of ``shape``."""
        return BendingState(self, shape)

    def moment(self, kappa, kappa_dot, kappa_ddot, state: "BendingState"):
        """Full moment ``m κ̈ + d κ̇ + k1 κ + k3 κ³ + M_f`` at a trial curvature.

        ``state`` is not changed (``M_f`` is ``state``'s trial value).

        Examples
        --------
        >>> law = BendingLaw(k1=2.0, d=0.5, m=0.1)
        >>> float(law.moment(1.0, 2.0, 10.0, law.new_state()))
        4.0
        """
        M, _ = state.trial(kappa)
        return self.m * np.asarray(kappa_ddot) + self.d * np.asarray(kappa_dot) + M


#: Newton tangents of the friction moment :meth:`BendingState.trial` offers.
FRICTION_TANGENTS = ("consistent", "nonnegative", "stick")


def check_friction_tangent(name: str) -> str:
    """``name`` if it is one of :data:`FRICTION_TANGENTS`, else ValueError naming them."""
    if name not in FRICTION_TANGENTS:
        raise ValueError(f"friction_tangent = {name!r}: must be one of {FRICTION_TANGENTS}")
    return name


class BendingState:
    """History of an array of material points under one :class:`BendingLaw`.

    This is the object the FE layer holds per direction and quadrature
    point: ``trial`` (no mutation, any number of times) and ``commit``
    (once per converged step). ``commit`` and ``load_state_dict`` give
    ``kappa`` a new array, so a holder can tell by identity whether the
    committed state changed since it last looked.

    Examples
    --------
    >>> law = BendingLaw(k1=1.0, friction=FrictionParams(1.0, 0.0, 1.0, 0.5))
    >>> st = law.new_state((1,))
    >>> st.trial(np.array([1.0]))[0].round(4)
    array([1.8647])
    >>> st.friction_moment(np.array([1.0])).round(4)
    array([0.8647])
    """

    def __init__(self, law: BendingLaw, shape=()):
        self.law = law
        self.shape = tuple(int(n) for n in shape) if np.iterable(shape) else (int(shape),)
        self.friction = None if law.friction is None else FrictionState(law.friction, self.shape)
        self.kappa = np.zeros(self.shape)

    def trial(self, kappa, friction_tangent: str = "consistent"):
        """Elastic + friction moment and its tangent at a trial curvature.

        Parameters
        ----------
        kappa : array_like
            Trial curvature [1/m].
        friction_tangent : {"consistent", "nonnegative", "stick"}
            ``"stick"`` is the tangent of a point that sticks at its committed
            curvature (:meth:`FrictionState.stick_tangent`, floored at zero), fixed
            within a step: Newton's fallback where the consistent one cycles
            between stick and slip. ``"nonnegative"`` floors the friction part of ``dM`` at zero. Where the slow
            Dahl term overtakes the fast one after a reversal the friction moment falls
            with curvature; with Fabric 2's weft as printed (ε_f = 7.6e-4 cm⁻¹) the total
            tangent falls to −51 k1 on loading from rest (``tests/constitutive/test_law.py``).
            The consistent tangent then sends Newton off; the floored one converges (linearly
            there) to the same equilibrium, since the moment itself is unchanged.

        Returns
        -------
        M, dM : ndarray
            ``k1 κ + k3 κ³ + M_f`` [N·m/m] and ``dM/dκ`` [N·m].

        Examples
        --------
        >>> law = BendingLaw(k1=1.0, friction=FrictionParams(2.0, 1.9, 1.0, 0.5))
        >>> st = law.new_state((1,))
        >>> st.commit(np.array([0.0]))
        >>> k = np.array([2.0])                        # past the friction moment's peak
        >>> bool(st.trial(k)[1][0] < 1.0), st.trial(k, "nonnegative")[1].tolist()
        (True, [1.0])
        """
        check_friction_tangent(friction_tangent)
        M, dM = self.law.elastic(kappa)
        if self.friction is not None:
            Mf, dMf = self.friction.trial(kappa)
            if friction_tangent == "nonnegative":
                dMf = np.maximum(dMf, 0.0)
            elif friction_tangent == "stick":
                dMf = np.maximum(self.friction.stick_tangent(), 0.0)
            M, dM = M + Mf, dM + dMf
        if np.shape(M) != self.shape:   # scalar parameters with a scalar trial: full arrays
            M, dM = np.broadcast_to(M, self.shape).copy(), np.broadcast_to(dM, self.shape).copy()
        return M, dM

    def friction_moment(self, kappa):
        """Friction moment alone at a trial curvature (zeros without friction)."""
        if self.friction is None:
            return np.zeros(np.broadcast_shapes(np.shape(kappa), self.shape))
        return self.friction.moment(kappa)

    def commit(self, kappa):
        """Accept ``kappa`` (call once per converged step)."""
        if self.friction is not None:
            self.friction.commit(kappa)
        self.kappa = np.broadcast_to(np.asarray(kappa, dtype=float), self.shape).copy()

    def state_dict(self) -> dict:
        """The committed state as arrays: ``kappa`` and, with friction, ``friction.<name>``."""
        out = {"kappa": self.kappa.copy()}
        if self.friction is not None:
            out.update({f"friction.{k}": v for k, v in self.friction.state_dict().items()})
        return out

    def load_state_dict(self, state: dict) -> None:
        """Restore a committed state written by :meth:`state_dict` (same law and shape)."""
        saved = {k.split(".", 1)[1]: v for k, v in state.items() if k.startswith("friction.")}
        if bool(saved) != (self.friction is not None):
            raise ValueError("bending state: saved " + ("with" if saved else "without")
                             + " friction, but the law has " + ("none" if saved else "friction"))
        self.kappa = restored_array("bending state kappa", state, "kappa", self.shape)
        if self.friction is not None:
            self.friction.load_state_dict(saved)

    def friction_work(self, kappa):
        """Work ``∫ M_f dκ`` [J/m²] the friction dissipates from the committed to the trial
        curvature, per material point (zeros without friction; :meth:`FrictionState.work`)."""
        if self.friction is None:
            return np.zeros(np.broadcast_shapes(np.shape(kappa), self.shape))
        return self.friction.work(kappa)

    def copy(self):
        """Independent copy of the state (e.g. to restart a cut step)."""
        new = BendingState.__new__(BendingState)
        new.law, new.shape, new.kappa = self.law, self.shape, self.kappa.copy()
        new.friction = None if self.friction is None else self.friction.copy()
        return new
