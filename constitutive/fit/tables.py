"""The fit's printed tables: one result's parameters, and every thesis cell fitted and compared
with the thesis (``python -m constitutive.fit``, ``--all-thesis``).
"""
from __future__ import annotations

import multiprocessing as mp
import time
from pathlib import Path

from tqdm import tqdm

from constitutive.datasets import DATASET_NAMES, load_dataset
from constitutive.fit.global_fit import fit
from constitutive.fit.plots import plot_fit
from constitutive.fit.residual import evaluate
from constitutive.fit.variants import (
    DEFAULT_ACCEL_TIME,
    DERIVED_UNITS,
    PARAM_UNITS,
    THESIS_RESIDUALS,
    THESIS_VARIANTS,
    VARIANTS,
    thesis_law,
    to_kes,
)

__all__ = ["format_result", "accel_sweep_lines", "all_thesis", "format_all"]


def format_result(r):
    """Human-readable parameter table of a :class:`FitResult` (KES units)."""
    p, der, kv = to_kes(r.params()), r.derived(), r.kes_values()
    lines = [f"dataset {r.dataset}   variant {r.variant} ({VARIANTS[r.variant].label})   "
             f"T = {r.accel_time:g} s   samples {r.loop.kappa.size} (1 ms)",
             f"residual 4.17 = {r.residual:.4e} (gf·cm/cm)²", "",
             f"{'parameter':<10}{'value':>14}  unit", "-" * 36]
    for k, v in p.items():
        lines.append(f"{k:<10}{'—' if v is None else f'{v:14.4e}':>14}  {PARAM_UNITS[k][0]}")
    lines.append("-" * 36)
    for k, v in der.items():
        vv = None if v is None else v / DERIVED_UNITS[k][1]
        lines.append(f"{k:<10}{'—' if vv is None else f'{vv:14.4e}':>14}  {DERIVED_UNITS[k][0]}")
    lines.append("-" * 36)
    lines.append(f"{'B':<10}{kv['model'][0]:14.4e}  gf·cm²/cm   (data {kv['data'][0]:.4e})")
    lines.append(f"{'2HB':<10}{kv['model'][1]:14.4e}  gf·cm/cm    (data {kv['data'][1]:.4e})")
    return "\n".join(lines)


def _fit_cell(args):
    """One cell of :func:`all_thesis` (a pool's task): its residual and CPU seconds."""
    name, variant, accel_time, plot_dir = args
    c0 = time.process_time()
    r = fit(name, variant, accel_time)
    cpu = time.process_time() - c0
    if plot_dir is not None:
        Path(plot_dir).mkdir(parents=True, exist_ok=True)
        plot_fit(r, Path(plot_dir) / f"{name}_{variant}.png")
    return name, variant, r.residual, cpu


def all_thesis(accel_time=DEFAULT_ACCEL_TIME, workers=2, variants=THESIS_VARIANTS, progress=True,
               plot_dir=None):
    """Fit every (dataset × variant) cell.

    Returns
    -------
    fitted : dict
        {(dataset, variant): residual 4.17}
    own : dict
        {dataset: residual of the thesis's own full-model parameters, same harness}
    cpu : dict
        {(dataset, variant): CPU seconds of the fit}
    """
    cells = [(n, v, accel_time, plot_dir) for n in DATASET_NAMES for v in variants]
    fitted, times = {}, {}
    if workers > 1:
        with mp.get_context("fork").Pool(workers) as pool:
            it = pool.imap_unordered(_fit_cell, cells)
            for n, v, res, dt in tqdm(it, total=len(cells), disable=not progress, desc="fits"):
                fitted[n, v], times[n, v] = res, dt
    else:
        for c in tqdm(cells, disable=not progress, desc="fits"):
            n, v, res, dt = _fit_cell(c)
            fitted[n, v], times[n, v] = res, dt
    own = {n: evaluate(thesis_law(n), load_dataset(n).sample(accel_time)) for n in DATASET_NAMES}
    return fitted, own, times


def format_all(fitted, own, variants=THESIS_VARIANTS):
    """The table of :func:`all_thesis`: the fitted residual of each cell beside the thesis's
    parameters run through this harness ("thesis own") and the thesis's printed value."""
    head = f"{'dataset':<14}{'variant':<13}{'fitted R':>11}{'thesis own':>12}{'thesis tbl':>12}"
    lines = [head, "-" * len(head)]
    for n in DATASET_NAMES:
        for v in variants:
            o = f"{own[n]:12.4e}" if v == "full" else " " * 12
            t = THESIS_RESIDUALS[n].get(v)
            t = f"{t:12.4e}" if t is not None else " " * 12
            lines.append(f"{n:<14}{v:<13}{fitted[n, v]:11.4e}{o}{t}")
    return "\n".join(lines)


def accel_sweep_lines(curves, variant: str, times, fit_mass: bool = False):
    """The lines of the fit of ``curves`` refitted at each acceleration time of ``times`` (a
    header, then one per time as its fit ends): its residual 4.17 and, for a thesis dataset,
    that of the thesis's own parameters."""
    yield f"{'T [s]':>8}{'fitted R':>12}{'thesis own':>12}"
    for T in times:
        r = fit(curves, variant, T, fit_mass=fit_mass)
        own = (f"{evaluate(thesis_law(curves.name), curves.sample(T)):12.4e}"
               if curves.name in THESIS_RESIDUALS else "")
        yield f"{T:8.3f}{r.residual:12.4e}{own}"
