"""Import of external triangle meshes (gmsh ``.msh`` and anything meshio reads).

Named boundaries come from gmsh physical line groups (or meshio cell sets of
line cells) and/or from a dict of predicates on facet midpoints.

Examples
--------
>>> import tempfile, os, meshio
>>> points = np.array([[0., 0], [1, 0], [1, 1], [0, 1]])
>>> cells = [("triangle", np.array([[0, 1, 2], [0, 2, 3]])), ("line", np.array([[3, 0]]))]
>>> tag = {"gmsh:physical": [np.array([1, 1]), np.array([7])],
...        "gmsh:geometrical": [np.array([1, 1]), np.array([1])]}
>>> path = os.path.join(tempfile.mkdtemp(), "square.msh")
>>> meshio.Mesh(points, cells, cell_data=tag,
...             field_data={"clamped": np.array([7, 1])}).write(path, file_format="gmsh22", binary=False)
>>> mesh = load_mesh(path, boundaries={"right": lambda x: x[0] > 1 - 1e-9})
>>> {k: len(v) for k, v in sorted(mesh.boundaries.items())}
{'clamped': 1, 'right': 1}
"""
from __future__ import annotations

import contextlib
import io
import warnings
from pathlib import Path
from typing import Callable, Mapping

import meshio
import numpy as np
from skfem import MeshTri

from .quality import MeshError, check_arrays, check_mesh
from .rectangle import positive

__all__ = ["load_mesh", "save_mesh"]


def _line_groups(m: meshio.Mesh) -> dict[str, np.ndarray]:
    """Named groups of line cells, each as (n, 2) node pairs."""
    groups: dict[str, list] = {}
    tags = m.cell_data.get("gmsh:physical")
    if tags is not None:
        names = {int(v[0]): k for k, v in m.field_data.items() if len(v) > 1 and int(v[1]) == 1}
        for block, tag in zip(m.cells, tags):
            if block.type != "line":
                continue
            for value in np.unique(tag):
                name = names.get(int(value), f"gmsh_line_{int(value)}")
                groups.setdefault(name, []).append(block.data[tag == value])
    for name, sets in (m.cell_sets or {}).items():
        if name.startswith("gmsh:"):
            continue
        for block, idx in zip(m.cells, sets):
            if block.type == "line" and idx is not None and len(idx):
                groups.setdefault(name, []).append(block.data[np.asarray(idx)])
    return {k: np.vstack(v) for k, v in groups.items()}


def _facets_of(mesh: MeshTri, name: str, pairs: np.ndarray) -> np.ndarray:
    """Facet indices of ``mesh`` matching node pairs; error if a pair is no edge."""
    key = {tuple(f): k for k, f in enumerate(np.sort(mesh.facets, axis=0).T)}
    found = []
    for a, b in np.sort(pairs, axis=1):
        k = key.get((a, b))
        if k is None:
            raise MeshError(f"boundary '{name}': line {a}-{b} is not an edge of any triangle")
        found.append(k)
    return np.unique(np.array(found, dtype=np.int64))


def _why(exc: BaseException, printed: str) -> str:
    """meshio's reason in one line: what it printed before giving up, else its message."""
    if isinstance(exc, UnicodeDecodeError):
        return "binary data where text was expected"
    text = " ".join(printed.split())
    if not text and not isinstance(exc, SystemExit):
        text = " ".join(str(exc).split())
    return text or type(exc).__name__


