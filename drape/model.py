"""What a structural model offers the integrator, the runner and the analyses.

:class:`drape.plate.KirchhoffPlate` (small deflection) and :class:`drape.shell.KirchhoffLoveShell`
(large rotation) both satisfy :class:`StructuralModel`; the runner (:mod:`drape.run`) and the
analyses (:mod:`drape.analyses`) use nothing else of them.
"""
from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

__all__ = ["StructuralModel"]


@runtime_checkable
class StructuralModel(Protocol):
    """The interface of a structural model (plate or shell).

    A state is ``(u, v, a)``: the global dof vector and its first and second time derivatives.
    """

    mesh: object
    material: object
    ndofs: int
    fixed_dofs: np.ndarray
    load_scale: float

    # ------------------------------------------------------------------ loads and time
    @property
    def load_time(self) -> float:
        """Time [s] of the last force evaluation; time-dependent loads are read at it."""

    def prescribed(self, t: float):
        """``(dofs, values)`` imposed at ``t``, or None."""

    def force_scale(self, t: float) -> float:
        """A typical force norm (full self-weight, edge loads) for relative residual tests."""

    # ------------------------------------------------------------------ forces
    def residual(self, u, v, a, t: float):
        """``R = M a + C v + f_int(u) − f_ext(t)`` and its derivatives ``(K, C, M)``."""

    def commit(self, u, v, a) -> None:
        """Accept a converged state (law states, work ledgers)."""

    def state_dict(self) -> dict:
        """What :meth:`commit` keeps, as named arrays (a run's checkpoint saves it)."""

    def load_state_dict(self, state: dict) -> None:
        """Restore a :meth:`state_dict` of a model built from the same case."""

    # ------------------------------------------------------------------ results
    def energies(self, u, v, t: float | None = None) -> dict:
        """Kinetic, strain, external potential, friction and damping work [J] and their total.

        ``t`` evaluates the loads' potential (default: :attr:`load_time`).
        """

    def nodal_displacement(self, u) -> np.ndarray:
        """Displacement 3-vectors at the mesh vertices, shape (n_points, 3)."""

    def fields(self, u, v, a) -> dict:
        """Output data ``{"point_data": {...}, "cell_data": {...}}`` (cell data are averages)."""
