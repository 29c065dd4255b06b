"""Sweeps of small cantilever runs on Dask: run tables, grids, failures, resume, clusters."""
from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from drape.run import runner
from drape.batch import rows as sweep_rows
from drape.batch import sweep
from drape.cli import sweep as sweep_cli
from drape.case.case import load_case

ROOT = Path(__file__).resolve().parents[3]
CANTILEVER = ROOT / "cases" / "cantilever.toml"
#: A tiny cantilever: 4 triangles, a tenth of a second of the gravity ramp.
TINY = ["mesh.nx=2", "mesh.ny=1", "solver.t_end=0.1"]


def write_table(path: Path, text: str) -> Path:
    path.write_text(text)
    return path


def direct_run(tmp_path: Path, overrides: list[str], name: str) -> dict:
    """The same run through drape.run.runner directly (the reference for a sweep row)."""
    case = load_case(CANTILEVER, TINY + overrides)
    return runner.run_case(case, tmp_path / name, quiet=True)


def env_with_worktree() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return env


# --------------------------------------------------------------------------- rows
def test_table_columns_must_be_case_keys_or_measurements(tmp_path):
    bad = write_table(tmp_path / "t.csv", "name,bending_scale\na,2\n")
    with pytest.raises(sweep_rows.SweepError, match="column 'bending_scale'"):
        sweep_rows.read_table(bad)
    twice = write_table(tmp_path / "u.csv", "name,mesh.nx\na,2\na,3\n")
    with pytest.raises(sweep_rows.SweepError, match="'a' appears twice"):
        sweep_rows.read_table(twice)
    slash = write_table(tmp_path / "v.csv", "name,mesh.nx\n../x,2\n")
    with pytest.raises(sweep_rows.SweepError, match="names the run's folder"):
        sweep_rows.read_table(slash)
    ragged = write_table(tmp_path / "w.csv", "name,mesh.nx\na,2,3\n")
    with pytest.raises(sweep_rows.SweepError, match="row 1: 3 cells for 2 columns"):
        sweep_rows.read_table(ragged)


def test_unnamed_table_rows_are_numbered_and_blank_cells_keep_the_base(tmp_path):
    table = write_table(tmp_path / "t.csv", "mesh.nx,mesh.ny,measured.DC\n2,,40\n\n3,1,\n")
    rows = sweep_rows.read_table(table)
    assert [r.name for r in rows] == ["run000", "run001"]
    assert rows[0].keys == {"mesh.nx": "2"} and rows[0].measured == {"measured.DC": "40"}
    assert rows[1].overrides() == ["mesh.nx=3", "mesh.ny=1"]


def test_grid_is_the_product_of_the_value_lists():
    rows = sweep_rows.grid_rows(["mesh.nx=2,3,4", "material.bending_scale=1, 2"])
    assert len(rows) == 6
    assert {(r.keys["mesh.nx"], r.keys["material.bending_scale"]) for r in rows} == {
        (nx, s) for nx in ("2", "3", "4") for s in ("1", "2")}
    with pytest.raises(sweep_rows.SweepError, match="dotted case KEY"):
        sweep_rows.grid_rows(["nx=2,3"])
    with pytest.raises(sweep_rows.SweepError, match="empty value"):
        sweep_rows.grid_rows(["mesh.nx=2,,3"])


