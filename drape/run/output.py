"""Writing a run to disk as it happens: VTU series with a PVD index, history.csv, summary.json.

Every write is flushed (CSV) or atomic (VTU, PVD, JSON: written to a temporary file in the
same directory, then ``os.replace``-d: :func:`drape.run.atomic.atomic_write`), so a run that
dies at any point leaves a readable PVD that references only complete VTU files.

Examples
--------
>>> import tempfile, numpy as np
>>> from skfem import MeshTri
>>> mesh = MeshTri()                       # unit square, 4 points, 2 triangles
>>> with tempfile.TemporaryDirectory() as d:
...     w = OutputWriter(d, "demo", mesh)
...     _ = w.write_step(0.0, {"displacement": np.zeros((4, 3)), "kappa_xx": np.zeros(2)})
...     w.append_history({"t": 0.0, "kinetic": 0.0})
...     _ = w.write_summary({"status": "completed"})
...     w.close()
...     sorted(p.name for p in w.directory.iterdir())
['demo.pvd', 'demo_0000.vtu', 'history.csv', 'summary.json']
"""
from __future__ import annotations

import csv
import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any, Mapping

import meshio
import numpy as np

from drape.models.fields import split_fields
from drape.run.atomic import atomic_write

__all__ = ["OutputSchedule", "OutputWriter", "read_pvd", "read_history"]


class OutputSchedule:
    """Decide which converged steps are written: every ``every`` steps or every ``every_dt``.

    With ``every_dt`` a step is written once ``t`` has reached the next multiple of
    ``every_dt`` (steps may be cut, so output times are the first converged times past
    each mark). The first step is always written; pass ``force=True`` for the last one.

    Examples
    --------
    >>> s = OutputSchedule(every_dt=0.1)
    >>> [s.due(i, t) for i, t in enumerate([0.0, 0.05, 0.1, 0.12, 0.25])]
    [True, False, True, False, True]
    >>> s = OutputSchedule(every=2)
    >>> [s.due(i, 0.0) for i in range(5)]
    [True, False, True, False, True]
    """

    def __init__(self, every: int | None = 1, every_dt: float | None = None):
        if every_dt is not None and every_dt <= 0:
            raise ValueError(f"output.every_dt = {every_dt}: must be > 0")
        if every is not None and every < 1:
            raise ValueError(f"output.every = {every}: must be >= 1")
        self.every = every
        self.every_dt = every_dt
        self._next_t = -math.inf
        self._last_step = None

    def state_dict(self) -> dict:
        """Where the schedule stands (the next output time, the last step written)."""
        return {"next_t": self._next_t, "last_step": self._last_step}

    def load_state_dict(self, state: dict) -> None:
        """Continue from a :meth:`state_dict`."""
        self._next_t, self._last_step = float(state["next_t"]), state["last_step"]

    def due(self, step: int, t: float, force: bool = False) -> bool:
        if step == self._last_step:
            return False  # already written (e.g. forced write of the last step)
        if self.every_dt is not None:
            ok = force or t >= self._next_t - 1e-9 * self.every_dt
            if ok:
                self._next_t = (math.floor(t / self.every_dt + 1e-9) + 1) * self.every_dt
        else:
            ok = force or step % (self.every or 1) == 0
        if ok:
            self._last_step = step
        return ok


