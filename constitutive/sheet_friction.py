"""Bliman–Sorine friction on the curvature tensor of a sheet (frame invariant).

The friction law of one fabric direction (:mod:`constitutive.friction`) acts on one
curvature κ. Applied to the warp and weft curvatures κ11 and κ22 apart, it leaves twist
frictionless and makes the friction of a bend depend on where its axes lie on the yarns:
a saddle κ = diag(c, −c) meets friction on both yarns, the same saddle turned by 45°
(pure twist) meets none. A sheet with equal warp and weft is then square-symmetric, not
isotropic, and its folds lock onto the yarn axes or the diagonals (docs/theory.md §2).

Here each Dahl state is a symmetric tensor ``Y`` that follows the curvature tensor along
its path. In the scaled curvature ``ξ_αβ = κ_αβ / √(a_α a_β)`` (``a_α`` the state's Dahl
length in direction α) with the norm ``|ξ|² = ξ11² + ξ22² + 2 ξ12²``,

    dY/ds = E − Y,    E = dξ/|dξ|,    s = ∫ |dξ|,

and the moment is ``M_f,αβ = Σ_i ± √(f_iα f_iβ) Y_i,αβ`` (``+`` for the fast state 1,
``−`` for the slow state 2). With equal directions this is the Dahl operator of a
vector-valued slip (as in planar friction) written on the curvature tensor: rotating the
curvature history rotates the moment, whatever the axes. In a strip bent along one yarn
(κ22 = κ12 = 0, the KES-FB test) ``Y`` keeps a single component and the update is the
direction's scalar law exactly, so the KES values B and 2HB calibrate it as before.

Over a straight increment Δξ (the path between two converged states, as the scalar law
takes it to be monotone) the update is exact,

    Y = E + (Y_n − E) exp(−|Δξ|),

and so is the work ``∫ M_f : dκ``. Arrays are in Voigt order (κ11, κ22, 2 κ12) for the
curvature and (M11, M22, M12) for the moment, the pair whose product is the power.

>>> from constitutive.friction import FrictionParams
>>> p = FrictionParams(f1=1.0, f2=0.0, eps_f=1.0, eta=0.5)
>>> st = SheetFrictionState(p, p, shape=(2,))
>>> bend = np.array([[0.3, 0.0, 0.0], [0.0, 0.0, 0.0]])
>>> M, D = st.trial(bend)
>>> round(float(M[0, 0]), 6) == round(float(FrictionState(p, (1,)).trial([0.3])[0][0]), 6)
True
"""
from __future__ import annotations

import numpy as np

from constitutive.friction import FrictionParams, FrictionState, ParameterError, restored_array
from constitutive.sheet_friction_kernel import dahl_pair

__all__ = ["SheetFrictionState", "rotate_voigt"]

_SQRT2 = np.sqrt(2.0)


def rotate_voigt(voigt, angle: float, moment: bool = False):
    """The Voigt array of a symmetric 2-tensor rotated by ``angle`` (rad) about the normal.

    ``moment=False`` reads (t11, t22, 2 t12) (a curvature), ``True`` (t11, t22, t12).

    >>> np.round(rotate_voigt(np.array([1.0, 0.0, 0.0]), np.pi / 4), 6).tolist()
    [0.5, 0.5, 1.0]
    """
    v = np.asarray(voigt, dtype=float)
    off = v[..., 2] * (1.0 if moment else 0.5)
    T = np.stack([np.stack([v[..., 0], off], -1), np.stack([off, v[..., 1]], -1)], -2)
    c, s = np.cos(angle), np.sin(angle)
    R = np.array([[c, -s], [s, c]])
    T = R @ T @ R.T
    return np.stack([T[..., 0, 0], T[..., 1, 1], T[..., 0, 1] * (1.0 if moment else 2.0)], -1)


