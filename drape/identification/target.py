"""What an identification matches: the descriptors of a fabric's scanned drapes and their scatter.

A scan and a simulated drape are read through the same Cusick analysis
(:mod:`drape.analyses.scan_measure`), so both give the drape coefficient, the node count and the
outline's harmonic amplitudes ``a_0 .. a_20`` (:mod:`drape.analyses.outline`, independent of where
the folds sit round the disc). A :class:`Drapes` holds those of several drapes (the scans of one
fabric, or one parameter point's seeds) and their mean and scatter between specimens.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from drape.analyses.scan_measure import measure_scan

__all__ = ["Drape", "Drapes", "drape_of", "scan_drapes"]


@dataclass(frozen=True)
class Drape:
    """The descriptors of one drape: DC (%), node count, harmonic amplitudes (m)."""

    name: str
    dc: float
    nodes: int
    harmonics: tuple

    def to_json(self) -> dict:
        return {"name": self.name, "DC_percent": self.dc, "nodes": self.nodes,
                "outline_harmonics_m": list(self.harmonics)}

    @classmethod
    def from_json(cls, data: dict) -> "Drape":
        return cls(data["name"], float(data["DC_percent"]), int(data["nodes"]),
                   tuple(float(a) for a in data["outline_harmonics_m"]))


def drape_of(name: str, summary: dict) -> Drape:
    """A :class:`Drape` from a Cusick analysis summary (a run's ``summary["analysis"]`` or a
    scan's :meth:`drape.analyses.scan_measure.Measurement.descriptors`)."""
    return Drape(name, float(summary["drape_coefficient_percent"]), int(summary["n_nodes"]),
                 tuple(float(a) for a in summary["outline_harmonics_m"]))


@dataclass(frozen=True)
class Drapes:
    """Several drapes of one fabric (or one parameter point) and their statistics."""

    drapes: tuple = field(default_factory=tuple)

    def __len__(self) -> int:
        return len(self.drapes)

    @property
    def dc(self) -> np.ndarray:
        return np.array([d.dc for d in self.drapes])

    @property
    def nodes(self) -> np.ndarray:
        return np.array([d.nodes for d in self.drapes])

    @property
    def harmonics(self) -> np.ndarray:
        """(n_drapes, 21) amplitudes in metres."""
        return np.array([d.harmonics for d in self.drapes])

    def dc_std(self) -> float:
        """Sample standard deviation of DC between drapes (0 for one drape)."""
        return float(np.std(self.dc, ddof=1)) if len(self) > 1 else 0.0

    def nodes_std(self) -> float:
        return float(np.std(self.nodes, ddof=1)) if len(self) > 1 else 0.0

    def nodes_mode(self) -> int:
        """Most frequent node count; among tied ones the nearest the median, then the smaller.

        >>> Drapes(tuple(Drape("d", 50.0, n, ()) for n in (5, 6, 6, 7))).nodes_mode()
        6
        """
        counts = Counter(self.nodes.tolist())
        middle = float(np.median(self.nodes))
        return int(min(counts, key=lambda k: (-counts[k], abs(k - middle), k)))

    def summary(self) -> dict:
        """JSON-ready: count, DC mean and sd, node histogram, mode, mean amplitudes (mm)."""
        counts = Counter(self.nodes.tolist())
        return {"drapes": len(self), "DC_mean_percent": float(self.dc.mean()),
                "DC_std_percent": self.dc_std(), "nodes_mean": float(self.nodes.mean()),
                "nodes_mode": self.nodes_mode(),
                "nodes_histogram": {str(k): counts[k] for k in sorted(counts)},
                "harmonics_mean_mm": [1e3 * float(a) for a in self.harmonics.mean(axis=0)]}


def scan_drapes(paths, names=None, **measure_kw) -> tuple[Drapes, list]:
    """Read scan files (any mesh meshio reads) into :class:`Drapes`; also return the
    :class:`drape.analyses.scan_measure.Measurement` of each (for the report's outlines).

    Raises
    ------
    drape.analyses.scan.ScanError
        One line naming the scan that cannot be read as a Cusick drape.
    """
    names = names or [None] * len(paths)
    measured = [measure_scan(p, name=n, **measure_kw) for p, n in zip(paths, names)]
    drapes = tuple(drape_of(m.name, m.result.summary()) for m in measured)
    return Drapes(drapes), measured
