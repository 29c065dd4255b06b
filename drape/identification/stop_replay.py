"""Where the convergence stop would have ended identifications that spent their budget.

Identifications run with ``--converged-within 0`` (or before the stop existed) hold every point
their search ran. In each, the search's own points are taken in order (the final
``identified`` runs aside); the stop fires at the first point that lies within ``W`` box widths
(log scale, :func:`drape.identification.surrogate.unit_distance`) of an earlier one of the
folder (:func:`stop_index`). Library points are left out, so the stop could only come earlier
than shown. Until the stop the search is the same either way (the surrogate sees the same
evaluations), so :func:`replay_table` gives the evaluations and forward-run wall time the stop
saves, not its effect on the answer. The stop as ``drape identify`` applies it also needs the
surrogate's answer run, which the stored points do not say; where it was not, the search goes
on from the point shown.
"""
from __future__ import annotations

import json
from pathlib import Path

from drape.identification.store import read_evaluations
from drape.identification.surrogate import unit_distance

__all__ = ["stop_index", "replay_table"]


def stop_index(points: list[dict], box: dict, within: float) -> int:
    """Number of points run before the stop fires (all of them if it never does).

    >>> box = {"bending_length": (1.0, 4.0)}
    >>> stop_index([{"bending_length": c} for c in (1.0, 2.0, 2.01, 3.0)], box, 0.01)
    2
    """
    for i in range(1, len(points)):
        if min(unit_distance(box, points[i], q) for q in points[:i]) <= within:
            return i
    return len(points)


def _row(folder: Path, within) -> str | None:
    """The table's line of one identification folder (None if it ran no point of its own)."""
    box = {k: tuple(v) for k, v in json.loads((folder / "identify.json").read_text())["box"].items()}
    own = [e for e in read_evaluations(folder) if not e.name.startswith("identified")]
    if not own:
        return None
    # each evaluation's seeds run side by side: its wall is its longest run
    wall = [max(r.get("wall_time_s") or 0.0 for r in e.runs) / 60 for e in own]
    cells = []
    for w in within:
        n = stop_index([e.point for e in own], box, w)
        cells.append(f"{n}, {sum(wall[:n]):.1f}")
    return f"| {folder.name} | {len(own)} | {sum(wall):.1f} | " + " | ".join(cells) + " |"


def replay_table(directory, within=(0.01, 0.02)) -> str:
    """The stop replayed on every identification folder of ``directory`` (``*/identify.json``).

    Parameters
    ----------
    directory : path
        Folder of identification folders.
    within : sequence of float
        The stop's distances ``W`` to replay (box widths).

    Returns
    -------
    str
        A markdown table: per folder the points it ran and their wall time (minutes), and per
        ``W`` the points and wall time until the stop.

    Raises
    ------
    ValueError
        ``directory`` holds no identification folder.
    """
    directory = Path(directory)
    folders = sorted(f.parent for f in directory.glob("*/identify.json"))
    if not folders:
        raise ValueError(f"{directory}: no identification folders (*/identify.json)")
    head = " | ".join(f"W = {w:g}: points, wall (min)" for w in within)
    lines = [f"| folder | points run | wall (min) | {head} |", "|---|---|---|" + "---|" * len(within)]
    return "\n".join(lines + [r for r in (_row(f, within) for f in folders) if r is not None])
