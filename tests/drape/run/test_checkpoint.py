"""Runs that survive being killed: SIGTERM like Ctrl-C, a checkpoint per converged step, --resume."""
from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import meshio
import numpy as np
import pytest

from drape.cli import run as run_cli
from drape.run import runner
from drape.case.case import load_case
from drape.run.checkpoint import CHECKPOINT, read_checkpoint
from drape.run.output import read_history, read_pvd
from drape.run.termination import EXIT_TERMINATED

ROOT = Path(__file__).resolve().parents[3]
CANTILEVER = ROOT / "cases" / "cantilever.toml"
#: A small friction cantilever: gravity ramps on over 0.2 s, then 0.4 s under constant load.
#: Newton converges tightly, so the comparison sees what the checkpoint holds, not the
#: tolerance of the iterations (an iteration path resumed elsewhere ends elsewhere in it).
# atol: the round-off floor of R (~5e-15 N); settling_dt: 0.01 s steps throughout
SMALL = ["mesh.nx=3", "mesh.ny=1", "solver.t_end=0.6", "solver.atol=1e-14", "solver.rtol=1e-11",
         "solver.settling_dt=0.01"]
RTOL = 1e-10


def env_with_worktree() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return env


#: Once gravity is on, a settling phase whose step doubles every 4 steps from 0.01 to 0.08 s.
GROWING = SMALL + ["solver.settling_dt=0.08"]
#: A loose settling rule the short run meets from the end of the ramp (0.2 s) on: its static
#: out-of-balance is 0.70–0.86 of the weight there, so it settles after 30 steps, at 0.49 s.
LOOSE_RULE = SMALL + ["stop.out_of_balance=0.95", "stop.steps=30"]


def reference_run(tmp_path_factory, overrides: list[str]) -> Path:
    out = tmp_path_factory.mktemp("uninterrupted")
    summary = runner.run_case(load_case(CANTILEVER, overrides), out, quiet=True)
    assert summary["status"] == "completed"
    return out


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory) -> Path:
    return reference_run(tmp_path_factory, SMALL)


def start_run(out: Path, overrides: list[str] = SMALL) -> subprocess.Popen:
    cmd = [sys.executable, "-m", "drape.run", str(CANTILEVER), "--out", str(out), "--quiet",
           *sum((["--set", o] for o in overrides), [])]
    return subprocess.Popen(cmd, cwd=ROOT, env=env_with_worktree(), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def signal_after(proc: subprocess.Popen, out: Path, rows: int, signum) -> tuple[str, str]:
    """Send ``signum`` once history.csv has ``rows`` rows; return the process's output."""
    history = out / "history.csv"
    deadline = time.monotonic() + 300
    try:
        while time.monotonic() < deadline and proc.poll() is None:
            if history.exists() and len(history.read_text().splitlines()) > rows:
                break
            time.sleep(0.02)
        assert proc.poll() is None, proc.communicate()
        proc.send_signal(signum)
        return proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def resume(out: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "drape.run", "--resume", str(out), "--quiet"],
                          cwd=ROOT, env=env_with_worktree(), capture_output=True, text=True,
                          timeout=300)


def assert_same_final_state(out: Path, reference: Path) -> None:
    """Displacements, velocities and every law state agree to RTOL (of each array's largest
    entry). Accelerations agree to round-off magnified by Newmark's a = Δu / (β Δt²) + ...,
    i.e. by 1 / (β Δt²) = 4e4 here."""
    got, want = read_checkpoint(out), read_checkpoint(reference)
    assert got.state.t == pytest.approx(want.state.t, rel=1e-14)
    for name, rtol in (("u", RTOL), ("v", RTOL), ("a", 1e-7)):
        np.testing.assert_allclose(getattr(got.state, name), getattr(want.state, name),
                                   rtol=rtol, atol=rtol * np.abs(getattr(want.state, name)).max())
    assert sorted(got.model) == sorted(want.model)
    assert any(".friction." in k for k in want.model)   # friction states compared
    for key, value in want.model.items():
        np.testing.assert_allclose(got.model[key], value, rtol=RTOL,
                                   atol=RTOL * max(np.abs(value).max(initial=0.0), 1e-300),
                                   err_msg=key)


@pytest.mark.slow
def test_sigterm_leaves_a_valid_run_that_resumes_to_the_uninterrupted_state(tmp_path, uninterrupted):
    out = tmp_path / "run"
    proc = start_run(out)
    _, err = signal_after(proc, out, rows=25, signum=signal.SIGTERM)
    assert proc.returncode == EXIT_TERMINATED == 143, err
    assert "--resume" in err

    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "terminated" and summary["reason"] == "terminated by SIGTERM"
    stopped_at = summary["t_final"]
    assert 0.0 < stopped_at < 0.6
    listed = read_pvd(out / "cantilever.pvd")
    assert listed and listed[-1][0] == pytest.approx(stopped_at, rel=1e-12)
    for _, vtu in listed:                                   # every listed step is readable
        assert meshio.read(vtu).point_data["displacement"].shape[1] == 3
    assert read_checkpoint(out).state.t == pytest.approx(stopped_at, rel=1e-12)

    done = resume(out)
    assert done.returncode == 0, done.stderr
    final = json.loads((out / "summary.json").read_text())
    want = json.loads((uninterrupted / "summary.json").read_text())
    assert final["status"] == "completed" and final["steps"] == want["steps"]
    assert_same_final_state(out, uninterrupted)
    got_rows, want_rows = read_history(out / "history.csv"), read_history(uninterrupted / "history.csv")
    assert [r["step"] for r in got_rows] == [r["step"] for r in want_rows]
    np.testing.assert_allclose([r["tip_uz"] for r in got_rows], [r["tip_uz"] for r in want_rows],
                               rtol=RTOL)
    assert final["analysis"]["tip_drop_m"] == pytest.approx(want["analysis"]["tip_drop_m"], rel=RTOL)


