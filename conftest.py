"""Headless plotting also for the doctests collected from the packages; the overrides that
shrink a Cusick case to a few seconds; a sweep stopped by SIGTERM once its first row is in."""
import csv
import os
import signal
import subprocess
import sys
import time

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")


#: ``--set`` overrides of a Cusick case for plumbing tests: 12 triangles, two 0.01 s steps.
TINY_CUSICK = ("mesh.n_radial=1", "mesh.n_circumferential=12", "solver.t_end=0.02", "solver.dt=0.01")


@pytest.fixture(scope="session")
def tiny_cusick():
    """The overrides :data:`TINY_CUSICK`, as a list: a Cusick case that runs in seconds (its
    figures mean nothing)."""
    return list(TINY_CUSICK)



@pytest.fixture
def terminate_after_first_row():
    """``run(cmd, results, cwd, env) -> (exit code, stderr)``: start the sweep command ``cmd``
    and send it SIGTERM as soon as its ``results`` file holds a finished row."""
    def rows(path):
        with open(path, newline="") as fh:
            return len(list(csv.DictReader(fh)))

    def run(cmd, results, cwd, env):
        proc = subprocess.Popen(cmd, cwd=cwd, env=env, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        try:
            deadline = time.monotonic() + 300
            while time.monotonic() < deadline and proc.poll() is None:
                if results.exists() and rows(results) >= 1:
                    break
                time.sleep(0.02)
            assert proc.poll() is None, proc.communicate()
            proc.send_signal(signal.SIGTERM)
            _, err = proc.communicate(timeout=120)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
        return proc.returncode, err
    return run


@pytest.fixture
def mesh_meshio_exits_on(tmp_path, monkeypatch):
    """A mesh file ``bad.msh`` whose reading makes meshio print why and call ``sys.exit``, as
    some of its readers do."""
    import meshio

    def gives_up(path, *args, **kwargs):
        print(f"Error: Couldn't read file {path} as either of ansys, gmsh", file=sys.stderr)
        sys.exit(1)

    monkeypatch.setattr(meshio, "read", gives_up)
    mesh = tmp_path / "bad.msh"
    mesh.write_text("$MeshFormat\n")
    return mesh