def load_mesh(path, boundaries: Mapping[str, Callable] | None = None, scale: float = 1.0,
              min_angle: float = 5.0, required_boundaries=()) -> MeshTri:
    """Read a triangle mesh with meshio and return a checked :class:`skfem.MeshTri`.

    Parameters
    ----------
    path
        File readable by meshio (gmsh ``.msh`` 2.2/4.1, ``.vtu``, ...).  Must
        hold linear ``triangle`` cells in a plane z = const.
    boundaries
        Extra named boundaries: ``{name: predicate}`` with ``predicate(x)``
        taking facet midpoints ``x`` (2, n) **after scaling** and returning a
        boolean mask (only boundary facets are considered).  These override
        file groups of the same name.
    scale
        Factor to metres (e.g. 1e-3 for a mesh drawn in millimetres).
    min_angle
        Smallest admissible triangle angle in degrees.
    required_boundaries
        Names that must be present (e.g. ``("clamped",)``).

    Returns
    -------
    skfem.MeshTri
        Nodes not used by any triangle (gmsh geometry points) are dropped.
    """
    path = Path(path)
    if path.is_dir():
        raise MeshError(f"{path} is a folder, not a mesh file")
    if not path.is_file():
        raise FileNotFoundError(f"mesh file not found: {path}")
    scale = positive("scale", scale)
    captured = io.StringIO()
    try:
        # meshio prints stray blank lines, and why it gives up before it exits
        with contextlib.redirect_stdout(captured), contextlib.redirect_stderr(captured):
            m = meshio.read(path)
    except (Exception, SystemExit) as exc:  # some of meshio's readers call sys.exit on bad files
        raise MeshError(f"{path.name}: not a mesh meshio can read "
                        f"({_why(exc, captured.getvalue())})") from None
    if captured.getvalue().strip():
        warnings.warn(f"meshio reading {path.name}: {captured.getvalue().strip()}")
    tris = [b.data for b in m.cells if b.type == "triangle"]
    if not tris:
        kinds = sorted({b.type for b in m.cells})
        raise MeshError(f"{path.name}: no linear 'triangle' cells (found {kinds})")
    t = np.vstack(tris).T
    pts = np.asarray(m.points, dtype=float)
    if pts.shape[1] == 3:
        z = pts[t.ravel(), 2]
        if np.ptp(z) > 1e-9 * max(np.ptp(pts[:, :2], axis=0).max(), 1e-300):
            raise MeshError(f"{path.name}: triangles are not in a plane z = const "
                            f"(z spans {z.min()}..{z.max()})")
    # drop unused nodes and renumber (gmsh often keeps geometry-only points)
    used, t_new = np.unique(t, return_inverse=True)
    renumber = -np.ones(pts.shape[0], dtype=np.int64)
    renumber[used] = np.arange(len(used))
    p = scale * pts[used, :2].T
    t = t_new.reshape(t.shape)
    check_arrays(p, t)
    mesh = MeshTri(p, t)
    named = {}
    for name, pairs in _line_groups(m).items():
        mapped = renumber[pairs]
        if np.any(mapped < 0):
            raise MeshError(f"boundary '{name}': refers to nodes not used by any triangle")
        named[name] = _facets_of(mesh, name, mapped)
    for name, predicate in (boundaries or {}).items():
        if not callable(predicate):
            raise ValueError(f"boundaries['{name}'] must be a callable of facet midpoints")
        named[name] = mesh.facets_satisfying(predicate, boundaries_only=True)
    if named:
        mesh = mesh.with_boundaries(named)
    check_mesh(mesh, required_boundaries, min_angle=min_angle)
    return mesh


def save_mesh(mesh: MeshTri, path) -> Path:
    """Write ``mesh`` as a gmsh 2.2 ``.msh`` with its named boundaries as
    physical line groups (read back with :func:`load_mesh`).

    A facet in several named boundaries is written once per name.

    >>> import tempfile, os
    >>> from meshes import strip
    >>> path = save_mesh(strip(0.1, 0.02, 4, 1), os.path.join(tempfile.mkdtemp(), "strip.msh"))
    >>> sorted(load_mesh(path).boundaries)
    ['bottom', 'clamped', 'free_end', 'left', 'right', 'top']
    """
    path = Path(path)
    names = sorted(mesh.boundaries or {})
    cells = [("triangle", mesh.t.T.astype(np.int64))]
    physical = [np.full(mesh.t.shape[1], 1)]
    field_data = {"domain": np.array([1, 2])}
    for k, name in enumerate(names, start=2):
        facets = np.asarray(mesh.boundaries[name])
        cells.append(("line", mesh.facets[:, facets].T.astype(np.int64)))
        physical.append(np.full(len(facets), k))
        field_data[name] = np.array([k, 1])
    points = np.vstack([mesh.p, np.zeros(mesh.p.shape[1])]).T
    meshio.Mesh(points, cells, cell_data={"gmsh:physical": physical, "gmsh:geometrical": physical},
                field_data=field_data).write(path, file_format="gmsh22", binary=False)
    return path


def read_quietly(path, error=None) -> meshio.Mesh:
    """``meshio.read`` with its console output held back and every failure one line.

    meshio prints what each reader said and calls ``sys.exit`` when none could read the
    file; here that becomes ``error`` (an exception class, default :class:`MeshError`)
    with the message ``"<path>: cannot read as a mesh (<first thing it said>)"``.
    """
    error = MeshError if error is None else error
    said = io.StringIO()
    try:
        with contextlib.redirect_stdout(said), contextlib.redirect_stderr(said), \
                warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return meshio.read(path)
    except (Exception, SystemExit) as exc:  # meshio raises many kinds, some readers exit
        told = [] if isinstance(exc, SystemExit) else [str(exc)]
        lines = [ln.strip() for ln in [*told, *said.getvalue().splitlines()] if ln.strip()]
        raise error(f"{path}: cannot read as a mesh "
                    f"({lines[0] if lines else type(exc).__name__})") from None


def surface_triangles(mesh: meshio.Mesh) -> np.ndarray | None:
    """The triangles of a surface mesh, quads split in two, other cells left out (int64,
    shape (m, 3)); None when it has neither."""
    parts = []
    for block in mesh.cells:
        data = np.asarray(block.data, dtype=np.int64)
        if block.type.startswith("triangle"):
            parts.append(data[:, :3])
        elif block.type.startswith("quad"):
            parts += [data[:, [0, 1, 2]], data[:, [0, 2, 3]]]
    return np.concatenate(parts) if parts else None
