"""Seedable out-of-plane imperfection that lets a symmetric drape buckle into folds.

A flat Cusick specimen under gravity has an axisymmetric equilibrium (a cone)
that is unstable: the hem must shorten its circumference and does so by
folding.  A perfect mesh and solver would pick the folds from round-off, i.e.
from the mesh.  To make the fold pattern a documented input, the drape starts
from a small out-of-plane field on the hanging annulus,

.. math:: w(\\rho, \\varphi) = A\\, s(\\rho)\\, g(\\varphi),\\qquad
          s = \\left(\\frac{\\rho - r_d}{R - r_d}\\right)^2,\\qquad
          g = \\sum_k c_k \\cos(k\\varphi + \\varphi_k),

applied in one of three ways (``target``):

* ``"force"`` (recommended) — a transient out-of-plane load per unit area
  ``f_z = A ρ_A g s g(φ) h(t)`` with ``A`` a fraction of the weight and
  ``h = sin²(π t / duration)`` on ``[0, duration]``, zero after: a seeded draught of
  air.  The drape starts at rest (consistent initial acceleration), the load is a
  smooth field integrated by quadrature, hence the same on every mesh, and the
  settled shape is an equilibrium of gravity alone;
* ``"displacement"`` — initial ``u_z`` (``A`` in m);
* ``"velocity"`` — initial ``v_z`` (``A`` in m/s).  With the law's viscosity ``d κ̇``
  this start is inconsistent at the free hem (``κ̇_rr ≠ 0`` where the moment must
  vanish): the initial acceleration then carries mesh-scale content that grows with
  refinement.

``s`` vanishes with its slope at the disc edge, so the field respects the clamp.
Two kinds:

* ``"lobed"`` — one mode ``k = n_lobes`` with a seeded phase (imposes ``n`` folds);
* ``"random"`` — modes ``k_min..k_max`` with seeded normal amplitudes and uniform
  phases, scaled so ``max |g| = 1`` (lets the fabric choose its own node count).

The same ``seed`` always gives the same field (``numpy.random.default_rng``).

A strip or rectangle held (or first touching) at its left end carries the same kind of field
along its length, :class:`StripPerturbation`: ``w = A ξ² g(ξ)`` with ``ξ = x / L`` and
``g = Σ c_k cos(k π ξ + φ_k)``, zero with its slope at ``x = 0``. A strip laid down is never
quite straight; without such a field a strip compressed along its length (its leading end
stopped on a floor) can stay on the straight, unstable equilibrium that a symmetric start and
an exact Newton tangent keep it on.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from drape.fem.argyris import interpolate

__all__ = ["PerturbationError", "FoldPerturbation", "StripPerturbation", "perturbation_dofs"]


class PerturbationError(ValueError):
    """Invalid perturbation parameter."""


_KINDS = ("none", "lobed", "random")
_TARGETS = ("force", "displacement", "velocity")


@dataclass(frozen=True, kw_only=True)
class _SeededImperfection:
    """The seeded modes, the target and the time profile that every imperfection shares.

    Subclasses give the geometry: ``value``, ``grad``, ``hess`` of ``w`` at points (2, ...) and
    ``_mode_arguments``, the range of the modes' argument over the specimen (where
    ``max |g| = 1`` is taken).
    """

    kind: str = "random"
    amplitude: float = 1e-3
    seed: int = 0
    n_lobes: int = 6
    k_min: int = 2
    k_max: int = 12
    target: str = "displacement"
    duration: float = 0.2

    def __post_init__(self):
        if self.kind not in _KINDS:
            raise PerturbationError(f"perturbation.kind = {self.kind!r}: must be one of {_KINDS}")
        if self.target not in _TARGETS:
            raise PerturbationError(f"perturbation.target = {self.target!r}: must be one of {_TARGETS}")
        if not (np.isfinite(self.amplitude) and self.amplitude >= 0.0):
            raise PerturbationError(f"perturbation.amplitude = {self.amplitude!r}: must be >= 0")
        if not (np.isfinite(self.duration) and self.duration > 0.0):
            raise PerturbationError(f"perturbation.duration = {self.duration!r}: must be > 0 (s)")
        if self.kind == "lobed" and self.n_lobes < 1:
            raise PerturbationError(f"perturbation.n_lobes = {self.n_lobes!r}: must be >= 1")
        if self.kind == "random" and not (1 <= self.k_min <= self.k_max):
            raise PerturbationError(
                f"perturbation.k_min = {self.k_min!r}, k_max = {self.k_max!r}: need 1 <= k_min <= k_max")

    def _mode_arguments(self) -> np.ndarray:
        raise NotImplementedError

    def modes(self):
        """Mode numbers ``k``, amplitudes ``c_k`` and phases ``phi_k`` of ``g``."""
        rng = np.random.default_rng(self.seed)
        if self.kind == "none":
            return np.zeros(0, int), np.zeros(0), np.zeros(0)
        if self.kind == "lobed":
            return np.array([self.n_lobes]), np.ones(1), rng.uniform(0, 2 * np.pi, 1)
        k = np.arange(self.k_min, self.k_max + 1)
        c = rng.standard_normal(k.size)
        ph = rng.uniform(0, 2 * np.pi, k.size)
        gmax = np.abs(np.cos(np.outer(self._mode_arguments(), k) + ph) @ c).max()
        return k, c / gmax, ph

    def _series(self, t):
        """``g``, ``dg/dt``, ``d²g/dt²`` at arguments ``t``."""
        k, c, ph = self.modes()
        arg = np.multiply.outer(t, k) + ph
        return np.cos(arg) @ c, -np.sin(arg) @ (c * k), -np.cos(arg) @ (c * k**2)

    def traction(self, x, areal_weight: float):
        """Force per unit area ``(0, 0, ρ_A g w(x))`` of target "force", shape (3, ...).

        ``areal_weight`` is ``ρ_A g`` [N/m²]; multiply by :meth:`time_profile`.
        """
        w = areal_weight * self.value(x)
        return np.stack([np.zeros_like(w), np.zeros_like(w), w])

    def time_profile(self, t: float) -> float:
        """``h(t) = sin²(π t / duration)`` on ``[0, duration]``, else 0 (C¹, starts from zero).

        >>> p = FoldPerturbation(0.09, 0.15, target="force", duration=0.2)
        >>> p.time_profile(0.0), p.time_profile(0.1), p.time_profile(0.3)
        (0.0, 1.0, 0.0)
        """
        if not 0.0 < t < self.duration:
            return 0.0
        return float(np.sin(np.pi * t / self.duration) ** 2)


@dataclass(frozen=True)
class FoldPerturbation(_SeededImperfection):
    """Out-of-plane imperfection ``w = A s(rho) g(phi)`` on a Cusick annulus.

    Parameters
    ----------
    disc_radius, specimen_radius : float
        r_d and R (m).
    kind : {"none", "lobed", "random"}
    amplitude : float
        A: fraction of the weight (target "force"), metres ("displacement") or m/s
        ("velocity").
    seed : int
        Seeds the phases (and amplitudes for "random").
    n_lobes : int
        Mode number for "lobed".
    k_min, k_max : int
        Mode range for "random".
    target : {"force", "displacement", "velocity"}
    duration : float
        Length (s) of the transient load of target "force".
    centre : tuple of float

    Examples
    --------
    >>> p = FoldPerturbation(0.09, 0.15, kind="lobed", amplitude=1e-3, n_lobes=6, seed=1)
    >>> phi = np.linspace(0.0, 2.0 * np.pi, 361)
    >>> hem = 0.15 * np.array([np.cos(phi), np.sin(phi)])   # s = 1 on the hem
    >>> round(float(np.abs(p.value(hem)).max()), 6)
    0.001
    >>> abs(float(p.value(np.array([[0.09], [0.0]]))[0]))   # zero on the disc edge
    0.0
    """

    disc_radius: float
    specimen_radius: float
    centre: tuple = (0.0, 0.0)

    def __post_init__(self):
        super().__post_init__()
        if not (0.0 < self.disc_radius < self.specimen_radius):
            raise PerturbationError(
                f"disc_radius = {self.disc_radius!r}, specimen_radius = {self.specimen_radius!r}: "
                "need 0 < disc_radius < specimen_radius")

    def _mode_arguments(self):
        return np.linspace(0, 2 * np.pi, 4096, endpoint=False)

    def _polar(self, x):
        dx, dy = x[0] - self.centre[0], x[1] - self.centre[1]
        rho = np.hypot(dx, dy)
        return rho, np.arctan2(dy, dx)

    def _rinv(self, rho):
        # w and its derivatives vanish on and inside the disc: no 1/rho singularity there
        inside = rho <= self.disc_radius
        return np.where(inside, 0.0, 1.0 / np.where(inside, 1.0, rho))

    def _parts(self, x):
        """Radial profile s, s', s'' and angular g, g', g'' at points x (2, ...)."""
        rho, phi = self._polar(np.asarray(x, dtype=float))
        L = self.specimen_radius - self.disc_radius
        xi = np.maximum(rho - self.disc_radius, 0.0) / L
        s, s1, s2 = xi**2, 2 * xi / L, np.where(rho > self.disc_radius, 2 / L**2, 0.0)
        return rho, phi, (s, s1, s2), self._series(phi)

    def value(self, x):
        """``w`` at points ``x`` of shape (2, ...)."""
        _, _, (s, _, _), (g, _, _) = self._parts(x)
        return self.amplitude * s * g

    def grad(self, x):
        """``(w_x, w_y)``, shape (2, ...)."""
        rho, phi, (s, s1, _), (g, g1, _) = self._parts(x)
        A, co, si = self.amplitude, np.cos(phi), np.sin(phi)
        w_r, w_p = A * s1 * g, A * s * g1
        rinv = self._rinv(rho)
        return np.array([w_r * co - w_p * si * rinv, w_r * si + w_p * co * rinv])

    def hess(self, x):
        """``[[w_xx, w_xy], [w_xy, w_yy]]``, shape (2, 2, ...) (polar chain rule)."""
        rho, phi, (s, s1, s2), (g, g1, g2) = self._parts(x)
        A, co, si = self.amplitude, np.cos(phi), np.sin(phi)
        w_r, w_p = A * s1 * g, A * s * g1
        w_rr, w_rp, w_pp = A * s2 * g, A * s1 * g1, A * s * g2
        ri = self._rinv(rho)
        xx = (w_rr * co**2 - 2 * w_rp * si * co * ri + w_pp * si**2 * ri**2
              + w_r * si**2 * ri + 2 * w_p * si * co * ri**2)
        yy = (w_rr * si**2 + 2 * w_rp * si * co * ri + w_pp * co**2 * ri**2
              + w_r * co**2 * ri - 2 * w_p * si * co * ri**2)
        xy = (w_rr * si * co + w_rp * (co**2 - si**2) * ri - w_pp * si * co * ri**2
              - w_r * si * co * ri - w_p * (co**2 - si**2) * ri**2)
        return np.array([[xx, xy], [xy, yy]])


@dataclass(frozen=True)
class StripPerturbation(_SeededImperfection):
    """Out-of-plane imperfection ``w = A ξ² g(ξ)``, ``ξ = x / L``, of a strip on ``[0, L]``.

    ``g = Σ c_k cos(k π ξ + φ_k)``: ``k`` half-waves over the length (``kind = "lobed"``: one
    mode ``k = n_lobes``), ``|g| ≤ 1``. ``ξ²`` makes ``w`` vanish with its slope at the left end,
    where a strip is held or first touches; ``w`` is uniform across the width.

    Parameters
    ----------
    length : float
        L (m), the strip's length along x.
    kind, amplitude, seed, n_lobes, k_min, k_max, target, duration
        As :class:`FoldPerturbation`.

    Examples
    --------
    >>> p = StripPerturbation(0.3, kind="random", amplitude=1e-3, seed=2)
    >>> x = np.array([np.linspace(0.0, 0.3, 301), np.zeros(301)])
    >>> w = p.value(x)
    >>> float(w[0]), bool(0 < np.abs(w).max() <= 1e-3)
    (0.0, True)
    """

    length: float

    def __post_init__(self):
        super().__post_init__()
        if not (np.isfinite(self.length) and self.length > 0.0):
            raise PerturbationError(f"perturbation length = {self.length!r}: must be > 0 (m)")

    def _mode_arguments(self):
        return np.linspace(0.0, np.pi, 4097)

    def _parts(self, x):
        xi = np.clip(np.asarray(x, dtype=float)[0] / self.length, 0.0, 1.0)
        g, g1, g2 = self._series(np.pi * xi)
        L, k = self.length, np.pi
        # d/dx of g(π ξ) is (π / L) g'; of ξ², 2 ξ / L
        return (xi**2, 2 * xi / L, np.full_like(xi, 2 / L**2)), (g, k * g1 / L, k**2 * g2 / L**2)

    def value(self, x):
        """``w`` at points ``x`` of shape (2, ...)."""
        (s, _, _), (g, _, _) = self._parts(x)
        return self.amplitude * s * g

    def grad(self, x):
        """``(w_x, w_y)``, shape (2, ...)."""
        (s, s1, _), (g, g1, _) = self._parts(x)
        w_x = self.amplitude * (s1 * g + s * g1)
        return np.array([w_x, np.zeros_like(w_x)])

    def hess(self, x):
        """``[[w_xx, 0], [0, 0]]``, shape (2, 2, ...)."""
        (s, s1, s2), (g, g1, g2) = self._parts(x)
        w_xx = self.amplitude * (s2 * g + 2 * s1 * g1 + s * g2)
        zero = np.zeros_like(w_xx)
        return np.array([[w_xx, zero], [zero, zero]])


def perturbation_dofs(basis, perturbation) -> np.ndarray:
    """Dof vector of the out-of-plane field in the shell's 3-vector layout (z component only).

    Parameters
    ----------
    basis : skfem.Basis
        The shell's *scalar* Argyris basis (``KirchhoffLoveShell.basis``); the returned
        vector uses the shell layout, global dof ``3 s + c`` for scalar dof ``s`` and
        component ``c`` (the same numbering as ``ElementVector`` of the element).
    perturbation : FoldPerturbation or StripPerturbation

    Returns
    -------
    ndarray, shape (3 * basis.N,)
        Use as ``u0`` or ``v0`` according to ``perturbation.target``.

    Examples
    --------
    >>> from skfem import Basis, MeshTri
    >>> from drape.fem.argyris import ElementTriArgyrisLocal
    >>> mesh = MeshTri.init_circle(2).scaled((0.15, 0.15))
    >>> basis = Basis(mesh, ElementTriArgyrisLocal())
    >>> p = FoldPerturbation(0.09, 0.15, kind="lobed", n_lobes=4, amplitude=1e-3)
    >>> x = perturbation_dofs(basis, p)
    >>> bool(np.all(x[0::3] == 0) and np.all(x[1::3] == 0) and np.abs(x[2::3]).max() > 0)
    True
    """
    from skfem.element import ElementVector


    if isinstance(basis.elem, ElementVector):
        raise PerturbationError("perturbation_dofs: pass the scalar basis (shell.basis), "
                                "not an ElementVector basis")
    w = interpolate(basis, perturbation.value, perturbation.grad, perturbation.hess)
    out = np.zeros(3 * basis.N)
    out[2::3] = w
    return out
