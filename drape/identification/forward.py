"""Forward runs of parameter points on the sweep's Dask machinery.

A point is the base case with the point's ``--set`` items (:func:`drape.identification.parameters.overrides`)
run under the perturbation seeds 0 .. N-1, each an ordinary run (:func:`drape.batch.sweep.run_row`)
in ``DIR/runs/<point>/s<seed>/``, the seeds of a point and the points in flight all Dask tasks
at once. A run stopped midway continues from its checkpoint and a finished one is read back
from its summary (``run_row(..., resume=True)``), so a resumed identification loses no run.
"""
from __future__ import annotations

import uuid
from pathlib import Path

from drape.batch.ensemble import SEED_KEY
from drape.batch.sweep import run_row
from drape.identification.parameters import overrides
from drape.identification.store import Evaluation
from drape.identification.target import drape_of
from drape.run.runner import ResumeError, read_summary

__all__ = ["ForwardRuns"]

GOOD = ("completed", "settled")


class ForwardRuns:
    """Submit parameter points to a Dask client and collect their evaluations.

    Parameters
    ----------
    client : distributed.Client
    case_path : str
        The base case (absolute path: the workers read it).
    base_overrides : list of str
        The user's ``--set`` items, before each point's own.
    weight : float
        Weight W (mg/cm²) the point's ratios are scaled by.
    seeds : int
    root : Path
        Folder of the runs (``root/<name>/s<seed>``).
    setup : str
        The set-up's fingerprint, stored with each evaluation.
    """

    def __init__(self, client, case_path: str, base_overrides, weight: float, seeds: int,
                 root: Path, setup: str):
        self.client, self.case_path = client, case_path
        self.base, self.weight, self.seeds = list(base_overrides), weight, seeds
        self.root, self.setup = Path(root), setup
        self.pending: dict[str, tuple[dict, list]] = {}
        self._tag = uuid.uuid4().hex[:8]

    def submit(self, name: str, point: dict) -> None:
        """Start the seeds of ``point`` (every parameter's value) as Dask tasks."""
        items = self.base + overrides(point, self.weight)
        futures = [self.client.submit(run_row, self.case_path, items + [f"{SEED_KEY}={s}"],
                                      str(self.root / name / f"s{s}"), True,
                                      key=f"identify-{name}-s{s}-{self._tag}", pure=False)
                   for s in range(self.seeds)]
        self.pending[name] = (point, futures)

    def next_finished(self) -> Evaluation:
        """Wait until every seed of some pending point has finished; return its evaluation."""
        from distributed import wait

        while True:
            for name, (point, futures) in self.pending.items():
                if all(f.done() for f in futures):
                    del self.pending[name]
                    return self._evaluation(name, point, futures)
            wait([f for _, fs in self.pending.values() for f in fs if not f.done()],
                 return_when="FIRST_COMPLETED")

    def cancel(self) -> None:
        """Cancel what is still running (a stopped identification starts no new run)."""
        futures = [f for _, fs in self.pending.values() for f in fs]
        if futures:
            self.client.cancel(futures, force=True)

    def _evaluation(self, name: str, point: dict, futures) -> Evaluation:
        runs = []
        for seed, fut in enumerate(futures):
            try:
                result = fut.result()
            except Exception as exc:   # the worker died under it, or it was cancelled
                result = {"status": "lost", "reason": str(exc)}
            run_dir = self.root / name / f"s{seed}"
            runs.append({"seed": seed, "status": result.get("status"), "run_dir": str(run_dir),
                         "wall_time_s": result.get("wall_time_s"),
                         "reason": result.get("reason", ""),
                         "drape": _drape(run_dir, result, f"{name}.s{seed}")})
        return Evaluation(point, self.setup, runs, name)


def _drape(run_dir: Path, result: dict, name: str) -> dict | None:
    """The run's descriptors from its summary, or None when it gave no drape."""
    if result.get("status") not in GOOD:
        return None
    try:
        analysis = read_summary(run_dir).get("analysis", {})
    except ResumeError:
        return None
    if "drape_coefficient_percent" not in analysis:
        return None
    return {**drape_of(name, analysis).to_json(), "pvd": result.get("pvd")}
