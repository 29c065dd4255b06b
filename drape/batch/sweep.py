"""Drape a catalogue: one base case, many runs, on Dask.

``python -m drape.sweep BASE.toml [--table RUNS.csv | --grid KEY=V1,V2,... ...] [--seeds N] --out DIR``

Each run is an ordinary case run (:func:`drape.run.runner.run_case`) of the base case with the row's
keys overridden, in its own folder ``DIR/runs/<name>/``. The runs are Dask tasks: on an
embedded :class:`distributed.LocalCluster` (one single-threaded worker process per core) by
default, or on an existing cluster with ``--scheduler tcp://HOST:PORT`` (or the
``DASK_SCHEDULER_ADDRESS`` environment variable). Workers of an existing cluster must see the
case file and ``DIR`` under the same paths (a shared file system).

A run table is a CSV file with one row per run: a ``name`` column (optional; ``run000`` ...
otherwise), any case keys by their dotted names as columns (values read like ``--set``
values; an empty cell keeps the base case's value), and columns ``measured.<quantity>`` that
are not case keys but measurements copied into the results (``measured.DC``, the measured
drape coefficient in %, is drawn beside the computed one in the report). A grid is the
product of the values given for each key. ``--seeds N`` runs every row (or the base case
alone) under the perturbation seeds 0 .. N-1 and writes ``DIR/ensemble.json``, the seed
ensemble of each row (:mod:`drape.batch.ensemble`).

``DIR/results.csv`` gets one row per finished run as soon as it finishes: the inputs, the
status, the drape coefficient and nodes (Cusick runs), the settling time, the wall time and,
for a run that did not finish well, the one-line reason. A run that fails does not stop the
others. ``--resume`` keeps the rows already finished and runs only the others (a run stopped midway
continues from its checkpoint); the sweep's definition is kept in ``DIR/sweep.json``, so
``--resume --out DIR`` alone continues it.

A run that finished (its ``summary.json`` says completed or settled, for the same case) is
never run again: on ``--resume`` its row is read back from its summary, so a sweep stopped and
resumed gives the same ``results.csv`` as one never stopped.

Statuses: those of :mod:`drape.run.runner` (completed, settled, failed, interrupted, terminated,
error), ``invalid`` (the row's case does not validate or cannot be built) and ``lost`` (the
worker running it died). Exit codes (:mod:`drape.cli.sweep`): 0 every run finished (whatever its
status), 2 bad input, 4 an I/O error (the folder cannot be written or another sweep writes
into it, the scheduler cannot be reached), 130 interrupted (Ctrl-C), 143 terminated
(SIGTERM): finished rows stay in ``results.csv``. The Dask dashboard is off unless
``--dashboard`` asks for it, and then it listens on 127.0.0.1 only.

The embedded cluster listens on 127.0.0.1 only, and speaks mutual TLS with certificates made
for it when it starts and held in memory (:meth:`distributed.security.Security.temporary`):
another user of the machine can reach its port but cannot connect, so only the client of the
process that started it submits work. An existing cluster (``--scheduler``) is used with
whatever security its address and the Dask configuration give.
"""
from __future__ import annotations

import csv
import json
import math
import os
import socket
import sys
import time
import uuid
from pathlib import Path

from constitutive.units import G0
from drape.batch.rows import MEASURED, RESULT_COLUMNS, SweepError, SweepRow, read_results
from drape.case.build import build
from drape.case.case import CaseError, dump_case, load_case
from drape.fem.compiled import limit_threads
from drape.run.atomic import atomic_write, atomic_write_text
from drape.run.checkpoint import CHECKPOINT, CheckpointError, read_checkpoint
from drape.run.messages import describe, one_line
from drape.run.lock import folder_lock
from drape.run.runner import ResumeError, read_summary, run_case

__all__ = ['SINGLE_THREADED', 'open_client', 'run_row', 'run_sweep']



#: Statuses that mean "this run has to be run again" on ``--resume``.
UNFINISHED = ("interrupted", "terminated", "lost")

