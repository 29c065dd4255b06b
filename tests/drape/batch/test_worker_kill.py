"""A Dask worker killed (SIGKILL) in the middle of a run: the sweep and the identification
still end with every row and every evaluation exactly once, equal to an undisturbed run's.

The worker is the process that holds the run folder's lock once the run has a checkpoint and
no summary yet, so the kill lands between two steps of a run. Dask gives the task to the
worker its nanny starts in place of the dead one; the run starts again (a sweep) or continues
from its checkpoint (an identification).
"""
from __future__ import annotations

import csv
import json
import math
import os
import signal
import threading
import time
from contextlib import contextmanager
from pathlib import Path

import psutil
import pytest

from drape.batch import rows as sweep_rows
from drape.batch.sweep import open_client, run_sweep
from drape.identification.forward import ForwardRuns
from drape.identification.search import Search, run_search
from drape.identification.store import read_evaluations
from drape.identification.target import Drape, Drapes
from drape.run.lock import LOCK

ROOT = Path(__file__).resolve().parents[3]
CUSICK = ROOT / "cases" / "cusick_kes.toml"
#: The tiny Cusick case, 30 steps long (a few seconds), let down in 0.1 s so that its drape
#: depends on the fabric: long enough to be killed between two steps.
LONGER = ["solver.t_end=0.3", "load.gravity.ramp_time=0.1", "load.perturbation.duration=0.1"]
#: Result columns that time or place a run rather than say what it gave.
TIMING = ("wall_time_s", "worker")

pytestmark = pytest.mark.slow


class WorkerKiller(threading.Thread):
    """Kill, once, the child process that runs a run under ``root``: the holder of a run
    folder's lock once the folder has a checkpoint and no summary."""

    def __init__(self, root: Path):
        super().__init__(daemon=True)
        self.root = Path(root)
        self.killed: Path | None = None
        self.done = threading.Event()

    def run(self) -> None:
        me = psutil.Process()
        while not self.done.is_set():
            for lock in self.root.glob(f"**/{LOCK}"):
                run = lock.parent
                if not (run / "checkpoint.npz").exists() or (run / "summary.json").exists():
                    continue
                pid = _holder(me, lock)
                if pid is not None:
                    os.kill(pid, signal.SIGKILL)
                    self.killed = run
                    return
            time.sleep(0.005)


@contextmanager
def killing(root: Path, armed: bool):
    """A :class:`WorkerKiller` watching ``root`` for the block if ``armed`` (else idle)."""
    killer = WorkerKiller(root)
    if armed:
        killer.start()
    try:
        yield killer
    finally:
        killer.done.set()
        if armed:
            killer.join(timeout=10)


def _holder(me: psutil.Process, lock: Path) -> int | None:
    """The pid of the child process of ``me`` that has ``lock`` open, if any."""
    for child in me.children(recursive=True):
        try:
            if any(f.path == str(lock) for f in child.open_files()):
                return child.pid
        except (psutil.NoSuchProcess, psutil.AccessDenied):
            continue
    return None


def history(run_dir: Path) -> list[dict]:
    with open(run_dir / "history.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def same_history(a: list[dict], b: list[dict]) -> bool:
    """Step by step the same run. Numbers agree to 1e-12: ipctk sums the barrier energy in a
    parallel reduction whose order, and so whose last bit, changes from run to run; that energy
    is reported, never fed back, so every other column is bit for bit equal."""
    def close(x: str, y: str) -> bool:
        try:
            return x == y or math.isclose(float(x), float(y), rel_tol=1e-12, abs_tol=1e-300)
        except ValueError:
            return False
    return len(a) == len(b) and all(
        ra.keys() == rb.keys() and all(close(ra[k], rb[k]) for k in ra) for ra, rb in zip(a, b))


# --------------------------------------------------------------------------- sweep
def sweep_into(out: Path, tiny_cusick, kill: bool) -> Path | None:
    rows = sweep_rows.grid_rows(["material.bending_scale=1,2"])
    with killing(out, kill) as killer:
        run_sweep(CUSICK, rows, out, overrides=[*tiny_cusick, *LONGER], workers=1, quiet=True)
    return killer.killed


def results(out: Path) -> dict:
    return {r["name"]: {k: v for k, v in r.items() if k not in TIMING}
            for r in sweep_rows.read_results(out / "results.csv")}


def test_a_sweep_survives_a_worker_killed_mid_run(tmp_path, tiny_cusick):
    reference, disturbed = tmp_path / "undisturbed", tmp_path / "killed"
    sweep_into(reference, tiny_cusick, kill=False)
    killed = sweep_into(disturbed, tiny_cusick, kill=True)
    assert killed is not None and killed.parent == disturbed / "runs"

    names = [r["name"] for r in sweep_rows.read_results(disturbed / "results.csv")]
    assert sorted(names) == ["run000", "run001"]               # every row, exactly once
    assert results(disturbed) == results(reference)
    assert all(r["status"] == "completed" for r in results(disturbed).values())
    assert same_history(history(killed), history(reference / "runs" / killed.name))


# --------------------------------------------------------------------------- identification
#: Two made-up scans far apart (DC 40 and 100 %): any point of the box is within their reach.
SCANS = Drapes(tuple(Drape(name, dc, nodes, tuple([0.14] + [0.0] * 20))
                     for name, dc, nodes in (("a", 40.0, 5), ("b", 100.0, 8))))


def identify_into(out: Path, tiny_cusick, kill: bool):
    """Three evaluations (the box's corners and one design point), one seed each."""
    out.mkdir()
    search = Search(SCANS, {"bending_length": (1.2, 3.5)}, 3, out, "tiny", n_design=1)
    client, cluster = open_client(workers=1)
    try:
        forward = ForwardRuns(client, str(CUSICK), [*tiny_cusick, *LONGER], 12.5, 1,
                              out / "runs", "tiny")
        with killing(out, kill) as killer:
            found = run_search(search, forward)
    finally:
        client.close()
        cluster.close()
    return found, killer.killed


def evaluations(out: Path) -> list[dict]:
    """The stored evaluations, without their wall times and with run folders relative."""
    kept = []
    for e in read_evaluations(out):
        data = e.to_json()
        for run in data["runs"]:
            run.pop("wall_time_s")
            run["run_dir"] = str(Path(run["run_dir"]).relative_to(out))
        kept.append(data)
    return kept


def test_an_identification_survives_a_worker_killed_mid_run(tmp_path, tiny_cusick):
    reference, disturbed = tmp_path / "undisturbed", tmp_path / "killed"
    expected, _ = identify_into(reference, tiny_cusick, kill=False)
    found, killed = identify_into(disturbed, tiny_cusick, kill=True)
    assert killed is not None and killed.parent.parent == disturbed / "runs"

    got = evaluations(disturbed)
    assert [e["name"] for e in got] == ["e000", "e001", "e002"]   # every evaluation, once
    assert all(r["status"] == "completed" and r["drape"] for e in got for r in e["runs"])
    assert got == evaluations(reference)
    assert found["answer"] == expected["answer"]
    # the killed run went on from its checkpoint: each of its steps is in its history once
    assert same_history(history(killed), history(reference / killed.relative_to(disturbed)))
    assert json.loads((disturbed / "pending.json").read_text()) == {}