class _DahlTensor:
    """One tensor Dahl state: Voigt scale of its moments ``sf`` and of its lengths ``sa``.

    ``z = κ / sa`` are orthonormal coordinates of the scaled curvature ξ and the state ``y``
    is held in the same coordinates; ``M = sf y``.
    """

    def __init__(self, f_warp, f_weft, a_warp, a_weft):
        f_warp, f_weft, a_warp, a_weft = np.broadcast_arrays(
            *(np.asarray(x, dtype=float) for x in (f_warp, f_weft, a_warp, a_weft)))
        self.sf = np.stack([f_warp, f_weft, np.sqrt(f_warp * f_weft) / _SQRT2], -1)
        self.sa = np.stack([a_warp, a_weft, _SQRT2 * np.sqrt(a_warp * a_weft)], -1)
        self.power = self.sf * self.sa        # M · dκ = y · (sf sa) dz
        self._flat = {}

    def flat(self, shape):
        """``sf`` and ``sa`` broadcast to ``shape + (3,)`` as contiguous ``(n, 3)`` arrays (kept
        per shape: the compiled update reads them at every evaluation)."""
        if shape not in self._flat:
            self._flat[shape] = tuple(np.ascontiguousarray(np.broadcast_to(x, shape + (3,))).reshape(-1, 3)
                                      for x in (self.sf, self.sa))
        return self._flat[shape]

    def update(self, y_n, dkappa, tangent: bool):
        """State after the increment ``dkappa`` and, with ``tangent``, ``dM/dκ`` (…, 3, 3).

        The NumPy reference of the compiled update (:mod:`constitutive.sheet_friction_kernel`)
        that :class:`SheetFrictionState` runs."""
        dz = dkappa / self.sa
        r = np.sqrt(np.einsum("...i,...i->...", dz, dz))
        slip = r > 0.0
        rr = np.where(slip, r, 1.0)
        e = dz / rr[..., None]
        decay = np.exp(-r)
        y = e * (1.0 - decay)[..., None] + y_n * decay[..., None]
        if not tangent:
            return y, None
        # dy/dz = (1 − exp(−r))/r (I − e eᵀ) + exp(−r) (e − y_n) eᵀ; at r = 0 (stick) the
        # larger one-sided value (1 + |y_n|) I, as in the scalar law
        g = np.where(slip, -np.expm1(-r) / rr, 0.0)
        dy = (g[..., None, None] * (np.eye(3) - e[..., :, None] * e[..., None, :])
              + decay[..., None, None] * (e - y_n)[..., :, None] * e[..., None, :])
        stick = ~slip
        if stick.any():
            ny = np.sqrt(np.einsum("...i,...i->...", y_n, y_n))
            dy[stick] = (1.0 + ny[stick])[..., None, None] * np.eye(3)
        return y, self.to_kappa(dy)

    def to_kappa(self, dy_dz):
        """``dM/dκ = sf (dy/dz) / sa`` of a tangent in the orthonormal coordinates."""
        return self.sf[..., :, None] * dy_dz / self.sa[..., None, :]

    def stick(self, y_n):
        """``(1 + |y_n|)`` I in κ, the tangent of a point that sticks at its committed state."""
        ny = np.sqrt(np.einsum("...i,...i->...", y_n, y_n))
        return self.to_kappa((1.0 + ny)[..., None, None] * np.eye(3))

    def work(self, y_n, dkappa):
        """Exact ``∫ M · dκ`` over the straight increment ``dkappa``."""
        dz = dkappa / self.sa
        r = np.sqrt(np.einsum("...i,...i->...", dz, dz))
        rr = np.where(r > 0.0, r, 1.0)
        e = dz / rr[..., None]
        c = self.power
        # ∫₀^r c · (e + (y_n − e) exp(−s)) e ds
        return (r * np.einsum("...i,...i,...i->...", c, e, e)
                + (-np.expm1(-r)) * np.einsum("...i,...i,...i->...", c, e, y_n - e))


