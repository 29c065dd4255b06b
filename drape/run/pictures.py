"""Pictures of a finished (or stopped) run (``python -m drape.inspect DIR``, :mod:`drape.cli.inspect`).

Writes, into the run directory unless ``--out`` says otherwise,

* ``<name>_<field>_<NNNN>.png``: the deformed fabric (reference mesh warped by ``displacement``)
  coloured by a point or cell field, rendered off-screen with pyvista;
* ``history.png``: energies, probe displacements and solver effort against time (matplotlib);
* ``kes_loop.png``: the moment–curvature loop when the history has ``kappa`` and ``moment``.

Examples
--------
>>> import tempfile, numpy as np
>>> from skfem import MeshTri
>>> from drape.run.output import OutputWriter
>>> with tempfile.TemporaryDirectory() as d:
...     w = OutputWriter(d, "demo", MeshTri())
...     _ = w.write_step(0.0, {"displacement": np.zeros((4, 3)), "curvature_xx": np.ones(2)})
...     w.append_history({"t": 0.0, "kinetic": 0.0, "strain": 0.0})
...     w.close()
...     fields, steps = available(d)
...     fields, steps
(['curvature_xx', 'displacement'], [0.0])
"""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from constitutive.units import to_kes
from drape.case.case import CaseError, load_case
from drape.case.contact_build import body_surface, half_space
from drape.contact import ContactInputError, RigidPath, shapes
from drape.contact.half_space import HalfSpace
from drape.run.output import read_pvd

__all__ = ["InspectError", "find_pvd", "available", "render_step", "contact_bodies", "plot_history",
           "plot_kes_loop"]


class InspectError(ValueError):
    """The directory does not hold what was asked for (no PVD, unknown field, step out of range)."""


def find_pvd(directory) -> Path:
    """The one ``.pvd`` collection in a run directory."""
    directory = Path(directory)
    if not directory.is_dir():
        raise InspectError(f"{directory} is not a directory")
    found = sorted(directory.glob("*.pvd"))
    if len(found) != 1:
        raise InspectError(
            f"{directory}: expected one .pvd file, found {len(found)}"
            + (f" ({', '.join(p.name for p in found)})" if found else "")
        )
    return found[0]


def _read(path):
    import pyvista

    return pyvista.read(str(path))


def available(directory) -> tuple[list[str], list[float]]:
    """Field names of the last output step and the output times of the run."""
    steps = read_pvd(find_pvd(directory))
    if not steps:
        raise InspectError(f"{directory}: the PVD lists no steps yet")
    grid = _read(steps[-1][1])
    names = sorted(set(grid.point_data.keys()) | set(grid.cell_data.keys()))
    return names, [t for t, _ in steps]


def _scalar(grid, field: str):
    """(values, preference) of ``field``: vectors are shown by magnitude."""
    if field in grid.point_data:
        values = np.asarray(grid.point_data[field])
        where = "point"
    elif field in grid.cell_data:
        values = np.asarray(grid.cell_data[field])
        where = "cell"
    else:
        names = sorted(set(grid.point_data.keys()) | set(grid.cell_data.keys()))
        raise InspectError(f"--field {field!r} is not in the output; available: {', '.join(names)}")
    if values.ndim == 2:
        values = np.linalg.norm(values, axis=1)
    return values, where


def default_field(names: list[str]) -> str:
    """The field shown when none is asked for (first bending curvature, else displacement)."""
    for name in ("curvature_xx", "moment_xx", "displacement"):
        if name in names:
            return name
    return names[0]


def contact_bodies(directory):
    """The run's rigid contact bodies (``[[contact.body]]`` of its ``case.resolved.toml``) as a
    function of time giving their surfaces where their paths put them; None without any.

    A half-space is drawn as a square of its plane, :data:`HALF_SPACE_DRAWN` times the
    ``extent`` the function is given (the fabric's size; default 1 m) on a side."""
    path = Path(directory) / "case.resolved.toml"
    if not path.is_file():
        return None
    try:
        case = load_case(path)
        if case.contact is None or not case.contact.body:
            return None
        placed = [(half_space(b) if b.shape == "half_space" else body_surface(b),
                   None if b.path is None else RigidPath(b.path.times, b.path.translations))
                  for b in case.contact.body]
    except (CaseError, ContactInputError, OSError):
        return None          # the picture goes without the bodies rather than not at all

    def at(t, extent=1.0):
        surfaces = [shapes.plane(s.point, s.normal, HALF_SPACE_DRAWN * extent, resolution=1)
                    if isinstance(s, HalfSpace) else s for s, _ in placed]
        return [s if p is None else s.placed(translation=p.offset(t)) for s, (_, p) in zip(surfaces, placed)]

    return at


#: A half-space is drawn as a square this many times the fabric's size on a side.
HALF_SPACE_DRAWN = 1.5


