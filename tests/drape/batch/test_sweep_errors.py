"""Sweeps that are stopped, misconfigured or fed bad rows: nothing lost, nothing mixed, one line."""
from __future__ import annotations

import json
import os
import runpy
import socket
import subprocess
import sys
import urllib.error
import urllib.request
from pathlib import Path

import pytest

from drape.batch import rows as sweep_rows
from drape.batch import sweep
from drape.cli import sweep as sweep_cli
from drape.run.lock import folder_lock

ROOT = Path(__file__).resolve().parents[3]
CANTILEVER = ROOT / "cases" / "cantilever.toml"
TINY = ["mesh.nx=2", "mesh.ny=1", "solver.t_end=0.1"]
#: What results.csv must give the same for a run, however often the sweep was stopped.
SAME = ("name", "material.bending_scale", "status", "reason", "DC_percent", "nodes",
        "settling_time_s", "t_final_s", "steps", "bending_length_m")


def env_with_worktree() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return env


def sets(overrides: list[str]) -> list[str]:
    return sum((["--set", o] for o in overrides), [])


def one_error(capsys) -> str:
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


# --------------------------------------------------------------------------- bad input, one line
@pytest.mark.filterwarnings("ignore:'drape.sweep' found in sys.modules:RuntimeWarning")
@pytest.mark.parametrize("seeds, why", [("-1", "--seeds = -1: must be >= 1"),
                                        ("2", "has no seeded [load.perturbation]")])
def test_seed_errors_are_one_line_under_python_m(tmp_path, capsys, monkeypatch, seeds, why):
    """Run as ``python -m drape.sweep`` (the module loaded a second time, as __main__)."""
    monkeypatch.setattr(sys, "argv", ["drape.sweep", str(CANTILEVER), "--seeds", seeds,
                                      "--out", str(tmp_path / "s")])
    with pytest.raises(SystemExit) as stop:
        runpy.run_module("drape.sweep", run_name="__main__", alter_sys=True)
    assert stop.value.code == 2
    assert why in one_error(capsys)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.parametrize("address, code, why", [
    ("foo", 2, "--scheduler 'foo': not a scheduler address"),
    ("bogus://x:1", 2, "not a scheduler address"),
    (None, 4, "cannot reach the Dask scheduler at tcp://127.0.0.1:"),
])
def test_a_scheduler_that_is_no_address_or_does_not_answer_leaves_nothing(tmp_path, capsys,
                                                                          address, code, why):
    address = address or f"tcp://127.0.0.1:{free_port()}"
    out = tmp_path / "s"
    assert sweep_cli.main([str(CANTILEVER), "--grid", "mesh.nx=2", "--out", str(out), "--quiet",
                       "--scheduler", address, *sets(TINY)]) == code
    assert why in one_error(capsys)
    assert not (out / "results.csv").exists() and not (out / "sweep.json").exists()


def test_a_sweep_into_a_folder_in_use_is_refused(tmp_path, capsys):
    out = tmp_path / "s"
    out.mkdir()
    with folder_lock(out):
        assert sweep_cli.main([str(CANTILEVER), "--grid", "mesh.nx=2", "--out", str(out),
                           "--quiet", *sets(TINY)]) == 4
    assert "is in use by another run or sweep" in one_error(capsys)
    assert not (out / "results.csv").exists()


def test_a_mesh_reader_that_exits_makes_the_row_invalid_not_the_worker_die(
        tmp_path, mesh_meshio_exits_on):
    mesh = mesh_meshio_exits_on
    result = sweep.run_row(str(CANTILEVER), [f"mesh={{kind='file', path='{mesh}'}}"],
                           str(tmp_path / "run"))
    assert result["status"] == "invalid"
    assert result["reason"].startswith(f"mesh.path = '{mesh}': bad.msh: not a mesh meshio can read")


# --------------------------------------------------------------------------- exposure
def status_page(cluster) -> int:
    try:
        return urllib.request.urlopen(cluster.dashboard_link, timeout=10).status
    except urllib.error.HTTPError as exc:
        return exc.code