#: Thread limits of a run: one core per worker process, whatever its kernels could use.
SINGLE_THREADED = {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
# numba's kernels are capped by drape.fem.compiled.limit_threads, not by NUMBA_NUM_THREADS: numba
# re-reads that variable at every compilation and refuses a value other than its pool's.


def _one_line(exc: BaseException) -> str:
    text = " ".join(part.strip() for part in str(exc).splitlines() if part.strip())
    return f"{type(exc).__name__}: {text}" if not isinstance(exc, (CaseError, ValueError)) else text


class SchedulerError(OSError):
    """The Dask scheduler given cannot be reached (the message names its address)."""


def _material_columns(material) -> dict:
    """B of each direction (simulated KES-FB), the weight W and the bending length (B/W)^(1/3).

    The bending length of the fabric uses the geometric mean of the warp and weft B, i.e. it
    is the geometric mean of the two directions' bending lengths.
    """
    kes = material.simulated_kes()
    b_warp, b_weft = float(kes["warp"].B), float(kes["weft"].B)
    weight = float(material.areal_mass) * G0
    return {"B_warp_Nm": b_warp, "B_weft_Nm": b_weft, "weight_N_per_m2": weight,
            "bending_length_m": (math.sqrt(b_warp * b_weft) / weight) ** (1.0 / 3.0)}


def _worker_address() -> str:
    from distributed import get_worker

    try:
        return get_worker().address
    except ValueError:   # called outside a Dask worker
        return ""


def _continues(case, run_dir: Path) -> bool:
    """True when ``run_dir`` holds a stopped run of exactly ``case`` with a checkpoint."""
    return (run_dir / CHECKPOINT).exists() and _same_case(case, run_dir)


def _same_case(case, run_dir: Path) -> bool:
    """True when ``run_dir/case.resolved.toml`` is ``case``."""
    resolved = run_dir / "case.resolved.toml"
    if not resolved.exists():
        return False
    body = "".join(line for line in resolved.read_text().splitlines(keepends=True)
                   if not line.startswith("#"))
    return body == dump_case(case)


def run_row(case_path: str, overrides: list[str], run_dir: str, resume: bool = False) -> dict:
    """Run one row: an ordinary case run of ``case_path`` with ``overrides`` in ``run_dir``.

    With ``resume``, a run of the same case stopped in ``run_dir`` continues from its
    checkpoint. Never raises for a bad row or a failed run: the returned result columns say
    what happened (this is the Dask task, and one run must not stop the others).
    """
    for key, value in SINGLE_THREADED.items():
        os.environ.setdefault(key, value)
    limit_threads(1)

    wall0 = time.perf_counter()
    out = {"run_dir": run_dir, "worker": _worker_address()}
    try:
        case = load_case(case_path, overrides)
        parts = build(case)
        out.update(_material_columns(parts.material))
    except (CaseError, ValueError) as exc:
        return {**out, "status": "invalid", "reason": _one_line(exc)}
    except Exception as exc:
        return {**out, "status": "error", "reason": _one_line(exc)}
    source = f"from {case_path}" + "".join(f" --set {o}" for o in overrides)
    try:
        finished = _finished_run(case, Path(run_dir)) if resume else None
        if finished is not None:                  # ran to its end before the sweep was stopped
            return {**out, **_summary_columns(finished), "wall_time_s": finished["wall_time_s"]}
        checkpoint = _checkpoint(case, Path(run_dir)) if resume else None
        summary = run_case(case, Path(run_dir), quiet=True, parts=parts, source=source,
                           resume=checkpoint)
    except Exception as exc:
        return {**out, "status": "error", "reason": _one_line(exc),
                "wall_time_s": time.perf_counter() - wall0}
    return {**out, **_summary_columns(summary), "wall_time_s": time.perf_counter() - wall0}


def _summary_columns(summary: dict) -> dict:
    """The result columns a run's summary gives."""
    analysis = summary.get("analysis", {})
    out = {"status": summary["status"],
           "reason": "" if summary["status"] in ("completed", "settled") else summary["reason"],
           "DC_percent": analysis.get("drape_coefficient_percent"),
           "nodes": analysis.get("n_nodes"),
           "settling_time_s": summary.get("settling_time"),
           "t_final_s": summary["t_final"], "steps": summary["steps"], "pvd": summary["pvd"]}
    if "error" in analysis:
        out["reason"] = f"analysis {analysis.get('name')}: {analysis['error']}"
    return out


def _finished_run(case, run_dir: Path) -> dict | None:
    """The summary of a run of exactly ``case`` that finished in ``run_dir``, else None."""
    try:
        summary = read_summary(run_dir)
    except ResumeError:
        return None
    if summary.get("status") not in ("completed", "settled") or not _same_case(case, run_dir):
        return None
    return summary


def _checkpoint(case, run_dir: Path):
    """The checkpoint of a stopped run of exactly ``case`` in ``run_dir``; None when there is
    none or it cannot be read (the row then runs from its start)."""
    if not _continues(case, run_dir):
        return None
    try:
        return read_checkpoint(run_dir)
    except CheckpointError:
        return None




class _Results:
    """results.csv: a header, then one row per finished run, each flushed to disk at once."""

    def __init__(self, path: Path, rows: list[SweepRow], keep: list[dict]):
        keys = list(dict.fromkeys(k for r in rows for k in r.keys))
        measured = list(dict.fromkeys(k for r in rows for k in r.measured))
        self.columns = ["name", *keys, *measured, *RESULT_COLUMNS]

        def write(tmp: Path) -> None:     # rewritten whole: only finished rows survive
            with open(tmp, "w", newline="") as fh:
                writer = csv.DictWriter(fh, self.columns, extrasaction="ignore")
                writer.writeheader()
                writer.writerows(keep)

        atomic_write(path, write)
        self.fh = open(path, "a", newline="")
        self.writer = csv.DictWriter(self.fh, self.columns, extrasaction="ignore")

    def add(self, row: SweepRow, result: dict) -> dict:
        record = {"name": row.name, **row.keys, **row.measured,
                  **{k: _cell(result.get(k)) for k in RESULT_COLUMNS}}
        self.writer.writerow(record)
        self.fh.flush()
        os.fsync(self.fh.fileno())
        return record

    def close(self):
        self.fh.close()


def _cell(value):
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)
    return value


