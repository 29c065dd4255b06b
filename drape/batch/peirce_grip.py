"""How firmly does contact grip the strip at the Peirce platform's edge? A study at rest.

The platform and the ruler of ``cases/peirce_platform.toml`` are fixed with their front edges at
an edge (no motion: :func:`resting_case`), the strip settles under its weight, and its chord
angle at rest (:func:`chord_at_rest`) is compared with that of the clamped strip of the same
overhang (``cases/cantilever.toml`` with its length set to the overhang). Both strips are
elastic (no friction moment, no viscosity: :data:`ELASTIC`), so the difference is the grip's
alone: a clamp turns the strip by nothing at the edge, the barrier's grip by the couple it
builds over a zone behind the edge. The variants (:data:`VARIANTS`) change the barrier
stiffness, the barrier layer's width, the cells and the contact points inside them
(``contact.subdivision``); :func:`grip_study` runs them.
"""
from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import tomli_w
from skfem import MeshTri

from constitutive.bundled import cases_dir
from drape.analyses.platform_reading import reading
from drape.case.case import dump_case, load_case
from drape.run.runner import run_case

__all__ = ["ELASTIC", "VARIANTS", "resting_case", "variant_overrides", "chord_at_rest", "grip_study",
           "grip_table"]

#: Both strips without the law's friction moment and viscosity: the supports compared alone.
ELASTIC = ["material.friction=false", "material.d=0"]
#: name: (cells along the strip, strip width, cells across, subdivision, barrier stiffness
#: [N/m³] or None for the case's own: one vertex's weight share at mid-layer, 2.43e6 with 0.8 mm
#: cells, barrier layer dhat [m] or None for the case's 10 µm)
VARIANTS = {
    "h0.8-n1": (28, "0.5cm", 2, 1, None, None),
    "h0.8-n1-k2.4e8": (28, "0.5cm", 2, 1, 2.4e8, None),
    "h0.4-n3-k2.4e8": (56, "0.2cm", 1, 3, 2.4e8, None),
    "h0.2-n1": (112, "0.1cm", 1, 1, None, None),
    "h0.2-n1-k2.4e7": (112, "0.1cm", 1, 1, 2.4e7, None),
    "h0.2-n1-k2.4e8": (112, "0.1cm", 1, 1, 2.4e8, None),
    "h0.2-n1-d2um": (112, "0.1cm", 1, 1, None, 2e-6),
    "h0.2-n1-d2um-k2.4e8": (112, "0.1cm", 1, 1, 2.4e8, 2e-6),
}
#: The ending statuses of a run that came to rest.
_FINISHED = ("completed", "settled")


def resting_case(edge: float, out, dhat: float | None = None,
                 base=cases_dir("peirce_platform.toml")) -> tuple[Path, float]:
    """The platform case with its bodies fixed, their front edges at ``edge``, as a case file.

    Parameters
    ----------
    edge : float
        Where the front edges of platform and ruler stand [m, along the strip].
    out : path
        Folder the case file is written to (created).
    dhat : float, optional
        Another barrier layer [m]: platform and ruler move apart or together by the change, so
        the strip still starts in the middle of both layers.
    base : path
        The platform case.

    Returns
    -------
    (Path, float)
        The case file (at rest by 1.5 s, the [stop] rule off) and the strip's overhang [m].
    """
    data = tomllib.loads(dump_case(load_case(base)))
    shift = 0.0 if dhat is None else 0.5 * (dhat - data["contact"]["dhat"])
    for body in data["contact"]["body"]:
        body["centre"][0] += edge - (body["centre"][0] + 0.5 * body["size"][0])
        # the platform lies below the strip, the ruler above it
        body["centre"][2] += float(np.sign(body["centre"][2])) * shift
        body.pop("path", None)
    if dhat is not None:
        data["contact"]["dhat"] = dhat
    data["solver"]["t_end"] = 1.5
    data["case"]["name"] = "peirce_platform_at_rest"
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"peirce_platform_at_rest{'' if dhat is None else f'_dhat{dhat:g}'}.toml"
    path.write_text(tomli_w.dumps(data))
    return path, data["mesh"]["length"] - edge


def variant_overrides(name: str) -> list[str]:
    """``--set`` items of the variant ``name`` (:data:`VARIANTS`), the elastic strip's included;
    its barrier layer is the resting case's (:func:`resting_case`)."""
    nx, width, ny, n, kappa, _ = VARIANTS[name]
    items = ELASTIC + [f"mesh.nx={nx}", f"mesh.width={width}", f"mesh.ny={ny}", f"contact.subdivision={n}"]
    return items + ([] if kappa is None else [f"contact.barrier_stiffness={kappa:g}"])


def chord_at_rest(run_dir, edge: float) -> float:
    """Chord angle [deg] from the strip's point above ``edge`` to its tip at the run's last step."""
    import meshio

    mesh = meshio.read(sorted(Path(run_dir).glob("*.vtu"))[-1])
    strip = MeshTri(np.ascontiguousarray(mesh.points[:, :2].T),
                    np.ascontiguousarray(mesh.cells_dict["triangle"].T))
    return reading(strip, mesh.point_data["displacement"], edge)["chord_angle"]


def _run(path, out: Path, overrides, quiet: bool) -> dict:
    """Run the case file ``path`` into ``out``; its summary, or RuntimeError if it did not finish."""
    summary = run_case(load_case(path, overrides), out, quiet=quiet, source=f"from {path}")
    if summary["status"] not in _FINISHED:
        raise RuntimeError(f"{path}: the run ended {summary['status']} ({summary['reason']})")
    return summary


def grip_study(edge: float, out, names=None, quiet: bool = False) -> tuple[float, float, list]:
    """The clamped strip and the variants at rest, each run into a folder of ``out``.

    Parameters
    ----------
    edge : float
        Front edge of platform and ruler [m].
    out : path
        The study's folder: ``clamped/`` and one folder per variant.
    names : list of str, optional
        Only these variants (default: every one of :data:`VARIANTS`).
    quiet : bool
        No progress bars.

    Returns
    -------
    (float, float, list of (str, float))
        The overhang [m], the clamped strip's chord angle [deg], and each variant's chord angle
        at rest [deg].
    """
    out = Path(out)
    _, overhang = resting_case(edge, out)
    clamped = _run(cases_dir("cantilever.toml"), out / "clamped", ELASTIC + [f"mesh.length={overhang!r}"],
                   quiet)["analysis"]["chord_angle_deg"]
    rows = []
    for name in names or VARIANTS:
        case, _ = resting_case(edge, out, VARIANTS[name][5])
        _run(case, out / name, variant_overrides(name), quiet)
        rows.append((name, chord_at_rest(out / name, edge)))
    return overhang, clamped, rows


def grip_table(overhang: float, clamped: float, rows) -> str:
    """The :func:`grip_study` as text: each variant's chord angle and its excess over the clamp's."""
    lines = [f"overhang {100 * overhang:.2f} cm; clamped strip at rest: chord angle {clamped:.3f}°",
             f"{'variant':16s} {'chord angle':>12s} {'excess':>8s}"]
    return "\n".join(lines + [f"{name:16s} {chord:11.3f}° {chord - clamped:7.3f}°" for name, chord in rows])