class SheetFrictionState:
    """Committed tensor friction state of an array of material points of a sheet.

    Parameters
    ----------
    warp, weft : FrictionParams or None
        The directions' scalar laws (at least one). A direction without friction
        contributes no moment (its f's are zero; the other's lengths stand in for its).
    shape : tuple of int
        Shape of the material-point array; the state arrays are ``shape + (3,)``.

    Attributes
    ----------
    kappa, y1, y2 : ndarray, shape ``shape + (3,)``
        Committed Voigt curvature and the two Dahl states (orthonormal coordinates).

    Notes
    -----
    The interface is :class:`constitutive.friction.FrictionState`'s with Voigt arrays:
    ``trial`` returns the moment (…, 3) and ``dM/dκ`` (…, 3, 3), which is not symmetric
    where a point reverses (the scalar law's kink, seen from the side).

    Examples
    --------
    Equal directions: the moment of a rotated history is the rotated moment.

    >>> p = FrictionParams(f1=2.0, f2=1.0, eps_f=0.5, eta=0.5)
    >>> a, b = SheetFrictionState(p, p, (1,)), SheetFrictionState(p, p, (1,))
    >>> k = np.array([[0.2, -0.1, 0.05]])
    >>> Ma = a.trial(k)[0]
    >>> Mb = b.trial(rotate_voigt(k, 0.7))[0]
    >>> bool(np.allclose(rotate_voigt(Ma, 0.7, moment=True), Mb))
    True
    """

    def __init__(self, warp: FrictionParams | None, weft: FrictionParams | None, shape=()):
        if warp is None and weft is None:
            raise ParameterError("sheet friction needs the friction law of at least one direction")
        if warp is None:
            warp = _silent(weft)
        elif weft is None:
            weft = _silent(warp)
        self.warp, self.weft = warp, weft
        self.shape = tuple(int(n) for n in shape) if np.iterable(shape) else (int(shape),)
        self._fast = _DahlTensor(warp.f1, weft.f1, warp.a1, weft.a1)
        self._slow = _DahlTensor(warp.f2, weft.f2, warp.a2, weft.a2)
        for part in (self._fast, self._slow):
            if np.broadcast_shapes(self.shape + (3,), part.sf.shape) != self.shape + (3,):
                raise ParameterError(f"friction parameters of shape {part.sf.shape[:-1]} do not "
                                     f"broadcast to the state shape {self.shape}")
        self.kappa = np.zeros(self.shape + (3,))
        self.y1 = np.zeros(self.shape + (3,))
        self.y2 = np.zeros(self.shape + (3,))
        self._cache = None

    def _increment(self, kappa):
        kappa = np.asarray(kappa, dtype=float)
        if kappa.shape[-1:] != (3,):
            raise ValueError(f"sheet curvature must end in 3 Voigt components, got shape {kappa.shape}")
        return kappa, kappa - self.kappa

    def _update(self, dk, tangent: bool):
        """``(M, dM/dκ or None, y1, y2)`` after the increment ``dk`` from the committed state,
        by the compiled kernel (:func:`constitutive.sheet_friction_kernel.dahl_pair`)."""
        shape = np.broadcast_shapes(np.shape(dk), self.y1.shape)[:-1]
        flat = [np.ascontiguousarray(np.broadcast_to(x, shape + (3,)), dtype=float).reshape(-1, 3)
                for x in (self.y1, self.y2, dk)]
        n = flat[0].shape[0]
        y1, y2, M = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))
        D = np.empty((n, 3, 3) if tangent else (0, 3, 3))
        dahl_pair(*flat, *self._fast.flat(shape), *self._slow.flat(shape), y1, y2, M, D, tangent)
        out = (M.reshape(shape + (3,)), D.reshape(shape + (3, 3)) if tangent else None)
        return out + (y1.reshape(shape + (3,)), y2.reshape(shape + (3,)))

    def trial(self, kappa):
        """Friction moment (…, 3) and its consistent tangent ``dM/dκ`` (…, 3, 3) at a trial
        Voigt curvature; the state is not changed."""
        kappa, dk = self._increment(kappa)
        M, D, y1, y2 = self._update(dk, True)
        self._cache = (kappa.copy(), y1, y2)
        return M, D

    def stick_tangent(self):
        """The tangent of a point that sticks at its committed state, (…, 3, 3), diagonal:
        the scalar law's ``f1 (1 + |y1|)/a1 − f2 (1 + |y2|)/a2`` with |y| the tensor norm."""
        return self._fast.stick(self.y1) - self._slow.stick(self.y2)

    def moment(self, kappa):
        """Friction moment alone at a trial curvature (no mutation)."""
        _, dk = self._increment(kappa)
        return self._update(dk, False)[0]

    def work(self, kappa):
        """Exact work ``∫ M_f · dκ`` from the committed to the trial curvature, per point."""
        _, dk = self._increment(kappa)
        return self._fast.work(self.y1, dk) - self._slow.work(self.y2, dk)

    def commit(self, kappa):
        """Accept ``kappa`` as the new committed curvature."""
        kappa = np.broadcast_to(np.asarray(kappa, dtype=float), self.shape + (3,))
        c = self._cache
        if c is not None and c[0].shape == kappa.shape and np.array_equal(c[0], kappa):
            y1, y2 = c[1], c[2]
        else:
            _, _, y1, y2 = self._update(kappa - self.kappa, False)
        self.y1 = np.broadcast_to(y1, self.kappa.shape).copy()
        self.y2 = np.broadcast_to(y2, self.kappa.shape).copy()
        self.kappa = kappa.copy()
        self._cache = None

    def state_dict(self) -> dict:
        """The committed state: ``kappa``, ``y1``, ``y2`` (each ``shape + (3,)``)."""
        return {"kappa": self.kappa.copy(), "y1": self.y1.copy(), "y2": self.y2.copy()}

    def load_state_dict(self, state: dict) -> None:
        """Restore a :meth:`state_dict` of a state of the same shape."""
        shape = self.shape + (3,)
        arrays = {k: restored_array(f"sheet friction state {k}", state, k, shape)
                  for k in ("kappa", "y1", "y2")}
        self.kappa, self.y1, self.y2 = arrays["kappa"], arrays["y1"], arrays["y2"]
        self._cache = None

    def copy(self):
        """Independent copy (same parameters, copied state arrays)."""
        new = SheetFrictionState.__new__(SheetFrictionState)
        new.__dict__.update(self.__dict__)
        new.kappa, new.y1, new.y2 = self.kappa.copy(), self.y1.copy(), self.y2.copy()
        new._cache = None
        return new


def _silent(params: FrictionParams) -> FrictionParams:
    """A direction without friction: no moment, the other direction's lengths."""
    zero = np.zeros_like(np.asarray(params.f1, dtype=float))
    out = object.__new__(FrictionParams)      # f1 = f2 = 0 breaks f1 > f2 on purpose: no friction
    for name, value in (("f1", zero), ("f2", zero), ("eps_f", params.eps_f), ("eta", params.eta)):
        object.__setattr__(out, name, value)
    return out