# --------------------------------------------------------------------------- LocalCluster
@pytest.mark.slow
def test_four_row_sweep_with_an_invalid_row_on_a_local_cluster(tmp_path):
    table = write_table(tmp_path / "catalogue.csv",
                        "name,material.bending_scale,measured.DC\n"
                        "limp,0.5,12.5\nbase,1,\nnegative,-1,\nstiff,2,31\n")
    out = tmp_path / "sweep"
    code = sweep_cli.main([str(CANTILEVER), "--table", str(table), "--out", str(out),
                       "--workers", "2", "--quiet", *sum((["--set", o] for o in TINY), [])])
    assert code == 0

    records = {r["name"]: r for r in sweep_rows.read_results(out / "results.csv")}
    assert sorted(records) == ["base", "limp", "negative", "stiff"]
    assert records["negative"]["status"] == "invalid"
    assert records["negative"]["reason"] == "material.bending_scale = -1: must be > 0.0"
    assert not (out / "runs" / "negative" / "summary.json").exists()
    for name in ("limp", "base", "stiff"):
        rec = records[name]
        assert rec["status"] == "completed" and rec["reason"] == ""
        summary = json.loads((out / rec["run_dir"] / "summary.json").read_text())
        assert summary["status"] == "completed" and summary["t_final"] == pytest.approx(0.1)
        assert (out / rec["run_dir"] / rec["pvd"]).exists()
    assert records["limp"]["measured.DC"] == "12.5" and records["base"]["measured.DC"] == ""

    # each row is the ordinary run of its overrides
    reference = direct_run(tmp_path, ["material.bending_scale=2"], "stiff")
    stiff = json.loads((out / "runs" / "stiff" / "summary.json").read_text())
    assert stiff["final"]["tip_uz"] == pytest.approx(reference["final"]["tip_uz"], rel=1e-12)
    base = json.loads((out / "runs" / "base" / "summary.json").read_text())
    assert abs(base["final"]["tip_uz"]) > 1.5 * abs(stiff["final"]["tip_uz"])
    # B scales with the moments; the bending length (B/W)^(1/3) with its cube root
    b = {n: float(records[n]["B_warp_Nm"]) for n in ("limp", "base", "stiff")}
    assert b["stiff"] / b["base"] == pytest.approx(2.0, rel=1e-9)
    assert b["limp"] / b["base"] == pytest.approx(0.5, rel=1e-9)
    c = {n: float(records[n]["bending_length_m"]) for n in ("base", "stiff")}
    assert c["stiff"] / c["base"] == pytest.approx(2.0 ** (1 / 3), rel=1e-9)


def test_an_existing_results_file_needs_resume(tmp_path):
    out = tmp_path / "sweep"
    out.mkdir()
    (out / "results.csv").write_text("name,status\n")
    rows = sweep_rows.grid_rows(["mesh.nx=2"])
    with pytest.raises(sweep_rows.SweepError, match="--resume"):
        sweep.run_sweep(CANTILEVER, rows, out)


# --------------------------------------------------------------------------- real cluster
def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for_port(port: int, proc: subprocess.Popen, timeout: float = 60.0) -> None:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise RuntimeError(f"{proc.args} exited with {proc.returncode}")
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.2)
    raise TimeoutError(f"nothing listens on 127.0.0.1:{port}")


def stop(proc: subprocess.Popen) -> int:
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
    return proc.returncode


def external_worker(address: str) -> str:
    from distributed import Client

    with Client(address, timeout=60) as client:
        workers = list(client.scheduler_info()["workers"])
    assert len(workers) == 1
    return workers[0]


@pytest.fixture
def dask_cluster(tmp_path):
    """A `dask scheduler` and one single-threaded `dask worker`, separate processes on 127.0.0.1."""
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    bindir = Path(sys.executable).parent
    env = env_with_worktree()
    log = open(tmp_path / "cluster.log", "w")
    scheduler = subprocess.Popen([str(bindir / "dask"), "scheduler", "--host", "127.0.0.1",
                                  "--port", str(port), "--no-dashboard"],
                                 cwd=ROOT, env=env, stdout=log, stderr=subprocess.STDOUT)
    worker = None
    try:
        wait_for_port(port, scheduler)
        worker = subprocess.Popen([str(bindir / "dask"), "worker", address, "--host", "127.0.0.1",
                                   "--nworkers", "1", "--nthreads", "1", "--no-dashboard",
                                   "--name", "external-worker"],
                                  cwd=ROOT, env=env, stdout=log, stderr=subprocess.STDOUT)
        from distributed import Client

        with Client(address, timeout=60) as client:
            client.wait_for_workers(1, timeout=60)
        yield address
    finally:
        codes = [stop(p) for p in (worker, scheduler) if p is not None]
        log.close()
    assert worker is not None and worker.poll() is not None and scheduler.poll() is not None, codes


