"""Benchmark of the large-rotation shell: assembly speed and the cantilever case.

1. The linearised shell stiffness (membrane + bending at the flat state) assembled
   (a) with a scikit-fem ``BilinearForm`` on ``ElementVector(Argyris, 3)`` (one
   Python form call per basis pair: 63² = 3969 per element batch) and (b) with
   the shell's batched einsum/matmul assembly on a precomputed sparsity pattern
   (docs/theory.md §4).  The two must agree to 1e-10 (relative, max norm);
   the speed-up is printed.  Also the full nonlinear residual + consistent
   tangent at a deformed state.
2. The Newton linear solve on the Cusick annulus (``meshes.cusick_annulus``, Fabric 1):
   the Newmark tangent ``K + γ/(βΔt) C + M/(βΔt²)`` at a sagging state factorized by
   :class:`drape.newmark.SparseLU` (minimum degree on A + Aᵀ, no pivoting) against
   scipy's default ``spsolve`` (COLAMD, partial pivoting): time, fill, residual.
3. The default cantilever case (``cases/cantilever.toml``, full hysteretic law)
   run through the case runner: simulated seconds per wall-clock second.

Run: ``python benchmarks/bench_shell.py [--nx 16] [--ny 4] [--repeat 5] [--annulus 4x48 6x72 8x96] [--no-case]``
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from skfem import Basis, BilinearForm
from skfem.element import ElementVector

from constitutive.material import load_material
from constitutive.conventions import CURVATURE_SIGN
from drape.shell import KirchhoffLoveShell
from meshes import strip

ROOT = Path(__file__).resolve().parents[1]


def skfem_linear_stiffness(shell):
    """The shell's tangent at u = 0 as a scikit-fem BilinearForm (reference, slow)."""
    basis = Basis(shell.mesh, ElementVector(shell.element, 3), quadrature=shell.basis.quadrature)
    C = shell.C_m
    D = np.array([shell.warp_law.k1, shell.weft_law.k1, 0.5 * shell.twist])
    s = CURVATURE_SIGN

    @BilinearForm
    def k0(u, v, w):
        gu, gv = u.grad, v.grad
        eu = [gu[0][0], gu[1][1], gu[0][1] + gu[1][0]]
        ev = [gv[0][0], gv[1][1], gv[0][1] + gv[1][0]]
        hu, hv = u.hess[2], v.hess[2]
        ku = [s * hu[0][0], s * hu[1][1], 2 * s * hu[0][1]]
        kv = [s * hv[0][0], s * hv[1][1], 2 * s * hv[0][1]]
        out = 0.0
        for i in range(3):
            out = out + D[i] * ku[i] * kv[i]
            for j in range(3):
                if C[i, j] != 0.0:
                    out = out + C[i, j] * eu[j] * ev[i]
        return out

    return basis, k0


def timeit(fun, repeat):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fun()
        best = min(best, time.perf_counter() - t0)
    return best, out


