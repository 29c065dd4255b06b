"""Fold number of the Cusick drape against the fold-number law of Cerda, Mahadevan & Pasini.

A circular sheet of radius R on a disc of radius R_D hangs over the overhang L = R − R_D. Its
folds are wrinkles of the hanging skirt, whose weight stands for an elastic foundation of
stiffness K ∼ ρ_A g / L, so their wavelength is λ ∼ (B/K)^{1/4} = (ℓ_g³ L)^{1/4} with the
elastogravity length ℓ_g = (B/(ρ_A g))^{1/3}, which is Peirce's bending length c = (B/W)^{1/3};
the number of folds round the disc is

    n = 2π R_D / λ ∼ 2π R_D / (ℓ_g³ (R − R_D))^{1/4},

and, for an overhang long against the disc (R ∼ L ≫ R_D), n ∼ (R/ℓ_g)^{3/4} (E. Cerda,
L. Mahadevan & J. M. Pasini, *The elements of draping*, PNAS 101(7):1806–1810, 2004;
docs/theory.md §6). The law holds for a skirt that hangs, L ≫ ℓ_g; the table gives L/ℓ_g
beside each point.

The paper states the law as a scaling (∼), without a numerical prefactor. The study
therefore fits one, C in n = C · 2π R_D / (ℓ_g³ L)^{1/4}, on half the grid of B (the
even-indexed points, in increasing B) and checks the law on the other half (the odd-indexed
points): :func:`compare`. What is tested is the law's dependence on c, not its magnitude.

The runs are those of :mod:`drape.batch.matched_dc` at a given B (warp = weft, 2HB = 0.5 B,
:func:`drape.batch.matched_dc.fabric_keys`), one per perturbation seed
(:func:`fold_law_rows`), through :func:`drape.batch.sweep.run_sweep`.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from drape.batch.matched_dc import GOOD, fabric_keys, sweep, write_rows
from drape.batch.rows import SweepRow, read_results
from drape.case import load_case

__all__ = ["bending_length_cm", "cerda_folds", "case_radii", "fold_law_rows", "fit_prefactor",
           "compare", "agreement", "markdown", "fold_figure", "write_plot", "write_table", "study"]

B_KEY = "material.kes.B_warp"
WEIGHT_KEY = "material.kes.weight"
SEED_KEY = "load.perturbation.seed"


def bending_length_cm(B: float, weight: float) -> float:
    """Peirce's bending length c = (B/W)^{1/3} in cm, the elastogravity length ℓ_g.

    Parameters
    ----------
    B : float
        Bending rigidity, gf·cm²/cm (KES-FB's B).
    weight : float
        Weight per area W, mg/cm² (KES-F's W); 1 mg/cm² is 10⁻³ gf/cm².

    >>> round(bending_length_cm(0.015, 15.0), 6)
    1.0
    """
    return (B / (1e-3 * weight)) ** (1.0 / 3.0)


def cerda_folds(c, disc_radius: float, specimen_radius: float, prefactor: float = 1.0):
    """Number of folds of a sheet draped over a disc, by the law of Cerda, Mahadevan & Pasini.

    n = C · 2π R_D / (ℓ_g³ (R − R_D))^{1/4}: the folds are the hanging skirt's wrinkles of
    wavelength λ = (ℓ_g³ L)^{1/4} (E. Cerda, L. Mahadevan & J. M. Pasini, *The elements of
    draping*, PNAS 101(7):1806–1810, 2004), counted round the disc's edge.

    Parameters
    ----------
    c : float or array_like
        The elastogravity length ℓ_g = (B/(ρ_A g))^{1/3}, i.e. Peirce's bending length
        (:func:`bending_length_cm`), in the radii's unit.
    disc_radius : float
        R_D, the supporting disc's radius.
    specimen_radius : float
        R, the specimen's radius (R > R_D).
    prefactor : float
        C. The paper states the law as a scaling (∼), without a numerical prefactor; C = 1 is
        n = 2π R_D/λ with λ = (ℓ_g³ L)^{1/4} taken literally. The study fits C
        (:func:`fit_prefactor`).

    Returns
    -------
    float or ndarray
        The law's fold number (not rounded), falling as c^{-3/4}.

    Raises
    ------
    ValueError
        If the specimen is not larger than the disc.

    Notes
    -----
    The law is that of a skirt that hangs: overhang L = R − R_D long against ℓ_g. For an
    overhang long against the disc too (R ∼ L ≫ R_D) the paper's form is n ∼ (R/ℓ_g)^{3/4}.

    >>> round(cerda_folds(1.0, 9.0, 15.0), 4)        # 2π·9 / 6^{1/4}
    36.1314
    >>> round(cerda_folds(2.0, 9.0, 15.0) / cerda_folds(1.0, 9.0, 15.0), 4)   # 2^{-3/4}
    0.5946
    """
    overhang = specimen_radius - disc_radius
    if overhang <= 0:
        raise ValueError(f"specimen radius {specimen_radius} must exceed the disc radius {disc_radius}")
    c = np.asarray(c, dtype=float)
    n = prefactor * 2.0 * math.pi * disc_radius / (c ** 3 * overhang) ** 0.25
    return float(n) if n.ndim == 0 else n


def case_radii(case, overrides=()) -> tuple[float, float]:
    """(R_D, R) of a Cusick case in cm: half its mesh's disc and specimen diameters.

    Raises
    ------
    ValueError
        If the case is not a Cusick drape.
    """
    spec = load_case(case, list(overrides)).mesh
    if getattr(spec, "kind", None) != "cusick":
        raise ValueError(f"{case}: not a Cusick case (mesh kind {getattr(spec, 'kind', None)!r})")
    return 50.0 * spec.disc_diameter, 50.0 * spec.specimen_diameter


def fold_law_rows(case, B_values, weight: float = 15.0, seeds: int = 1) -> list[SweepRow]:
    """The sweep rows of the study: each B under the perturbation seeds 0 … seeds−1.

    Parameters
    ----------
    case : str or Path
        The Cusick case the rows are run on (checked to be one: :func:`case_radii`).
    B_values : iterable of float
        Bending rigidities, gf·cm²/cm (warp = weft).
    weight : float
        W, mg/cm².
    seeds : int
        Perturbation seeds per B.

    Returns
    -------
    list of SweepRow
        Named ``B<B>_s<seed>``; the keys of :func:`drape.batch.matched_dc.fabric_keys`
        (``material.kes.B_warp``, ``B_weft``, ``HB2_warp``, ``HB2_weft`` = 0.5 B,
        ``material.kes.weight``) and ``load.perturbation.seed``, as the matched runs of
        :mod:`drape.batch.matched_dc` at that B.
    """
    case_radii(case)
    if seeds < 1:
        raise ValueError(f"seeds = {seeds}: at least one")
    rows = []
    for B in B_values:
        keys = fabric_keys(float(B), weight=weight)
        for seed in range(seeds):
            items = keys + [f"{SEED_KEY}={seed}"]
            rows.append(SweepRow(f"B{float(B):.5g}_s{seed}", dict(o.split("=", 1) for o in items)))
    return rows


def _finished(results) -> list[dict]:
    """The records that settled or completed and counted nodes."""
    return [r for r in results if r.get("status") in GOOD and str(r.get("nodes") or "").strip()]


def fit_prefactor(c, nodes, disc_radius: float, specimen_radius: float) -> float:
    """C of :func:`cerda_folds` fitted to (c, node count) points: the geometric mean of
    nodes / n(C = 1), i.e. least squares in log n.

    >>> n1 = cerda_folds(1.5, 9.0, 15.0)
    >>> round(fit_prefactor([1.5, 1.5], [0.5 * n1, 0.5 * n1], 9.0, 15.0), 6)
    0.5
    """
    c, nodes = np.asarray(c, dtype=float), np.asarray(nodes, dtype=float)
    keep = nodes > 0
    if not keep.any():
        raise ValueError("no node counts to fit the prefactor to")
    ratio = nodes[keep] / cerda_folds(c[keep], disc_radius, specimen_radius)
    return float(np.exp(np.mean(np.log(ratio))))


def compare(results, disc_radius: float = 9.0, specimen_radius: float = 15.0) -> list[dict]:
    """The sweep's finished records against the law, one row per B.

    Parameters
    ----------
    results : list of dict
        Records of ``results.csv`` (:func:`drape.batch.rows.read_results`; values as text)
        with ``material.kes.B_warp``, ``material.kes.weight``, ``load.perturbation.seed``,
        ``status``, ``DC_percent`` and ``nodes``. Runs that did not settle or complete are
        left out.
    disc_radius, specimen_radius : float
        R_D and R, cm (:func:`case_radii`).

    Returns
    -------
    list of dict
        In increasing B: ``B`` (gf·cm²/cm), ``weight``, ``c_cm``, ``overhang_over_c``
        (L/ℓ_g), ``seeds``, ``DC`` and ``nodes`` (per seed, as text), ``nodes_mean``,
        ``half`` (``fit``: even-indexed B, on which the prefactor is fitted; ``check``: the
        others), ``prefactor``, ``n_law`` and ``difference`` (mean nodes − n_law).
    """
    by_B: dict[float, list[dict]] = {}
    for r in _finished(results):
        by_B.setdefault(float(r[B_KEY]), []).append(r)
    if not by_B:
        return []
    table = []
    for i, B in enumerate(sorted(by_B)):
        recs = sorted(by_B[B], key=lambda r: int(float(r.get(SEED_KEY) or 0)))
        weight = float(recs[0][WEIGHT_KEY])
        c = bending_length_cm(B, weight)
        nodes = [int(float(r["nodes"])) for r in recs]
        table.append({"B": B, "weight": weight, "c_cm": round(c, 4),
                      "overhang_over_c": round((specimen_radius - disc_radius) / c, 3),
                      "seeds": " ".join(str(int(float(r.get(SEED_KEY) or 0))) for r in recs),
                      "DC": " ".join(f"{float(r['DC_percent']):.1f}" for r in recs),
                      "nodes": " ".join(map(str, nodes)), "nodes_mean": float(np.mean(nodes)),
                      "half": "fit" if i % 2 == 0 else "check", "_c": c, "_nodes": nodes})
    fit = [r for r in table if r["half"] == "fit"]
    C = fit_prefactor([r["_c"] for r in fit for _ in r["_nodes"]],
                      [n for r in fit for n in r["_nodes"]], disc_radius, specimen_radius)
    for r in table:
        n = cerda_folds(r.pop("_c"), disc_radius, specimen_radius, C)
        r.pop("_nodes")
        r.update(prefactor=round(C, 4), n_law=round(n, 2), difference=round(r["nodes_mean"] - n, 2))
    return table


def agreement(table: list[dict]) -> dict:
    """Per half (``fit``, ``check``): the number of B and the RMS and largest |difference|
    between mean simulated nodes and the law."""
    out = {}
    for half in ("fit", "check"):
        d = np.array([r["difference"] for r in table if r["half"] == half], dtype=float)
        out[half] = {"points": int(d.size),
                     "rms": round(float(np.sqrt(np.mean(d ** 2))), 2) if d.size else None,
                     "max_abs": round(float(np.max(np.abs(d))), 2) if d.size else None}
    return out


def markdown(table: list[dict]) -> str:
    """The comparison as a markdown table and a line per half (:func:`agreement`)."""
    lines = ["| B (gf·cm²/cm) | c (cm) | L/c | half | DC % per seed | nodes per seed | law n | "
             "nodes − law |", "|---|---|---|---|---|---|---|---|"]
    for r in table:
        lines.append(f"| {r['B']:.4g} | {r['c_cm']:.3f} | {r['overhang_over_c']:.2f} | {r['half']} | "
                     f"{r['DC']} | {r['nodes']} | {r['n_law']:.2f} | {r['difference']:+.2f} |")
    if table:
        lines.append("")
        lines.append(f"Prefactor C = {table[0]['prefactor']:.4g}, fitted on the even-indexed B "
                     "(half `fit`) and checked on the others (half `check`).")
        for half, a in agreement(table).items():
            if a["points"]:
                lines.append(f"- {half}: {a['points']} B, RMS difference {a['rms']:.2f} nodes, "
                             f"largest {a['max_abs']:.2f}")
    return "\n".join(lines)


def fold_figure(table: list[dict], disc_radius: float = 9.0, specimen_radius: float = 15.0):
    """Nodes against c: every seed's count (fit and check halves apart) and the law's curve.

    Returns a matplotlib ``Figure`` (not attached to pyplot).
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7, 4.5))
    ax = fig.add_subplot()
    for half, style in (("fit", ("o", "C0")), ("check", ("s", "C1"))):
        pts = [(r["c_cm"], int(n)) for r in table if r["half"] == half for n in r["nodes"].split()]
        if pts:
            x, y = zip(*pts)
            ax.plot(x, y, style[0], color=style[1], ms=6, ls="none",
                    label=f"simulated ({half} half)")
    if table:
        c = np.array([r["c_cm"] for r in table])
        grid = np.geomspace(c.min() / 1.1, c.max() * 1.1, 200)
        ax.plot(grid, cerda_folds(grid, disc_radius, specimen_radius, table[0]["prefactor"]), "k-",
                label=f"Cerda et al. 2004, C = {table[0]['prefactor']:.3g}")
        ax.set_xscale("log")
    ax.set_xlabel("bending length c = (B/W)$^{1/3}$ (cm)")
    ax.set_ylabel("nodes")
    ax.set_title(f"Fold number against bending length ({2 * specimen_radius:g} cm on "
                 f"{2 * disc_radius:g} cm)")
    ax.legend(loc="upper right")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def write_plot(table: list[dict], path, disc_radius: float = 9.0, specimen_radius: float = 15.0) -> Path:
    """Write :func:`fold_figure` as a PNG to ``path``; return the path."""
    path = Path(path)
    fold_figure(table, disc_radius, specimen_radius).savefig(path, dpi=120)
    return path


def write_table(table: list[dict], out, disc_radius: float = 9.0, specimen_radius: float = 15.0) -> str:
    """Write ``fold_law.csv``, ``fold_law.md`` and ``fold_law.png`` to ``out``; return the
    markdown."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    if not table:
        raise ValueError("no finished runs to compare with the law")
    text = markdown(table)
    write_rows(table, text, out, "fold_law")
    write_plot(table, out / "fold_law.png", disc_radius, specimen_radius)
    return text


def study(case, B_values, weight: float, seeds: int, out, workers=None, overrides=()) -> str | None:
    """Run the study: the rows of ``B_values`` through the sweep into ``out/runs`` (continued
    where it exists), compared with the law and written to ``out`` (:func:`write_table`).

    Returns the markdown table, or None when no run finished.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    disc_radius, specimen_radius = case_radii(case, overrides)
    rows = fold_law_rows(case, sorted(set(B_values)), weight, seeds)
    sweep(case, rows, out / "runs", workers, list(overrides))
    table = compare(read_results(out / "runs" / "results.csv"), disc_radius, specimen_radius)
    return write_table(table, out, disc_radius, specimen_radius) if table else None
