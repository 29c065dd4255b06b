"""Headless plotting also for the doctests collected from the packages; a loader for the
scripts of ``benchmarks/``."""
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
