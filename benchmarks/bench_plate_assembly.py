"""Benchmark: assembly of residual + consistent tangent of the Kirchhoff plate (drape/models/plate.py).

For Morley and Argyris on three square meshes, times ``KirchhoffPlate.residual``
(cubic + friction law at every quadrature point, element contractions, one
``bincount`` scatter into a fixed CSR pattern) and prints the cost per element
and elements per second; the cost per element should stay flat (linear scaling).

Usage::

    python benchmarks/bench_plate_assembly.py [--sizes 16 32 64] [--repeat 5] [--solve] [--newmark 32]
"""
from __future__ import annotations

import argparse
import time
from types import SimpleNamespace

import numpy as np
import skfem

from constitutive.friction import FrictionParams
from constitutive.law import BendingLaw
from drape.models.plate import KirchhoffPlate


def build(n: int, element: str) -> KirchhoffPlate:
    mesh = skfem.MeshTri.init_tensor(np.linspace(0, 0.3, n + 1), np.linspace(0, 0.3, n + 1))
    mesh = mesh.with_boundaries({"left": lambda x: np.isclose(x[0], 0.0)})
    law = BendingLaw(k1=2e-5, k3=1e-9, friction=FrictionParams(f1=3e-3, f2=1.5e-3, eps_f=30.0, eta=0.4))
    mat = SimpleNamespace(areal_mass=0.2, warp=law, weft=law, twist_rigidity=2e-5)
    return KirchhoffPlate(mesh, mat, element=element, supports={"left": "clamped"})


def time_residual(plate: KirchhoffPlate, repeat: int) -> float:
    rng = np.random.default_rng(0)
    u = 1e-3 * rng.standard_normal(plate.ndofs)
    z = np.zeros(plate.ndofs)
    plate.residual(u, z, z, 0.0)  # warm-up
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        plate.residual(u, z, z, 0.0)
        best = min(best, time.perf_counter() - t0)
    return best


def time_solve(plate: KirchhoffPlate) -> float:
    """One SuperLU solve of the effective Newmark tangent on the free dofs (for comparison)."""
    import scipy.sparse.linalg as spla

    free = np.setdiff1d(np.arange(plate.ndofs), plate.fixed_dofs)
    J = (plate.K0 + plate.M / (0.25 * 1e-3**2))[free][:, free].tocsc()
    t0 = time.perf_counter()
    spla.spsolve(J, np.ones(free.size))
    return time.perf_counter() - t0


def time_newmark(n: int, element: str, steps: int = 20, dt: float = 2e-3) -> None:
    """Wall time per Newmark step (fabric1, gravity) with each direct solver back end,
    symmetric (upper triangle) and general."""
    from constitutive.material import load_material
    from drape.solvers.linear import DirectSolver, pardiso_available
    from drape.solvers.time_stepping import integrate

    mat = load_material("fabric1")
    mesh = skfem.MeshTri.init_tensor(np.linspace(0, 0.1, n + 1), np.linspace(0, 0.1, n + 1))
    mesh = mesh.with_boundaries({"left": lambda x: np.isclose(x[0], 0.0)})
    backends = ["superlu"] + (["pardiso"] if pardiso_available() else [])
    for backend in backends:
        for symmetric in (True, False):
            solver = DirectSolver(symmetric=symmetric, backend=backend)
            plate = KirchhoffPlate(mesh, mat, element=element, supports={"left": "clamped"}, rayleigh=(5.0, 0.0))
            its = []
            t0 = time.perf_counter()
            integrate(plate, steps * dt, dt, linear_solver=solver, on_step=lambda s, i: its.append(i.iterations))
            wall = (time.perf_counter() - t0) / steps
            label = f"{backend}{' sym' if symmetric else ''}"
            print(f"newmark {element:8s} {mesh.t.shape[1]:6d} elem {plate.ndofs:6d} dofs {label:12s}: "
                  f"{wall:7.3f} s/step, {np.mean(its):.1f} Newton it/step, "
                  f"{solver.factorizations} factorizations, {dt / wall:6.3f}x real time at dt = {dt:g} s",
                  flush=True)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes", type=int, nargs=3, default=[16, 32, 64],
                        help="elements per side of the square meshes (2 n² triangles)")
    parser.add_argument("--repeat", type=int, default=5, help="timed repetitions (best is reported)")
    parser.add_argument("--elements", nargs="+", default=["morley", "argyris"], choices=["morley", "argyris"])
    parser.add_argument("--newmark", type=int, metavar="N", default=0,
                        help="also time Newmark steps on an N×N mesh with each direct solver")
    parser.add_argument("--solve", action="store_true",
                        help="also time one direct (SuperLU) solve of the Newmark tangent, for comparison")
    args = parser.parse_args(argv)
    print(f"{'element':8s} {'n_elem':>7s} {'n_dofs':>7s} {'n_qp':>4s} {'setup s':>8s} "
          f"{'assembly s':>10s} {'us/elem':>8s} {'elem/s':>10s}" + (f" {'solve s':>8s}" if args.solve else ""))
    for element in args.elements:
        for n in args.sizes:
            t0 = time.perf_counter()
            plate = build(n, element)
            setup = time.perf_counter() - t0
            t = time_residual(plate, args.repeat)
            ne = plate.mesh.t.shape[1]
            line = (f"{element:8s} {ne:7d} {plate.ndofs:7d} {plate._dx.shape[1]:4d} {setup:8.2f} "
                    f"{t:10.4f} {1e6 * t / ne:8.1f} {ne / t:10.0f}")
            if args.solve:
                line += f" {time_solve(plate):8.3f}"
            print(line, flush=True)
    if args.newmark:
        for element in args.elements:
            time_newmark(args.newmark, element)


if __name__ == "__main__":
    main()