def test_the_local_cluster_serves_no_dashboard_unless_asked_and_only_on_localhost():
    for asked, expected in ((False, 404), (True, 200)):
        client, cluster = sweep._client(None, 1, dashboard=asked)
        try:
            assert cluster.dashboard_link.startswith("http://127.0.0.1:")
            assert cluster.scheduler_address.startswith("tls://127.0.0.1:")
            assert status_page(cluster) == expected
        finally:
            client.close()
            cluster.close()


# --------------------------------------------------------------------------- resume
def test_a_finished_run_is_read_back_from_its_summary_not_run_again(tmp_path):
    run_dir = tmp_path / "run"
    first = sweep.run_row(str(CANTILEVER), TINY, str(run_dir))
    assert first["status"] == "completed"
    files = {p.name: p.stat().st_mtime_ns for p in run_dir.iterdir()}
    again = sweep.run_row(str(CANTILEVER), TINY, str(run_dir), resume=True)
    assert {p.name: p.stat().st_mtime_ns for p in run_dir.iterdir()} == files
    assert {k: v for k, v in again.items() if k not in ("worker", "wall_time_s")} == \
        {k: v for k, v in first.items() if k not in ("worker", "wall_time_s")}
    # a finished run of another case in the folder is not this row's: it runs
    other = sweep.run_row(str(CANTILEVER), TINY + ["material.bending_scale=2"], str(run_dir),
                          resume=True)
    assert other["status"] == "completed" and other["bending_length_m"] > first["bending_length_m"]
    assert "bending_scale = 2.0" in (run_dir / "case.resolved.toml").read_text()


def sweep_command(out: Path, *extra: str) -> list[str]:
    return [sys.executable, "-m", "drape.sweep", str(CANTILEVER), "--grid",
            "material.bending_scale=0.5,1,2", "--out", str(out), "--workers", "1", "--quiet",
            *extra]


@pytest.mark.slow
def test_a_terminated_sweep_resumes_to_the_results_of_an_uninterrupted_one(
        tmp_path, terminate_after_first_row):
    """The cantilever settles in each row (0.5: limp, 2: stiff); SIGTERM once one row is in,
    then --resume, gives results.csv row for row as a sweep that was never stopped."""
    reference = tmp_path / "uninterrupted"
    done = subprocess.run(sweep_command(reference), cwd=ROOT, env=env_with_worktree(),
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr

    out = tmp_path / "stopped"
    results = out / "results.csv"
    code, err = terminate_after_first_row(sweep_command(out), results, ROOT, env_with_worktree())
    assert code == 143, err
    assert len(sweep_rows.read_results(results)) < 3
    resumed = subprocess.run([sys.executable, "-m", "drape.sweep", "--resume", "--out", str(out),
                              "--workers", "1", "--quiet"], cwd=ROOT, env=env_with_worktree(),
                             capture_output=True, text=True, timeout=600)
    assert resumed.returncode == 0, resumed.stderr

    def table(folder: Path) -> list[dict]:
        rows = sorted(sweep_rows.read_results(folder / "results.csv"), key=lambda r: r["name"])
        return [{k: r[k] for k in SAME} for r in rows]

    expected = table(reference)
    assert [r["status"] for r in expected] == ["settled"] * 3
    assert table(out) == expected


# --------------------------------------------------------------------------- threads
def test_a_row_on_a_worker_whose_numba_threads_run_leaves_numba_able_to_compile(tmp_path):
    """A worker that has run a parallel kernel has launched numba's pool; changing
    NUMBA_NUM_THREADS after that makes numba's next compilation fail. A row caps the
    kernels' threads without touching it."""
    script = f"""
import os
os.environ.pop("NUMBA_NUM_THREADS", None)
import numba
from numba.np.ufunc import parallel
parallel._launch_threads()
from drape.batch import sweep
row = sweep.run_row({str(CANTILEVER)!r}, {TINY!r}, {str(tmp_path / 'run')!r})
assert row["status"] == "completed", row
numba.core.config.reload_config()        # what every compilation does first
from drape.fem import compiled, shell_kernels
shell_kernels.use_threads(10 ** 6)
assert compiled.thread_limit() == 1 and numba.get_num_threads() == 1
print("ok")
"""
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and done.stdout.strip().endswith("ok"), done.stderr[-2000:]
