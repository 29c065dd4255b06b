"""The runner's answers to what goes wrong: one line on stderr and an exit code of one meaning."""
from __future__ import annotations

import errno
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from drape.cli import common as cli
from drape.cli import run as run_cli
from drape.run import runner
from drape.run.checkpoint import CHECKPOINT
from drape.run.lock import folder_lock
from drape.run.termination import Terminated

ROOT = Path(__file__).resolve().parents[3]
CANTILEVER = ROOT / "cases" / "cantilever.toml"
#: A tiny cantilever: 4 triangles, two steps.
TINY = ["--set", "mesh.nx=2", "--set", "mesh.ny=1", "--set", "solver.t_end=0.02"]


def env_with_worktree() -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return env


def one_error(capsys) -> str:
    """The single line the tool wrote to stderr."""
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


@pytest.fixture(scope="module")
def finished(tmp_path_factory) -> Path:
    """A tiny cantilever run that completed."""
    out = tmp_path_factory.mktemp("finished")
    assert run_cli.main([str(CANTILEVER), "--out", str(out), "--quiet", *TINY]) == 0
    return out


def stopped_copy(finished: Path, tmp_path: Path) -> Path:
    """``finished`` as if it had been stopped after its last step."""
    import shutil

    out = tmp_path / "stopped"
    shutil.copytree(finished, out)
    summary = json.loads((out / "summary.json").read_text())
    summary["status"] = "terminated"
    (out / "summary.json").write_text(json.dumps(summary))
    return out