@pytest.mark.slow
def test_a_run_stopped_in_its_settling_phase_resumes_with_the_same_growing_steps(
        tmp_path, tmp_path_factory):
    reference = reference_run(tmp_path_factory, GROWING)
    want_dt = [r["dt"] for r in read_history(reference / "history.csv")]
    assert max(want_dt) == pytest.approx(0.08) and len(set(want_dt)) > 3   # the step did grow
    out = tmp_path / "run"
    proc = start_run(out, GROWING)
    _, err = signal_after(proc, out, rows=27, signum=signal.SIGTERM)   # a few steps after 0.2 s
    assert proc.returncode == EXIT_TERMINATED, err
    stopped_at = json.loads((out / "summary.json").read_text())["t_final"]
    assert 0.2 < stopped_at < 0.6

    done = resume(out)
    assert done.returncode == 0, done.stderr
    got = read_history(out / "history.csv")
    assert [r["t"] for r in got] == pytest.approx([r["t"] for r in read_history(
        reference / "history.csv")], rel=1e-12)
    assert [r["dt"] for r in got] == pytest.approx(want_dt, rel=1e-12)
    assert_same_final_state(out, reference)


@pytest.mark.slow
def test_a_run_stopped_while_the_settling_rule_counts_resumes_with_its_count(tmp_path, tmp_path_factory):
    reference = tmp_path_factory.mktemp("settles")
    want = runner.run_case(load_case(CANTILEVER, LOOSE_RULE), reference, quiet=True)
    assert want["status"] == "settled" and want["t_final"] == pytest.approx(0.49, rel=1e-9)
    out = tmp_path / "run"
    proc = start_run(out, LOOSE_RULE)
    _, err = signal_after(proc, out, rows=27, signum=signal.SIGTERM)   # a few steps after 0.2 s
    assert proc.returncode == EXIT_TERMINATED, err
    counted = read_checkpoint(out).run["settling_count"]
    assert 0 < counted < 30                    # stopped while the rule was counting

    done = resume(out)
    assert done.returncode == 0, done.stderr
    got = json.loads((out / "summary.json").read_text())
    # a count restarted from 0 would settle `counted` steps later
    assert got["status"] == "settled" and got["steps"] == want["steps"]
    assert got["t_final"] == pytest.approx(want["t_final"], rel=1e-12) and got["reason"] == want["reason"]


@pytest.mark.slow
def test_resume_drops_output_written_after_the_checkpoint(tmp_path, uninterrupted):
    """A run killed hard may have written steps its checkpoint does not hold; they are redone."""
    killed = tmp_path / "killed"
    proc = start_run(killed)
    signal_after(proc, killed, rows=20, signum=signal.SIGKILL)
    assert proc.returncode == -signal.SIGKILL
    early = read_checkpoint(killed)
    assert 0.0 < early.state.t < 0.6

    # the finished run's folder with the early checkpoint: every step after it must be redone
    out = tmp_path / "run"
    shutil.copytree(uninterrupted, out)
    (out / "summary.json").unlink()
    shutil.copy(killed / CHECKPOINT, out / CHECKPOINT)
    (out / "case.resolved.toml").write_text((killed / "case.resolved.toml").read_text())
    stale = out / "cantilever_0012.vtu"
    stale.write_bytes(b"not a VTU file")                    # must be rewritten, not kept
    done = resume(out)
    assert done.returncode == 0, done.stderr
    assert_same_final_state(out, uninterrupted)
    assert [r["t"] for r in read_history(out / "history.csv")] == pytest.approx(
        [r["t"] for r in read_history(uninterrupted / "history.csv")], rel=1e-12)
    listed = read_pvd(out / "cantilever.pvd")
    assert [t for t, _ in listed] == pytest.approx(
        [t for t, _ in read_pvd(uninterrupted / "cantilever.pvd")], rel=1e-12)
    for _, vtu in listed:
        meshio.read(vtu)


def test_resume_without_a_checkpoint_says_so(tmp_path):
    done = resume(tmp_path)
    assert done.returncode == 2
    assert "no checkpoint" in done.stderr and len(done.stderr.splitlines()) == 1


def test_resume_of_a_completed_run_runs_nothing(tmp_path, uninterrupted):
    out = tmp_path / "done"
    shutil.copytree(uninterrupted, out)
    before = (out / "history.csv").stat().st_mtime_ns
    assert run_cli.main(["--resume", str(out), "--quiet"]) == 0
    assert (out / "history.csv").stat().st_mtime_ns == before
