"""What a structural model offers the integrator, the runner and the analyses.

:class:`drape.models.plate.KirchhoffPlate` (small deflection) and :class:`drape.models.shell.KirchhoffLoveShell`
(large rotation) both satisfy :class:`StructuralModel`; the runner (:mod:`drape.run.runner`) and the
analyses (:mod:`drape.analyses`) use nothing else of them.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
import scipy.sparse as sp

__all__ = ["StructuralModel", "Evaluation", "free_dofs"]


def free_dofs(ndofs: int, fixed, imposed=()) -> np.ndarray:
    """The dofs (sorted) that are neither fixed (homogeneous Dirichlet) nor imposed.

    Examples
    --------
    >>> free_dofs(6, [0, 3], [5]).tolist()
    [1, 2, 4]
    """
    free = np.ones(int(ndofs), dtype=bool)
    free[np.asarray(fixed, dtype=np.int64)] = False
    free[np.asarray(imposed, dtype=np.int64)] = False
    return np.flatnonzero(free)


@dataclass
class Evaluation:
    """Forces of a model at a state ``(u, v, a, t)`` and, if asked for, their derivatives.

    The residual of the equation of motion is ``inertia + force``; HHT-α weights the two
    parts differently, hence they are kept apart.

    Attributes
    ----------
    inertia : ndarray
        ``M a`` (with the law's curvature inertia, if any).
    force : ndarray
        Everything else: ``C v + f_int(u) − f_ext(u, t)``, friction included.
    K, C, M : scipy.sparse.csr_matrix or None
        ``∂R/∂u``, ``∂R/∂v``, ``∂R/∂a`` (None when no tangent, or only their weighted sum,
        was asked for).
    J : scipy.sparse.csr_matrix or None
        ``c_K K + c_C C + c_M M`` when the caller gave weights: the one matrix an implicit
        step factorises, which a model may assemble in one pass.

    Examples
    --------
    >>> import scipy.sparse as sp
    >>> one = sp.csr_matrix([[1.0]])
    >>> ev = Evaluation(np.zeros(1), np.zeros(1), 4 * one, 2 * one, one).weighted((1.0, 10.0, 100.0))
    >>> ev.J.toarray(), ev.K
    (array([[124.]]), None)
    """

    inertia: np.ndarray
    force: np.ndarray
    K: object = None
    C: object = None
    M: object = None
    J: object = None

    @property
    def residual(self) -> np.ndarray:
        """``M a + C v + f_int − f_ext``."""
        return self.inertia + self.force

    def weighted(self, weights) -> "Evaluation":
        """This evaluation with ``J = c_K K + c_C C + c_M M`` in place of ``K, C, M``, for a model
        that assembles the three apart; ``weights`` None or no tangent: itself.

        Matrices on one CSR pattern are summed by their data, so ``J`` keeps that pattern
        (a sparse sum would drop entries that cancel, and a solver re-analyses a new pattern).
        """
        if weights is None or self.K is None:
            return self
        terms = [(float(c), sp.csr_matrix(A)) for c, A in zip(weights, (self.K, self.C, self.M))
                 if A is not None and (c != 0.0 or A is self.K)]
        K = terms[0][1]
        if all(A.shape == K.shape and np.array_equal(A.indptr, K.indptr) and np.array_equal(A.indices, K.indices)
               for _, A in terms[1:]):
            J = sp.csr_matrix((sum(c * A.data for c, A in terms), K.indices, K.indptr), shape=K.shape)
        else:
            J = sum((c * A for c, A in terms[1:]), terms[0][0] * K).tocsr()
        return Evaluation(self.inertia, self.force, J=J)


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
    rayleigh: tuple   # (alpha, beta) of the damping C = alpha M + beta K0
    seconds: dict   # wall time of "law" (the laws' trial moments) and "assembly" (the rest of evaluate)

    # ------------------------------------------------------------------ loads and time
    @property
    def load_time(self) -> float:
        """Time [s] of the last force evaluation; time-dependent loads are read at it."""

    def prescribed(self, t: float):
        """``(dofs, values)`` imposed at ``t``, or None."""

    def force_scale(self, t: float) -> float:
        """A typical force norm (full self-weight, edge loads) for relative residual tests."""

    def lifting(self, t: float):
        """``(u_p, v_p, a_p)``: a full-size field carrying the imposed motion with its exact
        rates, or None (the imposed dofs then get Newmark-consistent rates)."""

    # ------------------------------------------------------------------ forces
    @property
    def symmetric_tangent(self) -> bool:
        """True when every tangent :meth:`evaluate` returns is symmetric (a symmetric
        factorisation is then valid)."""

    def evaluate(self, u, v, a, t: float, tangent: str | None = None, weights=None) -> Evaluation:
        """Forces at ``(u, v, a, t)``; with ``tangent`` (a name of
        :data:`constitutive.law.FRICTION_TANGENTS`) also ``K, C, M`` with that
        material tangent, or with ``weights = (c_K, c_C, c_M)`` only their sum ``J``
        (:meth:`Evaluation.weighted`). Does not change the model's committed state."""

    def residual(self, u, v, a, t: float):
        """``R = M a + C v + f_int(u) − f_ext(t)`` and its derivatives ``(K, C, M)``
        (:meth:`evaluate` with the model's own friction tangent)."""

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
