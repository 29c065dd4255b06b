"""Fixtures of the ``drape identify`` option tests: an identification that starts no forward
run (a stand-in cluster, and the search interrupted as Ctrl-C interrupts it, once the
definition is saved) and a synthetic scan to identify from."""
from __future__ import annotations

import pytest

from drape.identification import identify as identify_module


class StandInClient:
    """What the identification asks of a Dask client before its search runs."""

    def scheduler_info(self):
        return {"workers": {}}

    def close(self):
        pass


def _interrupted(*args, **kwargs):
    raise KeyboardInterrupt


@pytest.fixture
def no_runs(monkeypatch):
    """No cluster and no forward run: the search is interrupted as soon as it starts."""
    monkeypatch.setattr(identify_module, "open_client", lambda *a, **k: (StandInClient(), None))
    monkeypatch.setattr(identify_module, "run_search", _interrupted)


@pytest.fixture
def scan(tmp_path, drape_surface):
    """A synthetic five-fold drape written as a PLY scan."""
    return drape_surface(n_folds=5, n_sectors=120, n_rings=3).write(tmp_path / "scan.ply")
