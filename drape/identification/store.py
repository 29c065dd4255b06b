"""Forward runs kept on disk: one evaluation (a parameter point's seed ensemble) a line.

``evaluations.jsonl`` gets a line as soon as an evaluation's runs have all finished, flushed
and synced, so an identification killed at any moment keeps every finished one;
``evaluations.csv`` is the same as a table to read. A record holds the point, the set-up it
was run in (a fingerprint of the base case with its ``--set`` items, and the weight) and
each seed's descriptors, not a misfit: the misfit belongs to a fabric and is computed
again from the descriptors, so the evaluations of one fabric warm-start another's
identification (a *library*: a folder whose ``evaluations.jsonl`` collects the forward runs
of many identifications in the same set-up).
"""
from __future__ import annotations

import csv
import hashlib
import json
import os
from dataclasses import dataclass, field
from pathlib import Path

from constitutive.bundled import cases_dir
from drape.identification.target import Drape, Drapes

__all__ = ["EVALUATIONS", "BUNDLED_LIBRARY", "Evaluation", "fingerprint", "read_evaluations",
           "append_evaluation", "library_evaluations"]

EVALUATIONS = "evaluations.jsonl"
TABLE = "evaluations.csv"
#: Forward runs shipped with the package (``cases/libraries/identification``), by set-up: an
#: identification on a bundled base case starts from them instead of from nothing.
BUNDLED_LIBRARY = cases_dir("libraries", "identification")


@dataclass
class Evaluation:
    """One parameter point run under several perturbation seeds.

    Attributes
    ----------
    point : dict
        Every parameter's value (:func:`drape.identification.parameters.full_point`).
    setup : str
        :func:`fingerprint` of the set-up.
    runs : list of dict
        Per seed: ``seed``, ``status``, ``run_dir``, ``wall_time_s``, ``reason`` and ``drape``
        (:meth:`Drape.to_json`, or None when the run gave no drape).
    name : str
    """

    point: dict
    setup: str
    runs: list = field(default_factory=list)
    name: str = ""

    @property
    def drapes(self) -> Drapes:
        """The drapes of the seeds that gave one."""
        return Drapes(tuple(Drape.from_json(r["drape"]) for r in self.runs if r.get("drape")))

    @property
    def wall_time_s(self) -> float:
        return float(sum(r.get("wall_time_s") or 0.0 for r in self.runs))

    def to_json(self) -> dict:
        return {"name": self.name, "point": self.point, "setup": self.setup, "runs": self.runs}

    @classmethod
    def from_json(cls, data: dict) -> "Evaluation":
        return cls(data["point"], data["setup"], data["runs"], data.get("name", ""))


def fingerprint(case_text: str, overrides, weight: float) -> str:
    """A short hash of what makes forward runs comparable: the resolved base case (with the
    user's ``--set`` items) and the weight the parameters are scaled by."""
    text = json.dumps({"case": case_text, "set": sorted(overrides), "weight": weight})
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def read_evaluations(folder) -> list[Evaluation]:
    """The evaluations stored in ``folder`` (none when it has no store). A last line cut by a
    kill is skipped."""
    path = Path(folder) / EVALUATIONS
    if not path.exists():
        return []
    out = []
    for line in path.read_text().splitlines():
        try:
            out.append(Evaluation.from_json(json.loads(line)))
        except (json.JSONDecodeError, KeyError):
            continue
    return out


def append_evaluation(folder, evaluation: Evaluation) -> None:
    """Add ``evaluation`` to the store of ``folder`` (both files), synced to disk."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    with open(folder / EVALUATIONS, "a") as fh:
        fh.write(json.dumps(evaluation.to_json()) + "\n")
        fh.flush()
        os.fsync(fh.fileno())
    _append_row(folder / TABLE, evaluation)


def _append_row(path: Path, e: Evaluation) -> None:
    d = e.drapes
    row = {"name": e.name, **{k: "" if v is None else v for k, v in e.point.items()},
           "seeds": len(e.runs), "drapes": len(d),
           "DC_percent": " ".join(f"{x:.2f}" for x in d.dc),
           "nodes": " ".join(str(n) for n in d.nodes),
           "wall_time_s": f"{e.wall_time_s:.1f}"}
    new = not path.exists()
    with open(path, "a", newline="") as fh:
        writer = csv.DictWriter(fh, list(row))
        if new:
            writer.writeheader()
        writer.writerow(row)
        fh.flush()
        os.fsync(fh.fileno())


def library_evaluations(folder, setup: str, fixed: dict) -> list[Evaluation]:
    """The library's evaluations run in ``setup`` whose parameters not freed here have the
    values ``fixed`` gives (they can join this identification's surrogate)."""
    return [e for e in read_evaluations(folder)
            if e.setup == setup and all(e.point.get(k) == v for k, v in fixed.items())]
