"""Sparse direct solvers for Newton's linear systems, restricted to the free dofs.

A drape step solves ``J Δu = −R`` several times with tangents that share one
sparsity pattern. :class:`DirectSolver` separates the three phases of a direct
solver and does each only when needed:

- *analysis* (fill-reducing ordering, symbolic factorisation): once per pattern;
- *factorisation*: once per tangent;
- *solve*: once per right-hand side (a simplified Newton correction reuses the
  last factorisation).

Two back ends:

- ``"pardiso"``: Intel MKL PARDISO (through the ``mkl_rt`` library that
  ``pypardiso`` ships), multithreaded, with its analysis phase kept across
  factorisations. A symmetric tangent is factorised from its upper triangle by
  Cholesky (``mtype = 2``) while it is positive definite, as a stable state's is,
  and as *real symmetric indefinite* (``mtype = −2``, Bunch–Kaufman pivoting) where
  it is not, past a buckling point; a nonsymmetric one as *real nonsymmetric*
  (``mtype = 11``).
- ``"superlu"``: SciPy's SuperLU with a minimum-degree ordering of ``A + Aᵀ``
  and no pivoting (finite-element tangents are structurally symmetric), falling
  back to partial pivoting when that fails; available everywhere.

``"auto"`` takes PARDISO where it loads (x86-64 with ``pypardiso`` installed)
for systems of :data:`PARDISO_MIN_ORDER` unknowns or more, and SuperLU otherwise.

Examples
--------
>>> import numpy as np, scipy.sparse as sp
>>> A = sp.csr_matrix(np.array([[4.0, 1.0, 0.0], [1.0, 3.0, 1.0], [0.0, 1.0, 2.0]]))
>>> solver = DirectSolver(symmetric=True, backend="superlu")
>>> solver.factorize(A)
>>> np.allclose(A @ solver.solve(np.ones(3)), 1.0)
True
>>> solver.factorize(2 * A)          # same pattern: no new analysis
>>> solver.analyses, solver.factorizations, solver.solves
(1, 2, 1)
"""
from __future__ import annotations

import ctypes
import glob
import os
import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import prange

from drape.fem.compiled import njit

__all__ = ["LinearSolverError", "FreeRestriction", "DirectSolver", "pardiso_available", "blas_threads"]

BACKENDS = ("auto", "pardiso", "superlu")
#: "auto" takes SuperLU below this order: PARDISO's thread start-up outweighs its speed there.
PARDISO_MIN_ORDER = 2000


def blas_threads(limit: int = 1):
    """Context in which NumPy's BLAS (OpenBLAS) uses at most ``limit`` threads.

    In a drape step the cores are taken by the compiled element kernels (numba) and by
    PARDISO (OpenMP); OpenBLAS threads waking for vector norms and small products on top of
    them wait for a core, and a 13 000-entry norm then costs milliseconds instead of
    microseconds (a Newmark step of the Cusick drape: 5.9 s with the default, 3.9 s with
    one BLAS thread, benchmarks/bench_cusick.py). Uses ``threadpoolctl``.
    """
    from threadpoolctl import ThreadpoolController

    # OpenBLAS only: MKL's threads are PARDISO's, set by MKL itself
    return ThreadpoolController().select(internal_api="openblas").limit(limits=limit)


class LinearSolverError(RuntimeError):
    """The linear solver failed (singular matrix, solver error code); Newton treats the step as failed.

    ``code`` is the back end's error code, where it gives one (PARDISO's ``error``)."""

    def __init__(self, message: str, code: int | None = None):
        super().__init__(message)
        self.code = code


def _same_memory(x, y) -> bool:
    """The same array in memory (scipy's CSR constructor keeps views, not the objects given)."""
    return x is y or (x.dtype == y.dtype and x.shape == y.shape and x.strides == y.strides
                      and x.ctypes.data == y.ctypes.data)


def _same_pattern(A, pattern) -> bool:
    if pattern is None:
        return False
    indptr, indices = pattern
    return (_same_memory(A.indptr, indptr) and _same_memory(A.indices, indices)) or (
        A.indptr.shape == indptr.shape and A.indices.shape == indices.shape
        and np.array_equal(A.indptr, indptr) and np.array_equal(A.indices, indices))