# --------------------------------------------------------------------------- the sweep
#: Seconds to wait for an existing scheduler to answer.
CONNECT_TIMEOUT = 10


def _client(scheduler: str | None, workers: int | None, dashboard: bool = False):
    """A Dask client: of ``scheduler`` (or DASK_SCHEDULER_ADDRESS), else of a local cluster
    (:func:`_local_cluster`)."""
    import dask
    from distributed import Client

    address = scheduler or dask.config.get("scheduler-address", None)
    if address:
        _reachable(address)
        return Client(address, timeout=f"{CONNECT_TIMEOUT}s"), None
    cluster = _local_cluster(workers or os.cpu_count() or 1, dashboard)
    return Client(cluster), cluster      # the cluster's credentials go with it


def _local_cluster(workers: int, dashboard: bool = False):
    """A :class:`distributed.LocalCluster` of ``workers`` single-threaded processes that only
    this process's client can use.

    It listens on 127.0.0.1 only, its web server (health checks; the dashboard, which has no
    authentication, only if ``dashboard``) too. Any local user can reach a port there, so the
    scheduler, workers and client speak mutual TLS with a key and certificate made for this
    cluster and never written to disk: a client without them is refused at the handshake.
    """
    from distributed import LocalCluster
    from distributed.security import Security

    return LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                        host="127.0.0.1", protocol="tls://", security=Security.temporary(),
                        dashboard_address="127.0.0.1:0", scheduler_kwargs={"dashboard": dashboard},
                        env=dict(SINGLE_THREADED))


def open_client(scheduler: str | None = None, workers: int | None = None):
    """``(client, cluster)``: a Dask client of ``scheduler`` (or DASK_SCHEDULER_ADDRESS), else
    of a local cluster of ``workers`` single-threaded processes (``cluster`` is then the
    :class:`distributed.LocalCluster` to close after the client; None otherwise), for tools
    that submit :func:`run_row` tasks themselves."""
    return _client(scheduler, workers)


def _reachable(address: str) -> None:
    """Check that ``address`` is a scheduler address and that something listens there.

    Raises :class:`SweepError` for an address that is not one and :class:`SchedulerError`
    when nothing answers, before the sweep writes anything (a client that fails to connect
    cannot be closed cleanly).
    """
    from distributed.comm import parse_address, parse_host_port
    from distributed.comm.registry import backends

    try:
        scheme, location = parse_address(address)
        if scheme not in backends:
            raise ValueError(f"unknown scheme {scheme!r}; known: {', '.join(sorted(backends))}")
        host, port = parse_host_port(location) if scheme in ("tcp", "tls") else (None, None)
    except (ValueError, TypeError) as exc:
        raise SweepError(f"--scheduler {address!r}: not a scheduler address ({one_line(exc)}); "
                         f"e.g. tcp://HOST:8786") from None
    if host is None:
        return
    try:
        with socket.create_connection((host, port), timeout=CONNECT_TIMEOUT):
            pass
    except OSError as exc:
        raise SchedulerError(f"cannot reach the Dask scheduler at {address} "
                             f"({describe(exc)})") from None


