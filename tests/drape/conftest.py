"""Synthetic Cusick drapes whose shadow is known without the code under test.

A skirt hangs from the disc's edge along straight radial generators to a hem
``r(phi) = r0 + A cos(n (phi - phase))``, each generator dropping so that it keeps the
specimen's overhang ``R - RD`` as its length; the disc top is flat at z = 0. Seen from above
the generators only move outwards, so the shadow is the region inside the hem, of area
``pi (r0^2 + A^2 / 2)``, and the drape coefficient follows from it.

Also an identification that starts no forward run (:func:`no_runs`), for the tests of
``drape identify``'s options, and such a drape written as a scan (:func:`scan`).
"""
from __future__ import annotations

from dataclasses import dataclass

import meshio
import numpy as np
import pytest

from drape.identification import identify as identify_module

R, RD = 0.15, 0.09      # 30 cm specimen on an 18 cm disc (m)


@dataclass
class SyntheticDrape:
    """A drape's vertices (m), triangles and the drape coefficient of its hem (percent)."""

    points: np.ndarray
    triangles: np.ndarray
    dc_percent: float
    centre: tuple

    def write(self, path, scale: float = 1.0):
        """Write it as a mesh file (32-bit connectivity: PLY has no 64-bit integers)."""
        with np.errstate(all="ignore"):     # STL's normals of a degenerate triangle
            meshio.write(path, meshio.Mesh(scale * self.points,
                                           [("triangle", self.triangles.astype(np.int32))]))
        return path


def _rings(n_rings: int, n_sectors: int, first: int = 0) -> np.ndarray:
    """Triangles between consecutive rings of ``n_sectors`` vertices, numbered from ``first``."""
    tri = []
    for i in range(n_rings - 1):
        for j in range(n_sectors):
            a, b = first + i * n_sectors + j, first + i * n_sectors + (j + 1) % n_sectors
            tri += [[a, b, b + n_sectors], [a, b + n_sectors, a + n_sectors]]
    return np.array(tri, dtype=np.int64).reshape(-1, 3)


def synthetic_drape(n_folds=7, amplitude=0.015, r0=0.125, phase=0.0, centre=(0.0, 0.0),
                    n_sectors=360, n_rings=7, with_top=True) -> SyntheticDrape:
    """A drape of ``n_folds`` folds (module docstring); ``with_top=False`` leaves the annulus
    alone, as a simulated run's mesh."""
    phi = np.arange(n_sectors) * 2 * np.pi / n_sectors
    hem = r0 + amplitude * np.cos(n_folds * (phi - phase))
    t = np.linspace(0.0, 1.0, n_rings)[:, None]
    r = RD + t * (hem - RD)
    z = -t * np.sqrt(np.maximum((R - RD) ** 2 - (hem - RD) ** 2, 0.0))
    pts = np.column_stack([(r * np.cos(phi)).ravel(), (r * np.sin(phi)).ravel(), z.ravel()])
    tri = _rings(n_rings, n_sectors)
    if with_top:    # two rings inside the disc, the skirt's first ring its edge, a centre vertex
        inner = np.array([RD / 3, 2 * RD / 3])[:, None]
        cap = np.column_stack([(inner * np.cos(phi)).ravel(), (inner * np.sin(phi)).ravel(),
                               np.zeros(2 * n_sectors)])
        k = len(pts)
        top = _rings(2, n_sectors, k)
        edge = [[k + n_sectors + j, k + n_sectors + (j + 1) % n_sectors, (j + 1) % n_sectors]
                for j in range(n_sectors)]
        edge += [[k + n_sectors + j, (j + 1) % n_sectors, j] for j in range(n_sectors)]
        fan = [[k + 2 * n_sectors, k + j, k + (j + 1) % n_sectors] for j in range(n_sectors)]
        pts = np.vstack([pts, cap, [[0.0, 0.0, 0.0]]])
        tri = np.vstack([tri, top, edge, fan])
    pts[:, :2] += centre
    area = np.pi * (r0**2 + amplitude**2 / 2)
    dc = 100 * (area - np.pi * RD**2) / (np.pi * (R**2 - RD**2))
    return SyntheticDrape(pts, tri, float(dc), tuple(centre))


@pytest.fixture
def drape_surface():
    """:func:`synthetic_drape`, for the tests that build their own."""
    return synthetic_drape


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