def bench_assembly(nx, ny, repeat):
    mat = load_material("fabric1")
    mesh = strip(0.02, 0.025, nx, ny)
    shell = KirchhoffLoveShell(mesh, mat, load_boundary="free_end")
    ne = mesh.t.shape[1]
    print(f"mesh {nx}x{ny} strip: {ne} Argyris triangles, {shell.ndofs} dofs, "
          f"{shell.w.shape[1]} quadrature points per triangle")

    t_basis, (basis, form) = timeit(lambda: skfem_linear_stiffness(shell), 1)
    t_skfem, K_ref = timeit(lambda: form.assemble(basis), max(1, repeat // 5))
    t_fast, K_fast = timeit(shell.linear_stiffness, repeat)
    K_tan = shell.pattern.from_data(shell._internal(np.zeros(shell.ndofs), elastic_tangent=True)[1])
    diff_tan = abs(K_ref - K_tan).max() / abs(K_ref).max()
    diff = abs(K_ref - K_fast).max() / abs(K_ref).max()
    print(f"  linearised stiffness, skfem BilinearForm : {t_skfem:9.4f} s "
          f"(vector basis build {t_basis:.2f} s, not counted)")
    print(f"  linearised stiffness, batched einsum     : {t_fast:9.4f} s")
    print(f"  max |K_skfem - K_fast| / max |K|         : {diff:.2e}  "
          f"({'OK' if diff <= 1e-10 else 'MISMATCH'}, tolerance 1e-10)")
    print(f"  speed-up                                 : {t_skfem / t_fast:9.1f} x")
    print(f"  (nonlinear tangent at u = 0 vs skfem     : {diff_tan:.2e})")

    rng = np.random.default_rng(0)
    u = 1e-3 * rng.standard_normal(shell.ndofs)
    u[shell.fixed_dofs] = 0.0
    z = np.zeros_like(u)
    t_res, _ = timeit(lambda: shell.residual(u, z, z, 0.1), repeat)
    print(f"  full nonlinear residual + K, C, M        : {t_res:9.4f} s "
          f"({1e6 * t_res / ne:.0f} µs per triangle)")
    return dict(speedup=t_skfem / t_fast, rel_diff=diff, t_skfem=t_skfem, t_fast=t_fast,
                t_residual=t_res)


def bench_linear_solve(sizes, repeat):
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from drape.newmark import SparseLU
    from meshes import cusick_annulus

    mat = load_material("fabric1")
    dt, beta, gamma = 0.01, 0.3025, 0.6          # HHT alpha = -0.1, as in cases/cusick_*.toml
    out = {}
    for size in sizes:
        nr, nc = (int(v) for v in size.split("x"))
        shell = KirchhoffLoveShell(cusick_annulus(n_radial=nr, n_circumferential=nc), mat,
                                   clamped=("disc",))
        u = np.zeros(shell.ndofs)
        u[2::3] = -2e-3 * np.random.default_rng(0).random(shell.basis.N)   # a rough sag
        u[shell.fixed_dofs] = 0.0
        _, K, C, M = shell.residual(u, 0 * u, 0 * u, 0.0)
        free = np.setdiff1d(np.arange(shell.ndofs), shell.fixed_dofs)
        J = (K + gamma / (beta * dt) * C + M / (beta * dt**2)).tocsr()[free][:, free].tocsc()
        b = np.random.default_rng(1).standard_normal(free.size)
        t_ref, x_ref = timeit(lambda: spla.spsolve(J, b), repeat)
        t_new, lu = timeit(lambda: SparseLU(J), repeat)
        x = lu.solve(b)
        res = lambda y: np.linalg.norm(J @ y - b) / np.linalg.norm(b)  # noqa: E731
        fill_ref = spla.splu(J).L.nnz + spla.splu(J).U.nnz
        fill_new = lu._lu.L.nnz + lu._lu.U.nnz
        print(f"annulus {size}: {free.size} free dofs, nnz {J.nnz}")
        print(f"  spsolve (COLAMD, pivoting)   : {t_ref:8.3f} s  fill {fill_ref:>10d}  residual {res(x_ref):.1e}")
        print(f"  SparseLU (MMD A+Aᵀ, symmetric): {t_new:8.3f} s  fill {fill_new:>10d}  residual {res(x):.1e}"
              f"  (symmetric mode: {lu.symmetric_mode})")
        print(f"  speed-up {t_ref / t_new:.1f} x, fill ratio {fill_ref / fill_new:.1f}")
        out[size] = dict(t_spsolve=t_ref, t_sparse_lu=t_new, fill_ratio=fill_ref / fill_new)
    return out


def bench_case(case):
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "drape.run", str(case), "--out", out, "--quiet"],
                              cwd=ROOT, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            print(proc.stdout, proc.stderr)
            raise SystemExit(f"case run failed with exit code {proc.returncode}")
        summary = json.loads((Path(out) / "summary.json").read_text())
    t_sim = summary["t_final"]
    print(f"case {case.name}: {summary['status']} ({summary['reason']}), {summary['steps']} steps")
    print(f"  simulated {t_sim:.3f} s in {wall:.1f} s wall (incl. start-up and output) "
          f"-> {t_sim / wall:.3f} simulated s per wall s (aim >= 0.05)")
    ana = summary.get("analysis", {})
    for key in ("chord_angle_deg", "tip_angle_deg", "tip_drop_m", "bending_length_m",
                "flexural_rigidity_Nm", "G_over_B_kes"):
        if key in ana:
            print(f"  {key:22s} {ana[key]:.4g}")
    return dict(sim_per_wall=t_sim / wall, wall=wall, t_sim=t_sim)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--nx", type=int, default=16, help="cells along the strip (default 16)")
    p.add_argument("--ny", type=int, default=4, help="cells across the strip (default 4)")
    p.add_argument("--repeat", type=int, default=5, help="timing repeats, best taken (default 5)")
    p.add_argument("--case", type=Path, default=ROOT / "cases" / "cantilever.toml",
                   help="case file for the simulated-time rate (default cases/cantilever.toml)")
    p.add_argument("--annulus", nargs="*", default=["4x48", "6x72", "8x96"], metavar="NRxNC",
                   help="Cusick annuli for the linear-solve comparison (default 4x48 6x72 8x96)")
    p.add_argument("--no-case", action="store_true", help="skip the case run")
    args = p.parse_args(argv)
    bench_assembly(args.nx, args.ny, args.repeat)
    bench_linear_solve(args.annulus, args.repeat)
    if not args.no_case:
        bench_case(args.case)


if __name__ == "__main__":
    main()
