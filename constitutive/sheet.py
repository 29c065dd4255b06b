"""The bending law of a sheet: warp and weft laws, twist, and how friction sees the curvature.

A sheet's curvature is a tensor, (κ11, κ22, 2 κ12) in Voigt order, and its moment
(M11, M22, M12). The elastic part is per direction, as measured: ``k1 κ + k3 κ³`` of the
warp law on κ11 and of the weft law on κ22 (:class:`constitutive.law.BendingLaw`), and a
linear twist ``M12 = D_t κ12``. The dry friction is either

- ``"tensor"``: one frame-invariant law on the curvature tensor
  (:class:`constitutive.sheet_friction.SheetFrictionState`), which reduces to each
  direction's scalar law when the sheet bends along that yarn; or
- ``"per_direction"``: each direction's scalar law on its own curvature, twist
  frictionless (Lahey 2002, applied axis by axis).

Both agree in a strip bent along a yarn (the KES-FB and Peirce tests); they part where a
sheet bends about other axes, as a draping skirt does (docs/theory.md §2).

>>> from constitutive.friction import FrictionParams
>>> law = BendingLaw(k1=1.0, friction=FrictionParams(1.0, 0.0, 1.0, 0.5))
>>> sheet = SheetLaw(law, law, twist=1.0)
>>> M, D = sheet.new_state((1,)).trial(np.array([[1.0, 0.0, 0.0]]))
>>> np.round(M, 4).tolist(), D.shape
([[1.8647, 0.0, 0.0]], (1, 3, 3))
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from constitutive.friction import ParameterError, restored_array
from constitutive.law import BendingLaw, check_friction_tangent
from constitutive.sheet_friction import SheetFrictionState

__all__ = ["FRICTION_FRAMES", "SheetLaw", "SheetState"]

#: How a sheet's friction sees its curvature (:class:`SheetLaw`).
FRICTION_FRAMES = ("tensor", "per_direction")


@dataclass(frozen=True, eq=False)
class SheetLaw:
    """Bending law of a sheet (SI).

    Parameters
    ----------
    warp, weft : BendingLaw
        The directions' laws (κ11 along the warp, x; κ22 along the weft, y).
    twist : float
        Twist rigidity D_t [N·m]: ``M12 = D_t κ12``.
    friction : {"tensor", "per_direction"}
        How the friction sees the curvature (module docstring).
    """

    warp: BendingLaw
    weft: BendingLaw
    twist: float
    friction: str = "tensor"

    def __post_init__(self):
        if self.friction not in FRICTION_FRAMES:
            raise ParameterError(f"friction = {self.friction!r} must be one of {FRICTION_FRAMES}")
        if not (np.isfinite(self.twist) and self.twist > 0):
            raise ParameterError(f"twist = {self.twist!r} breaks twist > 0 (positive twist rigidity)")
        object.__setattr__(self, "twist", float(self.twist))

    @property
    def has_friction(self) -> bool:
        """True if either direction has dry friction."""
        return self.warp.friction is not None or self.weft.friction is not None

    @property
    def viscosity(self) -> np.ndarray:
        """``[[d_warp, d_weft], [m_warp, m_weft]]``: viscosity and curvature inertia."""
        return np.array([[self.warp.d, self.weft.d], [self.warp.m, self.weft.m]], dtype=float)

    def elastic(self, kappa):
        """Elastic Voigt moment and its (diagonal) tangent, (…, 3) and (…, 3, 3)."""
        kappa = np.asarray(kappa, dtype=float)
        M1, D1 = self.warp.elastic(kappa[..., 0])
        M2, D2 = self.weft.elastic(kappa[..., 1])
        half = 0.5 * self.twist
        M = np.stack(np.broadcast_arrays(M1, M2, half * kappa[..., 2]), -1)
        D = np.zeros(M.shape + (3,))
        D[..., 0, 0], D[..., 1, 1], D[..., 2, 2] = D1, D2, half
        return M, D

    def elastic_energy(self, kappa):
        """Stored energy per unit area, ``W(κ11) + W(κ22) + D_t κ12²`` [J/m²]."""
        kappa = np.asarray(kappa, dtype=float)
        return (self.warp.elastic_energy(kappa[..., 0]) + self.weft.elastic_energy(kappa[..., 1])
                + 0.25 * self.twist * kappa[..., 2] ** 2)

    def new_state(self, shape=()) -> "SheetState":
        """A state at rest for material points of ``shape``."""
        return SheetState(self, shape)


class SheetState:
    """History of an array of material points under one :class:`SheetLaw`.

    The interface the FE layer holds: ``trial`` (no mutation, any number of times),
    ``commit`` (once per converged step; it gives ``kappa`` a new array), the friction's
    work and moment, and ``state_dict``/``load_state_dict`` for checkpoints.
    """

    def __init__(self, law: SheetLaw, shape=()):
        self.law = law
        self.shape = tuple(int(n) for n in shape) if np.iterable(shape) else (int(shape),)
        self.tensor = None
        if law.friction == "tensor" and law.has_friction:
            self.tensor = SheetFrictionState(law.warp.friction, law.weft.friction, self.shape)
            laws = [dataclasses.replace(x, friction=None) for x in (law.warp, law.weft)]
        else:
            laws = [law.warp, law.weft]
        self.directions = [x.new_state(self.shape) for x in laws]
        self.kappa = np.zeros(self.shape + (3,))

    def trial(self, kappa, friction_tangent: str = "consistent"):
        """Voigt moment (…, 3) and its tangent ``dM/dκ`` (…, 3, 3) at a trial curvature.

        ``friction_tangent`` as in :meth:`constitutive.law.BendingState.trial`; with the
        tensor friction ``"nonnegative"`` keeps the positive semi-definite part of the
        friction tangent's symmetric part and ``"stick"`` is its stick tangent floored at 0.
        """
        check_friction_tangent(friction_tangent)
        kappa = np.asarray(kappa, dtype=float)
        M, D = self.law.elastic(kappa)
        for i, st in enumerate(self.directions):
            if st.friction is not None:
                Mi, Di = st.trial(kappa[..., i], friction_tangent)
                M[..., i], D[..., i, i] = Mi, Di
        if self.tensor is not None:
            Mf, Df = self.tensor.trial(kappa)
            if friction_tangent == "nonnegative":
                Df = _nonnegative(Df)
            elif friction_tangent == "stick":
                Df = np.maximum(self.tensor.stick_tangent(), 0.0)
            M, D = M + Mf, D + Df
        return M, D

    def friction_moment(self, kappa):
        """Friction part of the Voigt moment (zeros without friction)."""
        kappa = np.asarray(kappa, dtype=float)
        if self.tensor is not None:
            return self.tensor.moment(kappa)
        return np.stack([st.friction_moment(kappa[..., i]) for i, st in enumerate(self.directions)]
                        + [np.zeros(kappa.shape[:-1])], -1)

    def friction_work(self, kappa):
        """Exact work ``∫ M_f · dκ`` [J/m²] from the committed to the trial curvature."""
        kappa = np.asarray(kappa, dtype=float)
        if self.tensor is not None:
            return self.tensor.work(kappa)
        return sum(st.friction_work(kappa[..., i]) for i, st in enumerate(self.directions))

    def commit(self, kappa):
        """Accept ``kappa`` (once per converged step)."""
        kappa = np.broadcast_to(np.asarray(kappa, dtype=float), self.shape + (3,))
        for i, st in enumerate(self.directions):
            st.commit(kappa[..., i])
        if self.tensor is not None:
            self.tensor.commit(kappa)
        self.kappa = kappa.copy()

    def state_dict(self) -> dict:
        """Named arrays: ``kappa`` (Voigt), ``warp.*``, ``weft.*`` and, with the tensor friction,
        ``friction.*``."""
        out = {"kappa": self.kappa.copy()}
        out.update({f"{name}.{k}": v for name, st in zip(("warp", "weft"), self.directions)
               for k, v in st.state_dict().items()})
        if self.tensor is not None:
            out.update({f"friction.{k}": v for k, v in self.tensor.state_dict().items()})
        return out

    def load_state_dict(self, state: dict) -> None:
        """Restore a :meth:`state_dict` of a state of the same law and shape."""
        has_tensor = any(k.startswith("friction.") for k in state)
        if has_tensor != (self.tensor is not None):
            raise ValueError("sheet bending state: saved " + ("with" if has_tensor else "without")
                             + " tensor friction, but the law has "
                             + ("none" if has_tensor else "it"))
        for name, st in zip(("warp", "weft"), self.directions):
            st.load_state_dict({k[len(name) + 1:]: v for k, v in state.items()
                                if k.startswith(f"{name}.")})
        if self.tensor is not None:
            self.tensor.load_state_dict({k[len("friction."):]: v for k, v in state.items()
                                         if k.startswith("friction.")})
        self.kappa = restored_array("sheet bending state kappa", state, "kappa", self.shape + (3,))


def _nonnegative(D):
    """The positive semi-definite part of ``sym(D)`` (eigenvalues floored at zero)."""
    sym = 0.5 * (D + np.swapaxes(D, -1, -2))
    lam, vec = np.linalg.eigh(sym)
    return np.einsum("...ik,...k,...jk->...ij", vec, np.maximum(lam, 0.0), vec)
