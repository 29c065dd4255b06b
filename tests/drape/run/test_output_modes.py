"""A run's files get the mode a plain ``open()`` gives under the process's umask, the atomically
written ones (VTU, PVD, summary.json, checkpoint.npz) as much as the appended history.csv."""
from __future__ import annotations

import os
import re
import stat
from contextlib import contextmanager
from pathlib import Path

import pytest

from drape.case.case import load_case
from drape.run.atomic import atomic_write, atomic_write_text
from drape.run.runner import run_case

ROOT = Path(__file__).resolve().parents[3]
CANTILEVER = ROOT / "cases" / "cantilever.toml"
#: Four triangles, two steps: every kind of file a run writes, in a second.
TINY = ["mesh.nx=2", "mesh.ny=1", "solver.t_end=0.02", "solver.dt=0.01"]


@contextmanager
def umask(mask: int):
    """The process's umask set to ``mask`` for the block, then restored."""
    old = os.umask(mask)
    try:
        yield
    finally:
        os.umask(old)


def mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


@pytest.mark.parametrize("mask, expected", [(0o022, 0o644), (0o077, 0o600), (0o027, 0o640)])
def test_a_runs_files_have_the_mode_of_a_plain_open(tmp_path, mask, expected):
    out = tmp_path / "run"
    with umask(mask):
        summary = run_case(load_case(CANTILEVER, TINY), out, quiet=True)
    assert summary["status"] == "completed"
    atomic = [out / summary["pvd"], out / "summary.json", out / "checkpoint.npz",
              *out.glob("*.vtu")]
    assert len(atomic) >= 5                    # the PVD, the summary, the checkpoint, 2+ VTU
    assert mode(out / "history.csv") == expected
    assert {p.name: mode(p) for p in atomic} == {p.name: expected for p in atomic}
    assert not [p.name for p in out.iterdir() if p.name.endswith(".tmp")]


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_atomic_write_gives_what_open_gives_and_replaces_a_stricter_file(tmp_path, mask):
    plain, written = tmp_path / "plain.txt", tmp_path / "written.txt"
    written.write_text("old")
    written.chmod(0o400)                        # a file's old mode is not what decides
    with umask(mask):
        plain.write_text("x")
        atomic_write_text(written, "new")
    assert mode(written) == mode(plain) == 0o666 & ~mask
    assert written.read_text() == "new"


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    path = tmp_path / "summary.json"
    path.write_text("old")

    def fails(tmp: Path):
        tmp.write_text("half")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError, match="disk full"):
        atomic_write(path, fails)
    assert path.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["summary.json"]


#: What writes a file atomically by itself instead of through drape.run.atomic.
_OWN_ATOMIC = re.compile(r"\bos\.replace\(|\bmkstemp\(|NamedTemporaryFile\(|\.replace\(path\)")


def test_every_atomic_writer_goes_through_the_shared_function():
    found = []
    for pkg in ("constitutive", "drape", "meshes"):
        for f in sorted((ROOT / pkg).rglob("*.py")):
            if f == ROOT / "drape" / "run" / "atomic.py":
                continue
            for n, line in enumerate(f.read_text().splitlines(), 1):
                code = line.strip()
                if code.startswith((">>>", "...")):     # doctests make their own files
                    continue
                if _OWN_ATOMIC.search(code):
                    found.append(f"{f.relative_to(ROOT)}:{n}: {code}")
    assert not found, "\n".join(found)