def _finished(out: Path, rows: list[SweepRow]) -> list[dict]:
    """Rows of ``out/results.csv`` that need not run again (same inputs, a final status)."""
    path = out / "results.csv"
    if not path.exists():
        return []
    by_name = {r.name: r for r in rows}
    keep = []
    for rec in read_results(path):
        row = by_name.get(rec.get("name"))
        if row is None or rec.get("status") in UNFINISHED:
            continue
        given = {k: v for k, v in rec.items() if v and "." in k and not k.startswith(MEASURED)
                 and k not in RESULT_COLUMNS}
        if given != row.keys:
            raise SweepError(f"--resume: run {row.name!r} finished with {given}, but the sweep now "
                             f"gives {row.keys}; use a new --out for a different sweep")
        keep.append(rec)
    return keep


def run_sweep(case_path, rows: list[SweepRow], out, *, overrides: list[str] | None = None,
              scheduler: str | None = None, workers: int | None = None, resume: bool = False,
              quiet: bool = False, dashboard: bool = False) -> list[dict]:
    """Run ``rows`` of ``case_path`` into ``out``; return the results.csv records of this call.

    ``overrides`` (``--set`` items) apply to every row, before the row's own keys. One sweep
    at a time writes into ``out`` (:mod:`drape.run.lock`); nothing is written before the cluster
    answers.
    """
    out = Path(out).resolve()
    case_path = str(Path(case_path).resolve())
    out.mkdir(parents=True, exist_ok=True)
    with folder_lock(out):
        keep = _finished(out, rows) if resume else []
        if not resume and (out / "results.csv").exists():
            raise SweepError(f"{out / 'results.csv'} exists: continue it with --resume, or use a "
                             f"new --out")
        client, cluster = _client(scheduler, workers, dashboard)
        try:
            if dashboard and cluster is not None and not quiet:
                print(f"dashboard: {cluster.dashboard_link}", file=sys.stderr)
            _write_definition(out, case_path, rows, overrides or [])
            return _submit(client, case_path, rows, out, list(overrides or []), keep, resume, quiet)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()


def _submit(client, case_path: str, rows: list[SweepRow], out: Path, overrides: list[str],
            keep: list[dict], resume: bool, quiet: bool) -> list[dict]:
    """Run the rows not in ``keep`` on ``client``, adding each to results.csv as it finishes."""
    from distributed import as_completed
    from tqdm import tqdm

    done = {rec["name"] for rec in keep}
    todo = [r for r in rows if r.name not in done]
    results = _Results(out / "results.csv", rows, keep)
    records = []
    bar = tqdm(total=len(rows), initial=len(done), disable=quiet, unit="run", desc="runs",
               file=sys.stderr)
    futures = {}
    try:
        tag = uuid.uuid4().hex[:8]
        for row in todo:
            fut = client.submit(run_row, case_path, overrides + row.overrides(),
                                str(out / "runs" / row.name), resume,
                                key=f"drape-{row.name}-{tag}", pure=False)
            futures[fut] = row
        for fut in as_completed(list(futures)):
            row = futures[fut]
            try:
                result = fut.result()
            except Exception as exc:  # the worker died under it, or it was cancelled
                result = {"status": "lost", "reason": _one_line(exc)}
            result["run_dir"] = f"runs/{row.name}"   # relative: the sweep folder may move
            records.append(results.add(row, result))
            bar.set_postfix_str(f"{row.name}: {result['status']}", refresh=False)
            bar.update(1)
    finally:
        if futures:       # first of all: no row may start once the sweep is stopped
            client.cancel(list(futures), force=True)
        bar.close()
        results.close()
    return records


def _write_definition(out: Path, case_path: str, rows: list[SweepRow], overrides: list[str]):
    data = {"case": case_path, "set": overrides,
            "rows": [{"name": r.name, "keys": r.keys, "measured": r.measured, "group": r.group}
                     for r in rows]}
    atomic_write_text(out / "sweep.json", json.dumps(data, indent=1))


def _read_definition(out: Path):
    path = out / "sweep.json"
    if not path.exists():
        raise SweepError(f"--resume: {path} does not exist; give the case and --table or --grid")
    data = json.loads(path.read_text())
    rows = [SweepRow(r["name"], r["keys"], r["measured"], r.get("group", "")) for r in data["rows"]]
    return data["case"], rows, data["set"]