class FreeRestriction:
    """``J[free][:, free]`` (and optionally its upper triangle) of CSR matrices sharing a pattern.

    The map from ``J.data`` to the restricted matrix's data is computed once per
    pattern, so restricting a new tangent costs one gather (the
    restriction ``skfem.condense`` performs, without rebuilding the pattern each time).

    Parameters
    ----------
    free : ndarray of int
        Sorted free dofs.
    upper : bool
        Keep only the upper triangle (with the diagonal) of the restricted matrix.

    Examples
    --------
    >>> import numpy as np, scipy.sparse as sp
    >>> J = sp.csr_matrix(np.arange(1.0, 10.0).reshape(3, 3))
    >>> FreeRestriction(np.array([0, 2]))(J).toarray()
    array([[1., 3.],
           [7., 9.]])
    >>> FreeRestriction(np.array([0, 2]), upper=True)(J).toarray()
    array([[1., 3.],
           [0., 9.]])
    """

    def __init__(self, free, upper: bool = False):
        self.free = np.asarray(free, dtype=np.int64)
        self.upper = bool(upper)
        self._pattern = None

    def __call__(self, J) -> sp.csr_matrix:
        J = J if sp.isspmatrix_csr(J) else sp.csr_matrix(J)
        if not _same_pattern(J, self._pattern):
            self._build(J)
        self._pattern = (J.indptr, J.indices)   # an equal pattern elsewhere in memory: check it once
        data = np.empty(self._map.size)
        _gather(self._map, np.ascontiguousarray(J.data, dtype=float), data)
        A = sp.csr_matrix((data, self._indices, self._indptr), shape=self._shape)
        A.has_sorted_indices = True             # sorted by _build; spares scipy's check
        return A

    def _build(self, J):
        # restrict a matrix whose data are the positions (1-based) of J's entries
        probe = sp.csr_matrix((np.arange(1, J.nnz + 1, dtype=float), J.indices, J.indptr), shape=J.shape)
        sub = probe[self.free][:, self.free]
        if self.upper:
            sub = sp.triu(sub, format="csr")
        sub.sort_indices()
        self._map = sub.data.astype(np.int64) - 1
        self._indices, self._indptr, self._shape = sub.indices, sub.indptr, sub.shape


@njit(cache=True, parallel=True)
def _gather(positions, data, out):
    """``out = data[positions]`` on every core (numpy's fancy indexing of a million
    entries takes several times longer)."""
    for i in prange(positions.size):
        out[i] = data[positions[i]]


def _mkl_pardiso():
    """MKL's ``pardiso`` entry point from the ``mkl_rt`` library, or None.

    The library is the one pypardiso's ``mkl`` dependency installs into the environment's
    ``lib``; pypardiso itself is not imported (it searches the whole of ``sys.prefix`` for
    that library when imported, a second or more).
    """
    names = [os.path.join(sys.prefix, "lib", "libmkl_rt.so*"), os.path.join(sys.prefix, "lib", "libmkl_rt*.dylib"),
             os.path.join(sys.prefix, "Library", "bin", "mkl_rt*.dll")]
    for path in sorted(p for pattern in names for p in glob.glob(pattern)):
        try:
            function = ctypes.CDLL(path).pardiso
        except (OSError, AttributeError):
            continue
        c_int = ctypes.POINTER(ctypes.c_int32)
        function.argtypes = [ctypes.POINTER(ctypes.c_int64), c_int, c_int, c_int, c_int, c_int,
                             ctypes.c_void_p, c_int, c_int, c_int, c_int, c_int, c_int,
                             ctypes.c_void_p, ctypes.c_void_p, c_int]
        function.restype = None
        return function
    return None


_PARDISO = None


def pardiso_available() -> bool:
    """True when MKL PARDISO can be loaded (``pypardiso`` installed on x86-64)."""
    global _PARDISO
    if _PARDISO is None:
        _PARDISO = _mkl_pardiso() or False
    return _PARDISO is not False


