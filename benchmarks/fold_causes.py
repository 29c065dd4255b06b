"""Why stiffer fabrics hang in four square folds: each candidate cause, one at a time.

Fabrics known by their KES values only (``cases/cusick_kes.toml``, 30 cm on 18 cm), warp and
weft equal, 2HB/B = 0.5 cm⁻¹, W = 15 mg/cm², at three bending rigidities of the stiff end
of apparel fabrics (``--fabrics``, B in gf·cm²/cm). Every candidate changes one thing from
the per-direction friction law (the former default), except ``tensor`` (the friction on
the curvature tensor, now the default) and the ``tensor+`` rows, which combine it with
another candidate:

``per_direction``   each yarn's friction on its own curvature, twist frictionless
``tensor``          one frame-invariant friction law on the curvature tensor
``friction_off``    the calibrated elastic part alone
``shear_G``         membrane shear G = 1.8 gf/(cm·deg) (G12 ≈ 101 N/m, near an isotropic
                    membrane's E/2) instead of the soft default 50 N/m
``twist_low``       twist rigidity D_t = B/2 through a bias-direction B (B_bias = 0.75 B)
                    instead of the default √(B_warp B_weft) = B
``spectrum_short``  imperfection modes 5–12 only (default 2–12)
``amplitude_x4``    imperfection amplitude 0.08 of the weight (default 0.02)
``mesh_90``         90 elements round the annulus instead of 72 (another alignment of the
                    mesh's radial lines against the yarns)
``ramp_0.5s``       the specimen let down in 0.5 s instead of 2 s
``settle_1e-4``     settled at an out-of-balance of 1e-4 of the weight instead of 1e-3
``tensor+rigidity`` the rigidity varying over the specimen, cv 0.15 over 3 cm (a seeded
                    log-normal field, ``[model.rigidity_variation]``; the lowered case's)

``--case cases/cusick_lowered.toml`` runs the rows on the specimen let down on the support,
which carries the rigidity field already (``--only tensor`` there is the shipped set-up).

Usage::

    python benchmarks/fold_causes.py --out out/fold_causes            # 3 fabrics × 12 rows
    python benchmarks/fold_causes.py --out out/fold_causes --only per_direction tensor --seeds 3

Writes the sweep (``results.csv``, one run folder per row) and ``fold_causes.md``, the table
of DC and node count per candidate and fabric.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from drape.batch.ensemble import ensemble_stats  # noqa: E402
from drape.batch.matched_dc import fabric_keys  # noqa: E402
from drape.batch.rows import SweepRow, read_results
from drape.batch.sweep import run_sweep  # noqa: E402

PER_DIRECTION = ["model.bending_friction=per_direction"]

#: candidate -> overrides; a callable takes B (gf·cm²/cm) for values that scale with it.
CANDIDATES = {
    "per_direction": PER_DIRECTION,
    "tensor": [],
    "friction_off": ["material.friction=false"],
    "shear_G": PER_DIRECTION + ["material.kes.G=1.8"],
    "twist_low": lambda B: PER_DIRECTION + [f"material.kes.B_bias={0.75 * B:.6g}"],
    "spectrum_short": PER_DIRECTION + ["load.perturbation.k_min=5"],
    "amplitude_x4": PER_DIRECTION + ["load.perturbation.amplitude=0.08"],
    "mesh_90": PER_DIRECTION + ["mesh.n_circumferential=90"],
    "ramp_0.5s": PER_DIRECTION + ["load.gravity.ramp_time=0.5"],
    "settle_1e-4": PER_DIRECTION + ["stop.out_of_balance=1e-4"],
    "tensor+shear_G": ["material.kes.G=1.8"],
    "tensor+mesh_90": ["mesh.n_circumferential=90"],
    "tensor+rigidity": ["model.rigidity_variation.cv=0.15", "model.rigidity_variation.correlation_length=3cm"],
}


def _keys(overrides: list[str]) -> dict:
    return dict(o.split("=", 1) for o in overrides)


def study_rows(fabrics, candidates, seeds: int) -> list[SweepRow]:
    """One sweep row per (candidate, fabric, seed)."""
    rows = []
    for name in candidates:
        for B in fabrics:
            spec = CANDIDATES[name]
            keys = fabric_keys(B) + (spec(B) if callable(spec) else list(spec))
            group = f"{name}_B{B:g}"
            for seed in range(seeds):
                row_keys = _keys(keys + [f"load.perturbation.seed={seed}"])
                rows.append(SweepRow(f"{group}_s{seed}", row_keys, group=group))
    return rows


def table(records: list[dict], fabrics, candidates) -> str:
    """Markdown: DC % and node count (per seed) per candidate (rows) and fabric (columns)."""
    groups = {}
    for rec in records:
        groups.setdefault(rec["name"].rsplit("_s", 1)[0], []).append(rec)
    head = "| candidate | " + " | ".join(f"B = {B:g}" for B in fabrics) + " |"
    lines = [head, "|---" * (len(fabrics) + 1) + "|"]
    for name in candidates:
        cells = []
        for B in fabrics:
            recs = sorted(groups.get(f"{name}_B{B:g}", []), key=lambda r: r["name"])
            ok = [r for r in recs if r.get("status") in ("settled", "completed")]
            if not ok:
                cells.append("–")
                continue
            stats = ensemble_stats(ok)
            nodes = ", ".join(str(r["nodes"]) for r in ok)
            cells.append(f"{stats['DC_percent']['mean']:.1f} % / {nodes}")
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default="out/fold_causes", help="sweep folder")
    p.add_argument("--fabrics", default="0.08,0.16,0.32", help="B values, gf·cm²/cm")
    p.add_argument("--only", nargs="+", choices=list(CANDIDATES), default=list(CANDIDATES))
    p.add_argument("--seeds", type=int, default=1, help="perturbation seeds 0..N-1 per row")
    p.add_argument("--case", default=str(ROOT / "cases" / "cusick_kes.toml"))
    p.add_argument("--workers", type=int, default=None)
    p.add_argument("--resume", action="store_true")
    args = p.parse_args(argv)
    fabrics = [float(b) for b in args.fabrics.split(",")]
    rows = study_rows(fabrics, args.only, args.seeds)
    run_sweep(args.case, rows, args.out, workers=args.workers, resume=args.resume)
    records = read_results(Path(args.out) / "results.csv")
    text = table(records, fabrics, args.only)
    (Path(args.out) / "fold_causes.md").write_text(text + "\n")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