class OutputWriter:
    """Write a run's VTU series, PVD index, history and summary into ``directory``.

    Parameters
    ----------
    directory : path
        Created if missing; an earlier series of the same ``name`` in it is removed.
    name : str
        File stem: ``<name>_NNNN.vtu`` and ``<name>.pvd``.
    mesh : skfem.MeshTri
        Reference configuration (z = 0 plane); displacement is stored as point data.
    fields : list of str, optional
        Field names to keep (all if None); unknown names raise ``ValueError``.
    keep : (int, int), optional
        Continue the series already in ``directory`` (a resumed run): keep its first
        ``keep[0]`` VTU steps and ``keep[1]`` rows of history.csv, drop what came after.
    """

    def __init__(self, directory, name: str, mesh, fields: list[str] | None = None,
                 keep: tuple[int, int] | None = None):
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        self.name = name
        p = np.asarray(mesh.p, dtype=float)
        self.points = np.vstack([p, np.zeros((3 - p.shape[0], p.shape[1]))]).T.copy()
        self.cells = [("triangle", np.asarray(mesh.t, dtype=np.int64).T.copy())]
        self.fields = None if fields is None else list(fields)
        self.datasets: list[tuple[float, str]] = []
        self._history_file = None
        self._history_writer = None
        self.history_path = self.directory / "history.csv"
        self.pvd_path = self.directory / f"{name}.pvd"
        if keep is not None:
            self._keep(*keep)
            return
        # a new run in an old directory: drop the old series so that no stale step is left
        for old in self.directory.glob(f"{name}_[0-9][0-9][0-9][0-9].vtu"):
            old.unlink()
        for old in (self.pvd_path, self.history_path, self.directory / "summary.json"):
            old.unlink(missing_ok=True)

    def _keep(self, n_steps: int, n_rows: int) -> None:
        listed = read_pvd(self.pvd_path) if self.pvd_path.exists() else []
        with open(self.history_path, newline="") as fh:
            lines = list(csv.reader(fh))
        if len(listed) < n_steps or len(lines) - 1 < n_rows:
            raise ValueError(f"{self.directory}: {len(listed)} VTU steps and {len(lines) - 1} "
                             f"history rows, fewer than the {n_steps} and {n_rows} to continue from")
        self.datasets = [(t, path.name) for t, path in listed[:n_steps]]
        kept = {filename for _, filename in self.datasets}
        for old in self.directory.glob(f"{self.name}_[0-9][0-9][0-9][0-9].vtu"):
            if old.name not in kept:
                old.unlink()
        self._write_pvd()

        def write_rows(path):
            with open(path, "w", newline="") as fh:
                csv.writer(fh).writerows(lines[:n_rows + 1])

        atomic_write(self.history_path, write_rows)
        self._history_file = open(self.history_path, "a", newline="")
        self._history_writer = csv.DictWriter(self._history_file, fieldnames=lines[0],
                                              extrasaction="ignore", restval="")
        (self.directory / "summary.json").unlink(missing_ok=True)

    @property
    def n_points(self) -> int:
        return self.points.shape[0]

    @property
    def n_cells(self) -> int:
        return self.cells[0][1].shape[0]

    def _select(self, data: dict) -> dict:
        if self.fields is None:
            return data
        return {k: v for k, v in data.items() if k in self.fields or k == "displacement"}

    def write_step(self, t: float, fields: Mapping[str, Any]) -> Path:
        """Write one VTU file for time ``t`` and rewrite the PVD index to include it."""
        point_data, cell_data = split_fields(fields, self.n_points, self.n_cells)
        if self.fields is not None:
            missing = set(self.fields) - set(point_data) - set(cell_data)
            if missing:
                raise ValueError(
                    f"output.fields names {sorted(missing)} which the model does not produce; "
                    f"available: {', '.join(sorted({*point_data, *cell_data}))}"
                )
        point_data, cell_data = self._select(point_data), self._select(cell_data)
        mesh = meshio.Mesh(
            self.points,
            self.cells,
            point_data={k: np.ascontiguousarray(v, dtype=float) for k, v in point_data.items()},
            cell_data={k: [np.ascontiguousarray(v, dtype=float)] for k, v in cell_data.items()},
        )
        filename = f"{self.name}_{len(self.datasets):04d}.vtu"
        atomic_write(self.directory / filename, lambda p: meshio.write(p, mesh, file_format="vtu"))
        self.datasets.append((float(t), filename))
        self._write_pvd()
        return self.directory / filename

    def _write_pvd(self) -> None:
        root = ET.Element(
            "VTKFile", type="Collection", version="0.1", byte_order="LittleEndian"
        )
        collection = ET.SubElement(root, "Collection")
        for t, filename in self.datasets:
            ET.SubElement(
                collection, "DataSet", timestep=repr(t), group="", part="0", file=filename
            )
        ET.indent(root)
        tree = ET.ElementTree(root)
        atomic_write(
            self.pvd_path, lambda p: tree.write(p, encoding="utf-8", xml_declaration=True)
        )

    def append_history(self, row: Mapping[str, Any]) -> None:
        """Append one row to ``history.csv`` and flush; columns are fixed by the first row."""
        if self._history_writer is None:
            self._history_file = open(self.history_path, "w", newline="")
            self._history_writer = csv.DictWriter(
                self._history_file, fieldnames=list(row), extrasaction="ignore", restval=""
            )
            self._history_writer.writeheader()
        self._history_writer.writerow({k: _scalar(v) for k, v in row.items()})
        self._history_file.flush()

    def write_summary(self, summary: Mapping[str, Any]) -> Path:
        """Write ``summary.json`` atomically (numpy scalars and arrays converted)."""
        path = self.directory / "summary.json"
        text = json.dumps(summary, indent=2, default=_json_default, allow_nan=True)
        atomic_write(path, lambda p: p.write_text(text + "\n"))
        return path

    def close(self) -> None:
        if self._history_file is not None:
            self._history_file.close()
            self._history_file = None
            self._history_writer = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _scalar(v):
    if isinstance(v, (np.floating, float)):
        return repr(float(v))
    if isinstance(v, np.integer):
        return int(v)
    return v


def _json_default(obj):
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"cannot write {type(obj).__name__} to summary.json")


def read_history(path) -> list[dict]:
    """Rows of a ``history.csv``, numbers as float (int for whole numbers), blanks as None."""
    def value(text):
        if text == "":
            return None
        x = float(text)
        return int(x) if x.is_integer() and "." not in text and "e" not in text.lower() else x

    with open(path, newline="") as fh:
        return [{k: value(v) for k, v in row.items()} for row in csv.DictReader(fh)]


def read_pvd(path) -> list[tuple[float, Path]]:
    """Return ``[(time, vtu_path), ...]`` from a PVD collection.

    Examples
    --------
    >>> import tempfile, numpy as np
    >>> from skfem import MeshTri
    >>> with tempfile.TemporaryDirectory() as d:
    ...     w = OutputWriter(d, "demo", MeshTri())
    ...     _ = w.write_step(0.5, {"displacement": np.zeros((4, 3))})
    ...     [(t, p.name) for t, p in read_pvd(w.pvd_path)]
    [(0.5, 'demo_0000.vtu')]
    """
    path = Path(path)
    root = ET.parse(path).getroot()
    return [
        (float(ds.get("timestep")), path.parent / ds.get("file"))
        for ds in root.iter("DataSet")
    ]