class _Pardiso:
    """MKL PARDISO of one matrix type with phases called separately: 11 (analysis) per
    pattern, 22, 33. ``mtype``: 2 real symmetric positive definite, −2 real symmetric
    indefinite, 11 real nonsymmetric."""

    def __init__(self, mtype: int):
        if not pardiso_available():
            raise LinearSolverError("MKL PARDISO is not available (install pypardiso on x86-64)")
        self.mtype = int(mtype)
        self.pt = np.zeros(64, dtype=np.int64)
        self.iparm = np.zeros(64, dtype=np.int32)
        # 0-based iparm indices (MKL manual): user values; METIS ordering; default
        # iterative refinement; pivot perturbation 1e-8 (sym) / 1e-13 (unsym);
        # scaling and weighted matching; Bunch-Kaufman pivoting; zero-based indexing
        for k, value in {0: 1, 1: 2, 7: 0, 9: 13 if mtype == 11 else 8, 10: 1, 12: 1, 20: 1, 34: 1}.items():
            self.iparm[k] = value
        self._A = None
        self._analysed = False

    def _call(self, phase, A, b=None, x=None):
        c_int, c_double = ctypes.POINTER(ctypes.c_int32), ctypes.POINTER(ctypes.c_double)
        error = ctypes.c_int32(0)
        nrhs = 1
        b = np.zeros(1) if b is None else b
        x = np.zeros(1) if x is None else x
        perm = np.zeros(1, dtype=np.int32)
        _PARDISO(self.pt.ctypes.data_as(ctypes.POINTER(ctypes.c_int64)),
                 ctypes.byref(ctypes.c_int32(1)), ctypes.byref(ctypes.c_int32(1)),
                 ctypes.byref(ctypes.c_int32(self.mtype)), ctypes.byref(ctypes.c_int32(phase)),
                 ctypes.byref(ctypes.c_int32(A.shape[0])), A.data.ctypes.data_as(c_double),
                 A.indptr.ctypes.data_as(c_int), A.indices.ctypes.data_as(c_int),
                 perm.ctypes.data_as(c_int), ctypes.byref(ctypes.c_int32(nrhs)),
                 self.iparm.ctypes.data_as(c_int), ctypes.byref(ctypes.c_int32(0)),
                 b.ctypes.data_as(c_double), x.ctypes.data_as(c_double), ctypes.byref(error))
        if error.value != 0:
            raise LinearSolverError(f"PARDISO phase {phase} failed with error {error.value}", error.value)

    def analyse(self, A):
        self.release()
        self._A = A
        self._call(11, A)
        self._analysed = True

    def factorize(self, A):
        self._A = A
        self._call(22, A)

    def solve(self, b):
        b = np.ascontiguousarray(b, dtype=float)
        x = np.zeros_like(b)
        self._call(33, self._A, b, x)
        return x

    def release(self):
        if self._analysed:
            self._call(-1, self._A)
            self._analysed = False

    def __del__(self):
        try:
            self.release()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass


class _PardisoSymmetric:
    """Cholesky (PARDISO ``mtype = 2``) while the matrices are positive definite, Bunch–Kaufman
    LDLᵀ (``mtype = −2``) for those that are not.

    A stable state's tangent is positive definite, and Cholesky needs no pivoting: it is
    about a fifth faster to factorise and a third faster to solve. Where the fabric passes
    a buckling point, the Cholesky factorisation stops at the first non-positive pivot
    (PARDISO error −4); that matrix and the next :attr:`RETRY_AFTER` are factorised as
    indefinite, whose analysis is done once per pattern too.
    """

    #: Factorisations that go straight to LDLᵀ after a matrix that was not positive definite.
    RETRY_AFTER = 8

    def __init__(self):
        self.cholesky, self.ldlt = _Pardiso(2), _Pardiso(-2)
        self._ldlt_pattern = False
        self._cholesky_pattern = False
        self._active = None
        self._skip = 0
        self.ldlt_count = 0

    def analyse(self, A):
        self._ldlt_pattern = False
        try:
            self.cholesky.analyse(A)
            self._cholesky_pattern = True
        except LinearSolverError:   # e.g. a diagonal entry missing from the pattern
            self._cholesky_pattern = False

    def factorize(self, A):
        if self._skip:
            self._skip -= 1
        elif self._cholesky_pattern:
            try:
                self.cholesky.factorize(A)
                self._active = self.cholesky
                return
            except LinearSolverError as exc:
                if exc.code != -4:   # -4: a zero or negative pivot
                    raise
                self._skip = self.RETRY_AFTER
        if not self._ldlt_pattern:
            self.ldlt.analyse(A)
            self._ldlt_pattern = True
        self.ldlt.factorize(A)
        self._active = self.ldlt
        self.ldlt_count += 1

    def solve(self, b):
        return self._active.solve(b)

    def release(self):
        self.cholesky.release()
        self.ldlt.release()


