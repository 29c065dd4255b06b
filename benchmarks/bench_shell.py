"""Benchmark of the large-rotation shell's residual and tangent evaluation.

The shell of ``cases/cusick_fabric1.toml`` (Fabric 1, Argyris, the 6 × 72 graded Cusick
annulus, assumed membrane strain) at a sagging state with a velocity and an acceleration,
timed for

1. the kinematics (strain and curvature at the quadrature points) and the laws' trial
   moments, which every evaluation needs;
2. the force-only pass, ``_internal(u, v)`` (line search, balance checks);
3. the force with a Newmark step's matrix ``c_K K + c_C C_law + c_M M_law``,
   ``_internal(u, v, a, weights)``;
4. the whole ``evaluate`` of a step (plus Rayleigh damping, mass, external loads; the
   step's matrix as CSR);
5. a force pass followed by the step matrix at the same point, as Newton's line search and
   its next tangent take them (the second reuses the first's kinematics and law trial; every
   other row starts without a kept trial);
6. the step matrix's restriction to the free dofs (upper triangle, as the symmetric solver
   takes it): :class:`drape.solvers.linear.FreeRestriction`'s gather on every core, and the same
   gather by ``np.take`` for comparison.

The first call compiles the kernels (or loads them from numba's cache) and is reported
apart. Threads follow ``NUMBA_NUM_THREADS``.

Run: ``python benchmarks/bench_shell.py [--radial 6] [--circumferential 72] [--repeat 5]``
"""

from __future__ import annotations

import argparse
import time

import numba
import numpy as np

from constitutive.material import load_material
from drape.solvers.linear import FreeRestriction
from drape.models.shell import KirchhoffLoveShell
from meshes import cusick_annulus


#: ``(c_K, c_C, c_M)`` of a Newmark step of 0.01 s (β = 1/4, γ = 1/2)
STEP_WEIGHTS = (1.0, 2.0 / 0.01 * 0.5 * 2, 1.0 / (0.25 * 0.01 ** 2))


def timeit(fun, repeat):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fun()
        best = min(best, time.perf_counter() - t0)
    return best


def cusick_shell(n_radial, n_circumferential):
    """The shell of ``cases/cusick_fabric1.toml`` (mesh and membrane options)."""
    mesh = cusick_annulus(0.30, 0.18, n_radial=n_radial, n_circumferential=n_circumferential,
                          radial_grading=4.0)
    return KirchhoffLoveShell(mesh, load_material("fabric1"), clamped=("disc",),
                              membrane_strain_degree=0, membrane_stabilization=0.05)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--radial", type=int, default=6, help="rings of the annulus (default 6)")
    p.add_argument("--circumferential", type=int, default=72,
                   help="cells around the annulus (default 72)")
    p.add_argument("--repeat", type=int, default=5, help="timing repeats, best taken (default 5)")
    args = p.parse_args(argv)

    t0 = time.perf_counter()
    shell = cusick_shell(args.radial, args.circumferential)
    t_setup = time.perf_counter() - t0
    free = shell.ndofs - len(shell.fixed_dofs)
    print(f"Cusick annulus {args.radial} x {args.circumferential}: {len(shell.edofs)} triangles, "
          f"{free} free dofs, {shell.w.shape[1]} quadrature points per triangle, "
          f"{numba.get_num_threads()} threads")
    print(f"  set-up incl. first compile or cache load : {t_setup:9.3f} s")

    rng = np.random.default_rng(0)
    u = np.zeros(shell.ndofs)
    u[2::3] = -2e-3 * rng.random(shell.basis.N)            # a rough sag
    u[shell.fixed_dofs] = 0.0
    v, a = 1e-2 * rng.standard_normal(shell.ndofs), rng.standard_normal(shell.ndofs)

    def law():
        _, kappa = shell.qp_state(u)
        shell.moments(kappa)

    J = shell.evaluate(u, v, a, 0.5, "consistent", STEP_WEIGHTS).J
    restrict = FreeRestriction(np.setdiff1d(np.arange(shell.ndofs), shell.fixed_dofs), upper=True)
    restrict(J)

    def fresh(fun):
        """``fun`` without the shell's kept law trial of an earlier call."""
        def call():
            shell._kept_point = None
            return fun()
        return call

    rows = [("kinematics + law trial", law),
            ("force only", fresh(lambda: shell.internal_forces(u, v))),
            ("force + step matrix (kernel)", fresh(lambda: shell.internal_forces(u, v, a, STEP_WEIGHTS))),
            ("evaluate (R, step matrix as CSR)",
             fresh(lambda: shell.evaluate(u, v, a, 0.5, "consistent", STEP_WEIGHTS))),
            ("force, then step matrix at that point",
             fresh(lambda: (shell.internal_forces(u, v), shell.internal_forces(u, v, a, STEP_WEIGHTS)))),
            ("restriction to the free dofs", lambda: restrict(J)),
            ("  the same gather by np.take", lambda: np.take(J.data, restrict._map))]
    for name, fun in rows:
        t = timeit(fun, args.repeat)
        print(f"  {name:40s} : {t:9.4f} s")


if __name__ == "__main__":
    main()
