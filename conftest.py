"""Headless plotting also for the doctests collected from the packages; a loader for the
scripts of ``benchmarks/``; the overrides that shrink a Cusick case to a few seconds."""
import importlib.util
import os
from pathlib import Path

import pytest

os.environ.setdefault("MPLBACKEND", "Agg")
os.environ.setdefault("PYVISTA_OFF_SCREEN", "true")


@pytest.fixture
def benchmark_script():
    """Load a script of ``benchmarks/`` as a module: ``benchmark_script("bench_sensitivity")``."""
    def load(name):
        path = Path(__file__).resolve().parent / "benchmarks" / f"{name}.py"
        spec = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module
    return load


#: ``--set`` overrides of a Cusick case for plumbing tests: 12 triangles, two 0.01 s steps.
TINY_CUSICK = ("mesh.n_radial=1", "mesh.n_circumferential=12", "solver.t_end=0.02", "solver.dt=0.01")


@pytest.fixture(scope="session")
def tiny_cusick():
    """The overrides :data:`TINY_CUSICK`, as a list: a Cusick case that runs in seconds (its
    figures mean nothing)."""
    return list(TINY_CUSICK)