# --------------------------------------------------------------------------- one writer per folder
def test_a_second_run_into_a_folder_in_use_is_refused_and_mixes_nothing(tmp_path, capsys):
    out = tmp_path / "D"
    first = subprocess.Popen([sys.executable, "-m", "drape.run", str(CANTILEVER), "--out", str(out),
                              "--quiet", "--set", "mesh.nx=2", "--set", "mesh.ny=1",
                              "--set", "solver.t_end=0.4"],
                             cwd=ROOT, env=env_with_worktree(), stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 120
        while not (out / "history.csv").exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert first.poll() is None, first.communicate()
        code = run_cli.main([str(CANTILEVER), "--out", str(out), "--quiet", "--set",
                            "solver.t_end=0.1", *TINY[:4]])
        line = one_error(capsys)
        _, err = first.communicate(timeout=300)
    finally:
        if first.poll() is None:
            first.kill()
    assert code == cli.EXIT_IO == 4
    assert line.startswith(f"error: {out} is in use by another run")
    assert first.returncode == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["t_final"] == pytest.approx(0.4)
    assert "solver.t_end=0.4" in (out / "case.resolved.toml").read_text()
    assert "t_end = 0.4" in (out / "case.resolved.toml").read_text()


def test_a_resume_into_a_folder_in_use_is_refused(finished, tmp_path, capsys):
    out = stopped_copy(finished, tmp_path)
    with folder_lock(out):
        assert run_cli.main(["--resume", str(out), "--quiet"]) == 4
    assert "is in use by another run" in one_error(capsys)


def test_a_new_run_does_not_leave_an_earlier_runs_summary_behind(tmp_path, monkeypatch):
    out = tmp_path / "o"
    out.mkdir()
    (out / "summary.json").write_text(json.dumps({"case": "old", "status": "settled"}))

    def killed(case):
        raise RuntimeError("killed while building")

    monkeypatch.setattr(runner, "build", killed)
    assert run_cli.main([str(CANTILEVER), "--out", str(out), "--quiet", *TINY]) == 1
    assert not (out / "summary.json").exists()


# --------------------------------------------------------------------------- damaged checkpoints
@pytest.mark.parametrize("content", [b"", b"PK\x03\x04 truncated", "random"])
def test_resume_from_a_damaged_checkpoint_is_one_line(finished, tmp_path, capsys, content):
    out = stopped_copy(finished, tmp_path)
    data = (out / CHECKPOINT).read_bytes()
    if content == "random":
        content = np.random.default_rng(0).bytes(len(data))
    elif content:
        content = data[: len(data) // 2]
    (out / CHECKPOINT).write_bytes(content)
    assert run_cli.main(["--resume", str(out), "--quiet"]) == cli.EXIT_BAD_INPUT
    line = one_error(capsys)
    assert "is not a readable checkpoint" in line and "pickle" not in line


# --------------------------------------------------------------------------- output folders
def test_an_output_folder_under_a_file_is_an_io_error(tmp_path, capsys):
    (tmp_path / "file").write_text("x")
    code = run_cli.main([str(CANTILEVER), "--out", str(tmp_path / "file" / "o"), "--quiet", *TINY])
    assert code == cli.EXIT_IO
    assert one_error(capsys) == f"error: Not a directory: '{tmp_path / 'file' / 'o'}'"


def test_a_read_only_output_folder_is_an_io_error(tmp_path, capsys, monkeypatch):
    real_mkdir = Path.mkdir

    def read_only(self, *args, **kwargs):
        if self.is_relative_to(tmp_path / "ro"):
            raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(self))
        return real_mkdir(self, *args, **kwargs)

    monkeypatch.setattr(Path, "mkdir", read_only)
    code = run_cli.main([str(CANTILEVER), "--out", str(tmp_path / "ro" / "o"), "--quiet", *TINY])
    assert code == cli.EXIT_IO
    assert one_error(capsys) == f"error: Read-only file system: '{tmp_path / 'ro' / 'o'}'"


def test_a_full_disk_during_the_run_is_an_io_error_with_the_reason_on_disk(tmp_path, capsys,
                                                                            monkeypatch):
    import drape.run.checkpoint

    savez, calls = np.savez, []

    def full(*args, **kwargs):       # the disk fills up after the first step
        calls.append(1)
        if len(calls) > 1:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return savez(*args, **kwargs)

    monkeypatch.setattr(drape.run.checkpoint.np, "savez", full)
    out = tmp_path / "o"
    assert run_cli.main([str(CANTILEVER), "--out", str(out), "--quiet", *TINY]) == cli.EXIT_IO
    assert one_error(capsys) == "error: No space left on device"
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "error" and "No space left" in summary["reason"]


# --------------------------------------------------------------------------- stopped while building
@pytest.mark.parametrize("stop, code, status", [(KeyboardInterrupt, 130, "interrupted"),
                                                 (Terminated, 143, "terminated")])
def test_a_run_stopped_while_its_case_is_built_says_so_and_resumes(tmp_path, capsys, monkeypatch,
                                                                     stop, code, status):
    def stopped(case):
        raise stop()

    out = tmp_path / "o"
    with monkeypatch.context() as patch:
        patch.setattr(runner, "build", stopped)
        assert run_cli.main([str(CANTILEVER), "--out", str(out), "--quiet", *TINY]) == code
    assert f"{status} at t = 0 s" in one_error(capsys)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == status and "while the case was being built" in summary["reason"]
    assert run_cli.main(["--resume", str(out), "--quiet"]) == 0      # from the beginning
    assert json.loads((out / "summary.json").read_text())["status"] == "completed"
    assert "--set solver.t_end=0.02" in (out / "case.resolved.toml").read_text()


def test_ctrl_c_while_the_case_is_read_is_one_line(capsys, monkeypatch):
    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(run_cli, "load_case", interrupted)
    assert run_cli.main([str(CANTILEVER), "--check"]) == 130
    assert one_error(capsys) == "interrupted"


# --------------------------------------------------------------------------- bad input
def test_a_folder_given_as_the_case_is_bad_input(capsys):
    assert run_cli.main([str(ROOT / "cases"), "--check"]) == cli.EXIT_BAD_INPUT
    assert "is a folder, not a case file" in one_error(capsys)


def test_a_binary_case_file_is_bad_input_in_plain_words(tmp_path, capsys):
    case = tmp_path / "c.toml"
    case.write_bytes(bytes(range(256)))
    assert run_cli.main([str(case), "--check"]) == cli.EXIT_BAD_INPUT
    line = one_error(capsys)
    assert "not a text file" in line and "codec" not in line


@pytest.mark.parametrize("content", [None, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\nabc\n",
                                     bytes(range(256)) * 4])
def test_a_mesh_path_that_is_no_mesh_names_mesh_path(tmp_path, capsys, content):
    mesh = tmp_path / ("passwd" if content is None else "bad.msh")
    if content is None:
        mesh.write_text("root:x:0:0:root:/root:/bin/bash\n")
    elif isinstance(content, bytes):
        mesh.write_bytes(content)
    else:
        mesh.write_text(content)
    code = run_cli.main([str(CANTILEVER), "--check", "--set", "mesh={kind='file', path='%s'}" % mesh])
    assert code == cli.EXIT_BAD_INPUT
    line = one_error(capsys)
    assert f"mesh.path = '{mesh}': {mesh.name}: not a mesh meshio can read (" in line


def test_a_mesh_reader_that_exits_becomes_an_error_naming_the_file(
        tmp_path, mesh_meshio_exits_on):
    """Some of meshio's readers print why and call sys.exit: that must not end the process
    (or a Dask worker running the row)."""
    from meshes import MeshError, load_mesh
    mesh = mesh_meshio_exits_on
    with pytest.raises(MeshError, match=r"^bad.msh: not a mesh meshio can read \(Error: Couldn't "
                                        r"read file .* as either of ansys, gmsh\)$"):
        load_mesh(mesh)


def test_a_case_name_that_would_leave_the_output_folder_is_refused(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "keep.txt").write_text("mine")
    for name in ("..", ".", "a/b", ""):
        assert run_cli.main([str(CANTILEVER), "--quiet", "--set", f'case.name="{name}"',
                            *TINY]) == cli.EXIT_BAD_INPUT
        assert "case.name" in one_error(capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.txt"]


def test_an_infinite_length_names_the_case_key(capsys):
    assert run_cli.main([str(CANTILEVER), "--check", "--set", "mesh.length=inf"]) == 2
    line = one_error(capsys)
    assert "mesh.length = inf" in line and "'lx'" not in line


def test_an_absurd_mesh_is_refused_before_it_is_built(capsys):
    start = time.perf_counter()
    assert run_cli.main([str(CANTILEVER), "--check", "--set", "mesh.nx=100000000000"]) == 2
    assert "triangles asked for" in one_error(capsys)
    assert time.perf_counter() - start < 5


def test_an_unknown_option_is_one_line_and_bad_input(capsys):
    with pytest.raises(SystemExit) as stop:
        run_cli.main([str(CANTILEVER), "--chek"])
    assert stop.value.code == cli.EXIT_BAD_INPUT
    assert "unrecognized arguments: --chek" in one_error(capsys)


# --------------------------------------------------------------------------- what the user sees
def test_help_prints_the_exit_code_table(capsys):
    with pytest.raises(SystemExit):
        run_cli.main(["--help"])
    out = capsys.readouterr().out
    assert cli.EXIT_CODES in out
    for code in ("  2    bad input", "  3    the solver did not converge", "  4    I/O error",
                 "  130  interrupted", "  143  terminated"):
        assert code in out


def test_the_user_guide_has_the_exit_code_table():
    assert cli.EXIT_CODES in (ROOT / "docs" / "guide" / "run.md").read_text()


def test_a_cold_kernel_cache_is_announced(capsys, monkeypatch):
    import drape.fem.compiled

    monkeypatch.setattr(drape.fem.compiled, "cache_is_cold", lambda: True)
    assert run_cli.main([str(CANTILEVER), "--check", *TINY]) == 0
    assert capsys.readouterr().err.startswith("compiling the shell's kernels (first run only")
    assert run_cli.main([str(CANTILEVER), "--check", "--quiet", *TINY]) == 0
    assert capsys.readouterr().err == ""
    monkeypatch.setattr(drape.fem.compiled, "cache_is_cold", lambda: False)
    assert run_cli.main([str(CANTILEVER), "--check", *TINY]) == 0
    assert capsys.readouterr().err == ""


def test_a_signal_during_the_build_in_a_real_process_leaves_a_summary(tmp_path):
    """SIGTERM at once after start: whether it lands in the imports, the case or the build, the
    process ends 143 with one line; once the runner holds the folder, with a summary."""
    out = tmp_path / "o"
    proc = subprocess.Popen([sys.executable, "-m", "drape.run", str(CANTILEVER), "--out", str(out),
                             "--quiet", *TINY, "--set", "solver.t_end=1"], cwd=ROOT,
                            env=env_with_worktree(),
                            stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not (out / "case.resolved.toml").exists() and time.monotonic() < deadline:
        time.sleep(0.005)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 143, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert json.loads((out / "summary.json").read_text())["status"] == "terminated"