def render_step(directory, field: str | None = None, step: int = -1, out=None,
                window_size=(1200, 800), bodies=None, view: str = "isometric") -> Path:
    """PNG of output step ``step`` (index into the PVD, negative from the end) coloured by ``field``.

    ``bodies``, if given, is a function of time returning the rigid contact surfaces
    (:class:`drape.contact.surface.Surface`) where they stand then; they are drawn in grey.
    ``view``: "isometric" (lowered when there are bodies) or "xz" (from the side, along y).
    """
    import pyvista

    directory = Path(directory)
    pvd = find_pvd(directory)
    steps = read_pvd(pvd)
    if not steps:
        raise InspectError(f"{directory}: the PVD lists no steps yet")
    if not -len(steps) <= step < len(steps):
        raise InspectError(f"--step {step} is out of range: the run has {len(steps)} output steps "
                           f"(0..{len(steps) - 1}, or negative from the end)")
    index = step % len(steps)
    t, path = steps[index]
    grid = _read(path)
    names = sorted(set(grid.point_data.keys()) | set(grid.cell_data.keys()))
    field = field or default_field(names)
    values, where = _scalar(grid, field)
    shown = grid.warp_by_vector("displacement") if "displacement" in grid.point_data else grid
    raw = grid.point_data[field] if where == "point" else grid.cell_data[field]
    label = f"|{field}|" if np.ndim(raw) == 2 else field
    data = shown.point_data if where == "point" else shown.cell_data
    data["shown"] = values
    plotter = pyvista.Plotter(off_screen=True, window_size=list(window_size))
    plotter.add_mesh(shown, scalars="shown", preference=where, show_edges=True, cmap="viridis",
                     scalar_bar_args={"title": label})
    plotter.add_mesh(grid.extract_feature_edges(boundary_edges=True, feature_edges=False,
                                                manifold_edges=False),
                     color="grey", opacity=0.4, line_width=1)   # reference outline
    if view == "xz" and where == "point":    # a strip seen edge-on is a hairline: draw its edges thick
        plotter.add_mesh(shown.extract_feature_edges(boundary_edges=True, feature_edges=False,
                                                     manifold_edges=False),
                         scalars="shown", cmap="viridis", line_width=4, show_scalar_bar=False,
                         clim=(float(np.min(values)), float(np.max(values))))
    extent = float(max(np.ptp(np.asarray(grid.points)[:, :2], axis=0).max(), 1e-3))
    for surface in (bodies(t, extent) if bodies is not None else ()):
        plotter.add_mesh(surface.to_polydata(), color="lightgrey", smooth_shading=True,
                         split_sharp_edges=True)
    plotter.add_text(f"{pvd.stem}  t = {t:.4g} s  (step {index})", font_size=10)
    plotter.add_axes()
    if view == "xz":
        plotter.view_xz()
        plotter.camera.elevation = 15         # a little from above, so a strip shows its width
        plotter.enable_parallel_projection()
    else:
        plotter.view_isometric()
        if bodies is not None:
            plotter.camera.elevation = -20    # lower, to see the fabric hang over the bodies
    if bodies is not None:                    # framed on the fabric, the bodies around it
        plotter.reset_camera(bounds=shown.bounds)
        plotter.camera.zoom(0.8)
    else:
        plotter.reset_camera()
    out = Path(out) if out else directory / f"{pvd.stem}_{field}_{index:04d}.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    plotter.screenshot(str(out))
    plotter.close()
    return out


def read_history(directory) -> dict[str, np.ndarray]:
    """history.csv as columns of floats."""
    path = Path(directory) / "history.csv"
    if not path.is_file():
        raise InspectError(f"{path} does not exist")
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        raise InspectError(f"{path} has no rows")
    return {k: np.array([float(r[k]) if r[k] not in ("", None) else np.nan for r in rows])
            for k in rows[0]}


def _run_name(directory) -> str:
    summary = Path(directory) / "summary.json"
    try:
        data = json.loads(summary.read_text())
        return f"{data['case']}: {data['status']}"
    except (OSError, ValueError, KeyError):
        return Path(directory).resolve().name


_ENERGY = ("kinetic", "strain", "bending", "membrane", "external_potential", "gravity_potential",
           "friction_work", "damping_work", "total")


def plot_history(directory, out=None) -> Path:
    """Energies, probe displacements and solver effort against time, one PNG."""
    from matplotlib.figure import Figure  # without pyplot: the caller's backend is left alone

    h = read_history(directory)
    t = h["t"]
    probes = [k for k in h if k.startswith(("tip_", "centre_", "uz_"))]
    fig = Figure(figsize=(8, 9))
    axes = fig.subplots(3, 1, sharex=True)
    for name in _ENERGY:
        if name in h:
            axes[0].plot(t, h[name], label=name)
    axes[0].set_ylabel("energy [J]")
    axes[0].legend(fontsize=7, ncol=3)
    for name in probes:
        axes[1].plot(t, 1e3 * h[name], label=name)
    axes[1].set_ylabel("displacement [mm]")
    if probes:
        axes[1].legend(fontsize=7, ncol=3)
    if "iterations" in h:
        axes[2].plot(t, h["iterations"], ".", ms=3, label="Newton iterations")
    axes[2].set_ylabel("iterations")
    if "dt" in h:
        ax = axes[2].twinx()
        ax.semilogy(t[1:], h["dt"][1:], "r-", lw=0.8, label="dt")
        ax.set_ylabel("dt [s]", color="r")
    axes[2].set_xlabel("t [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle(_run_name(directory))
    fig.tight_layout()
    out = Path(out) if out else Path(directory) / "history.png"
    fig.savefig(out, dpi=110)
    return out


def plot_kes_loop(directory, out=None) -> Path | None:
    """Moment–curvature loop in KES units when history.csv has ``kappa`` and ``moment``."""
    h = read_history(directory)
    if "kappa" not in h or "moment" not in h:
        return None
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6, 4.5))
    ax = fig.subplots()
    ax.plot(to_kes(h["kappa"], "curvature"), to_kes(h["moment"], "moment"), lw=1)
    ax.set_xlabel("curvature K [cm⁻¹]")
    ax.set_ylabel("moment M [gf·cm/cm]")
    ax.axhline(0, color="k", lw=0.5)
    ax.axvline(0, color="k", lw=0.5)
    ax.grid(alpha=0.3)
    ax.set_title("simulated KES-FB loop")
    fig.tight_layout()
    out = Path(out) if out else Path(directory) / "kes_loop.png"
    fig.savefig(out, dpi=110)
    return out
