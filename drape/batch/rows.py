"""The rows of a sweep and its results table: a run table or a grid in, ``results.csv`` out.

A row is a name, its case-key overrides, its ``measured.*`` values and its group (a seed
ensemble's rows share one). A leaf of :mod:`drape.batch`: the sweep, the ensembles, the
studies and the report all read rows and results through it.
"""
from __future__ import annotations

import csv
import itertools
import re
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ['RESULT_COLUMNS', 'MEASURED', 'SweepError', 'SweepRow', 'read_table', 'grid_rows', 'read_results']



#: Output columns of results.csv after the input columns.
RESULT_COLUMNS = ("status", "reason", "DC_percent", "nodes", "settling_time_s", "t_final_s",
                  "steps", "wall_time_s", "bending_length_m", "B_warp_Nm", "B_weft_Nm",
                  "weight_N_per_m2", "run_dir", "pvd", "worker")



MEASURED = "measured."
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")


class SweepError(ValueError):
    """A run table, grid or sweep folder breaks a rule (the message names it)."""


@dataclass(frozen=True)
class SweepRow:
    """One run of a sweep: its name, its case overrides and the measured values beside it."""

    name: str
    keys: dict = field(default_factory=dict)       # dotted case key -> value text
    measured: dict = field(default_factory=dict)   # "measured.<quantity>" -> value text
    group: str = ""                                # the seed ensemble it belongs to

    def overrides(self) -> list[str]:
        """The row as ``--set`` items."""
        return [f"{k}={v}" for k, v in self.keys.items()]


# --------------------------------------------------------------------------- rows
def read_table(path) -> list[SweepRow]:
    """Rows of a run table (CSV with a header; see the module docstring).

    >>> import io, tempfile, os
    >>> with tempfile.NamedTemporaryFile("w", suffix=".csv", delete=False) as fh:
    ...     _ = fh.write("name,material.bending_scale,measured.DC\\nstiff,2,31.5\\nbase,,\\n")
    >>> rows = read_table(fh.name); os.unlink(fh.name)
    >>> [(r.name, r.keys, r.measured) for r in rows]
    [('stiff', {'material.bending_scale': '2'}, {'measured.DC': '31.5'}), ('base', {}, {})]
    """
    path = Path(path)
    try:
        with open(path, newline="") as fh:
            lines = [[cell.strip() for cell in rec] for rec in csv.reader(fh)]
    except FileNotFoundError:
        raise SweepError(f"run table {str(path)!r} does not exist") from None
    columns, records = (lines[0], lines[1:]) if lines else ([], [])
    if not columns:
        raise SweepError(f"run table {path}: no header row (a 'name' column and case keys)")
    for col in columns:
        if not col or (col != "name" and not col.startswith(MEASURED) and "." not in col):
            raise SweepError(f"run table {path}: column {col!r} is neither 'name', a dotted case "
                             f"key (e.g. material.bending_scale) nor measured.<quantity>")
    if len(set(columns)) != len(columns):
        raise SweepError(f"run table {path}: repeated column in {columns}")
    rows = []
    for i, rec in enumerate(r for r in records if any(r)):
        if len(rec) != len(columns):
            raise SweepError(f"run table {path}, row {i + 1}: {len(rec)} cells for "
                             f"{len(columns)} columns")
        cells = dict(zip(columns, rec))
        name = cells.pop("name", "") or f"run{i:03d}"
        keys = {k: v for k, v in cells.items() if v and not k.startswith(MEASURED)}
        measured = {k: v for k, v in cells.items() if v and k.startswith(MEASURED)}
        rows.append(SweepRow(name, keys, measured))
    return _checked(rows, f"run table {path}")


def grid_rows(specs: list[str]) -> list[SweepRow]:
    """Rows of the product of ``KEY=V1,V2,...`` value lists (the last key varies fastest).

    >>> [r.keys for r in grid_rows(["mesh.nx=4,8", "material.friction=true,false"])][:2]
    [{'mesh.nx': '4', 'material.friction': 'true'}, {'mesh.nx': '4', 'material.friction': 'false'}]
    """
    axes = []
    for spec in specs:
        key, sep, values = spec.partition("=")
        key = key.strip()
        if not sep or "." not in key:
            raise SweepError(f"--grid {spec!r}: expected KEY=V1,V2,... with a dotted case KEY")
        items = [v.strip() for v in values.split(",")]
        if not all(items):
            raise SweepError(f"--grid {spec!r}: empty value in the list")
        axes.append([(key, v) for v in items])
    if not axes:
        raise SweepError("--grid: give at least one KEY=V1,V2,...")
    keys = [axis[0][0] for axis in axes]
    if len(set(keys)) != len(keys):
        raise SweepError(f"--grid: key given twice in {keys}")
    rows = [SweepRow(f"run{i:03d}", dict(combo)) for i, combo in enumerate(itertools.product(*axes))]
    return _checked(rows, "--grid")


def _checked(rows: list[SweepRow], where: str) -> list[SweepRow]:
    if not rows:
        raise SweepError(f"{where}: no runs")
    seen = set()
    for row in rows:
        if not _NAME.match(row.name):
            raise SweepError(f"{where}: run name {row.name!r} must be letters, digits, '.', '_' "
                             f"or '-' (it names the run's folder)")
        if row.name in seen:
            raise SweepError(f"{where}: run name {row.name!r} appears twice")
        seen.add(row.name)
    return rows


# --------------------------------------------------------------------------- one run



# --------------------------------------------------------------------------- results
def read_results(path) -> list[dict]:
    """Rows of a results.csv (all values as text)."""
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))