@pytest.mark.slow
def test_two_row_sweep_through_an_existing_scheduler(tmp_path, dask_cluster, monkeypatch):
    import distributed

    def no_local_cluster(*args, **kwargs):
        raise AssertionError("a LocalCluster was started although --scheduler was given")

    monkeypatch.setattr(distributed, "LocalCluster", no_local_cluster)
    out = tmp_path / "sweep"
    code = sweep_cli.main([str(CANTILEVER), "--grid", "material.bending_scale=1,2", "--out", str(out),
                       "--scheduler", dask_cluster, "--quiet",
                       *sum((["--set", o] for o in TINY), [])])
    assert code == 0
    records = sweep_rows.read_results(out / "results.csv")
    assert [r["status"] for r in records] == ["completed", "completed"]
    tips = {r["material.bending_scale"]: json.loads(
        (out / r["run_dir"] / "summary.json").read_text())["final"]["tip_uz"] for r in records}
    reference = direct_run(tmp_path, ["material.bending_scale=2"], "ref")
    assert tips["2"] == pytest.approx(reference["final"]["tip_uz"], rel=1e-12)

    assert {r["worker"] for r in records} == {external_worker(dask_cluster)}


@pytest.mark.slow
def test_the_dask_environment_variable_names_the_scheduler(tmp_path, dask_cluster):
    out = tmp_path / "sweep"
    env = env_with_worktree()
    env["DASK_SCHEDULER_ADDRESS"] = dask_cluster
    proc = subprocess.run([sys.executable, "-m", "drape.sweep", str(CANTILEVER), "--grid",
                           "mesh.nx=2", "--out", str(out), "--quiet",
                           *sum((["--set", o] for o in TINY), [])],
                          cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    records = sweep_rows.read_results(out / "results.csv")
    assert [r["status"] for r in records] == ["completed"]
    assert records[0]["worker"] == external_worker(dask_cluster)


# --------------------------------------------------------------------------- SIGTERM + resume
@pytest.mark.slow
def test_a_terminated_sweep_resumes_with_only_the_missing_rows(
        tmp_path, terminate_after_first_row):
    out = tmp_path / "sweep"
    longer = ["mesh.nx=2", "mesh.ny=1", "solver.t_end=0.6"]
    cmd = [sys.executable, "-m", "drape.sweep", str(CANTILEVER), "--grid",
           "material.bending_scale=1,1.5,2,3", "--out", str(out), "--workers", "1", "--quiet",
           *sum((["--set", o] for o in longer), [])]
    results = out / "results.csv"
    code, err = terminate_after_first_row(cmd, results, ROOT, env_with_worktree())
    assert code == 143, err
    assert "terminated" in err
    first = sweep_rows.read_results(results)
    assert 1 <= len(first) < 4
    assert all(r["status"] == "completed" for r in first)
    kept = {r["name"]: (out / r["run_dir"] / "summary.json").stat().st_mtime_ns for r in first}

    resumed = subprocess.run([sys.executable, "-m", "drape.sweep", "--resume", "--out", str(out),
                              "--workers", "1"], cwd=ROOT, env=env_with_worktree(),
                             capture_output=True, text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    ran = [line.split(":")[0] for line in resumed.stdout.splitlines() if ": " in line]
    assert sorted(ran) == sorted({"run000", "run001", "run002", "run003"} - set(kept))
    final = sweep_rows.read_results(results)
    assert sorted(r["name"] for r in final) == ["run000", "run001", "run002", "run003"]
    assert all(r["status"] == "completed" for r in final)
    assert final[:len(first)] == first
    for name, mtime in kept.items():           # the finished runs were not run again
        assert (out / "runs" / name / "summary.json").stat().st_mtime_ns == mtime