class _SuperLU:
    """SuperLU: minimum degree on ``A + Aᵀ`` without pivoting, partial pivoting as fallback."""

    def __init__(self, symmetric: bool):
        self.symmetric = symmetric
        self._lu = None

    def analyse(self, A):
        pass  # SuperLU orders inside each factorisation

    def factorize(self, A):
        if self.symmetric:  # the upper triangle stands for the whole matrix
            A = A + sp.triu(A, k=1, format="csr").T
        A = sp.csc_matrix(A)
        try:
            self._lu = spla.splu(A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                 options=dict(SymmetricMode=True))
            b = A @ np.ones(A.shape[0])
            r = A @ self._lu.solve(b) - b
            if np.all(np.isfinite(r)) and np.linalg.norm(r) <= 1e-8 * np.linalg.norm(b):
                return
        except RuntimeError:  # a zero pivot without pivoting
            pass
        try:
            self._lu = spla.splu(A)
        except RuntimeError as exc:
            raise LinearSolverError(f"SuperLU: {exc}") from None

    def solve(self, b):
        return self._lu.solve(np.asarray(b, dtype=float))


class DirectSolver:
    """Factorise once, solve many times; analyse once per sparsity pattern.

    Parameters
    ----------
    symmetric : bool
        The matrices are symmetric: only their upper triangles are used
        (give them as :class:`FreeRestriction` ``upper=True`` output or in full).
    backend : {"auto", "pardiso", "superlu"}
        ``"auto"`` is decided at the first factorisation, by the order of the matrix.

    Attributes
    ----------
    analyses, factorizations, solves : int
        How often each phase ran.
    ldlt_factorizations : int
        Symmetric factorisations done by LDLᵀ (PARDISO): those of matrices on which Cholesky met
        a non-positive pivot, and of the few after each (``_PardisoSymmetric.RETRY_AFTER``).
    seconds : dict
        Wall time spent in each phase.
    tag : hashable or None
        What the last factorised matrix is, as its caller named it (``factorize(A, tag)``):
        a caller that finds its own tag may solve with the factorisation instead of
        factorising its matrix anew (a modified Newton keeps a tangent across steps).
    """

    def __init__(self, symmetric: bool = False, backend: str = "auto"):
        if backend not in BACKENDS:
            raise ValueError(f"backend = {backend!r}: must be one of {BACKENDS}")
        self.backend = backend
        self.symmetric = bool(symmetric)
        self._impl = None
        self._pattern = self._input = self._triu = None
        self.analyses = self.factorizations = self.solves = 0
        self.seconds = {"analysis": 0.0, "factorization": 0.0, "solve": 0.0}
        self.tag = None

    def factorize(self, A, tag=None) -> None:
        """Factorise ``A`` (CSR), named ``tag``; a new sparsity pattern is analysed first."""
        self.tag = None
        A = A if sp.isspmatrix_csr(A) else sp.csr_matrix(A)
        t0 = time.perf_counter()
        if not _same_pattern(A, self._input):
            full = self.symmetric and not _is_upper(A)
            # a full symmetric matrix: keep its upper triangle through a cached index map
            self._triu = FreeRestriction(np.arange(A.shape[0]), upper=True) if full else None
        self._input = (A.indptr, A.indices)   # an equal pattern elsewhere in memory: compared once
        if self._triu is not None:
            A = self._triu(A)
        elif not A.has_sorted_indices:
            A = A.sorted_indices()
        A.indptr, A.indices = A.indptr.astype(np.int32, copy=False), A.indices.astype(np.int32, copy=False)
        if self._impl is None:
            self._impl = self._backend(A.shape[0])
        if not _same_pattern(A, self._pattern):
            self._impl.analyse(A)
            self.analyses += 1
        self._pattern = (A.indptr, A.indices)
        t1 = time.perf_counter()
        self._impl.factorize(A)
        self.factorizations += 1
        self.tag = tag
        t2 = time.perf_counter()
        self.seconds["analysis"] += t1 - t0
        self.seconds["factorization"] += t2 - t1

    @property
    def ldlt_factorizations(self) -> int:
        """Symmetric factorisations done by LDLᵀ (PARDISO only; 0 for SuperLU)."""
        return int(getattr(self._impl, "ldlt_count", 0))

    def _backend(self, n: int):
        if self.backend == "auto":
            self.backend = "pardiso" if n >= PARDISO_MIN_ORDER and pardiso_available() else "superlu"
        if self.backend == "superlu":
            return _SuperLU(self.symmetric)
        return _PardisoSymmetric() if self.symmetric else _Pardiso(11)

    def solve(self, b) -> np.ndarray:
        """``A⁻¹ b`` with the last factorisation; LinearSolverError if the result is not finite."""
        t0 = time.perf_counter()
        x = self._impl.solve(b)
        self.solves += 1
        self.seconds["solve"] += time.perf_counter() - t0
        if not np.all(np.isfinite(x)):
            raise LinearSolverError("the solution of the linear system is not finite (singular matrix)")
        return x


def _is_upper(A) -> bool:
    rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    return bool(np.all(A.indices >= rows))
