"""The ``[contact]`` table and its ``[[contact.body]]`` tables: rigid bodies the fabric touches.

::

    [contact]
    thickness = "0.5 mm"        # the fabric's; default the material's thickness
    dhat = "1 mm"               # barrier layer beyond half the thickness
    [[contact.body]]
    name = "table"
    shape = "disc"              # plane | half_space | sphere | cylinder | box | disc | mesh
    centre = [0, 0, -0.002]
    radius = "9 cm"
    thickness = "1 cm"
    edge_radius = "2 mm"
    mu = 0.3
    path = { times = [0, 1], translations = [[0, 0, 0], [0, 0, -0.05]] }

Coordinates are metres in the fabric's frame (its reference lies in z = 0, gravity along −z).
"""
from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import Field, model_validator

from drape.case.quantities import Q, _rule, _Section
from drape.contact.bodies import PAIR_SETS
from drape.contact.contact import PROJECTIONS

__all__ = ["BodyPath", "ContactSpec", "BodySpec", "BODY_SHAPES", "PlaneBody", "HalfSpaceBody", "SphereBody",
           "CylinderBody", "BoxBody", "DiscBody", "MeshBody"]

Vector = Annotated[list[Q("m")], Field(min_length=3, max_length=3)]
"""x, y, z [m] (each may carry units)."""
Direction = Annotated[list[float], Field(min_length=3, max_length=3)]


class BodyPath(_Section):
    """``path``: a prescribed rigid translation, linear between keyframes."""

    times: list[Q("s")] = Field(min_length=1)
    """Keyframe times [s], strictly increasing."""
    translations: list[Vector] = Field(min_length=1)
    """The body's offset [m] from its placement at each keyframe time."""

    @model_validator(mode="after")
    def _one_offset_per_time(self):
        if len(self.translations) != len(self.times):
            raise _rule(f"path.translations: {len(self.translations)} rows for {len(self.times)} times")
        if any(b <= a for a, b in zip(self.times, self.times[1:])):
            raise _rule("path.times must be strictly increasing")
        return self


class _Body(_Section):
    name: str = Field(min_length=1)
    """Name of the body (in messages and output), unique in the case."""
    mu: float = Field(0.0, ge=0)
    """Coulomb friction coefficient of the fabric on this body."""
    translation: Vector = [0.0, 0.0, 0.0]
    """Placement: translation [m] applied after rotation and scale."""
    rotation_deg: Direction = [0.0, 0.0, 0.0]
    """Placement: rotations about x, y, z [degrees], applied in that order."""
    scale: float = Field(1.0, gt=0)
    """Placement: uniform scale factor."""
    path: BodyPath | None = None
    """Prescribed motion ``{times = [...], translations = [[x, y, z], ...]}``; none: still."""


class PlaneBody(_Body):
    """shape = "plane": a square patch facing ``normal``."""

    shape: Literal["plane"]
    point: Vector
    """Centre of the patch [m]."""
    normal: Direction = [0.0, 0.0, 1.0]
    """Direction the patch faces (the fabric's side)."""
    size: Q("m", gt=0)
    """Side of the square [m]."""
    resolution: int = Field(4, ge=1)
    """Divisions per side."""


class HalfSpaceBody(_Body):
    """shape = "half_space": the solid behind an exact, unbounded plane (a floor, a support plate
    larger than the fabric): each fabric vertex meets it in one pair, the same everywhere
    (``drape.contact.half_space``). It may move along its normal only."""

    shape: Literal["half_space"]
    point: Vector | Literal["resting"]
    """A point of the plane [m], or ``"resting"``: the plane just under a flat specimen at
    z = 0, where it rests in the middle of its barrier layer (half the fabric's thickness plus
    d̂/2 below it), whatever the fabric's thickness; the plane must then face +z."""
    normal: Direction = [0.0, 0.0, 1.0]
    """Direction the plane faces (the fabric's side)."""

    @model_validator(mode="after")
    def _resting_faces_up(self):
        if self.point == "resting" and not (self.normal[0] == self.normal[1] == 0 < self.normal[2]):
            raise _rule(f"contact.body {self.name!r}: point = \"resting\" puts the plane under a flat "
                        f"specimen, so normal must be [0, 0, 1], got {list(self.normal)}")
        return self


class SphereBody(_Body):
    """shape = "sphere"."""

    shape: Literal["sphere"]
    centre: Vector
    """Centre [m]."""
    radius: Q("m", gt=0)
    """Radius [m]."""
    resolution: int = Field(24, ge=3)
    """Segments along a great circle."""


class CylinderBody(_Body):
    """shape = "cylinder": closed, along ``axis``."""

    shape: Literal["cylinder"]
    centre: Vector
    """Centre of the axis [m]."""
    axis: Direction = [0.0, 1.0, 0.0]
    """Axis direction."""
    radius: Q("m", gt=0)
    """Radius [m]."""
    length: Q("m", gt=0)
    """Length along the axis [m]."""
    resolution: int = Field(24, ge=3)
    """Segments around the rim."""


class BoxBody(_Body):
    """shape = "box": a box with rounded edges."""

    shape: Literal["box"]
    centre: Vector
    """Centre [m]."""
    size: Vector
    """Side lengths along x, y, z [m]."""
    edge_radius: Q("m", ge=0) = 0.0
    """Radius of the rounded edges [m]."""
    resolution: int = Field(24, ge=3)
    """Segments of a full circle of the rounded edges."""


class DiscBody(_Body):
    """shape = "disc": a round table with a rounded rim, its top face at the centre's height."""

    shape: Literal["disc"]
    centre: Vector
    """Centre of the top face [m]."""
    radius: Q("m", gt=0)
    """Radius [m]."""
    thickness: Q("m", gt=0)
    """Thickness [m]."""
    edge_radius: Q("m", ge=0) = 0.0
    """Radius of the rounded rim [m]."""
    resolution: int = Field(48, ge=3)
    """Segments around the rim."""


class MeshBody(_Body):
    """shape = "mesh": a triangulated surface read from a file (meshio: STL, OBJ, PLY, VTU, ...)."""

    shape: Literal["mesh"]
    file: str
    """Path of the surface file (relative to the case file)."""
    units: str = "m"
    """Length unit of the file's coordinates (m, mm, cm, inch, ...)."""


#: The body tables by ``shape``.
BODY_SHAPES = {"plane": PlaneBody, "half_space": HalfSpaceBody, "sphere": SphereBody, "cylinder": CylinderBody,
               "box": BoxBody, "disc": DiscBody, "mesh": MeshBody}

BodySpec = Annotated[Union[PlaneBody, HalfSpaceBody, SphereBody, CylinderBody, BoxBody, DiscBody, MeshBody],
                     Field(discriminator="shape")]


#: Body shapes whose friction ``pairs = "per_point"`` reproduces (Coulomb on an incline).
FLAT_SHAPES = ("plane", "half_space")


class ContactSpec(_Section):
    """[contact]: contact of the fabric with rigid bodies and with itself (IPC, ``drape.contact``)."""

    thickness: Q("m", gt=0, le=0.05) | None = None
    """Fabric thickness [m], at most 5 cm: the mid-surface keeps half of it from a body.
    Default: the material's."""
    dhat: Q("m", gt=0, le=0.05) = 1e-3
    """Barrier activation distance d̂ [m] beyond half the thickness, at most 5 cm (a layer a
    fabric rests in, not a gap it hangs across)."""
    barrier_stiffness: Q("N/m**3", gt=0) | None = None
    """Barrier stiffness κ [N/m³]; default: a vertex carrying its share of the weight rests at
    half the thickness plus d̂/2 (``drape.contact.stiffness``)."""
    eps_v: Q("m/s", gt=0) = 1e-3
    """Friction's stick velocity [m/s]: slower contacts stick (elastically)."""
    self_contact: bool = False
    """Let the fabric collide with itself."""
    mu_self: float = Field(0.0, ge=0)
    """Friction coefficient of the fabric on itself."""
    subdivision: int = Field(1, ge=1, strict=True)
    """Collision mesh: every fabric triangle split into subdivision² sub-triangles whose
    vertices follow the shell's field inside the element (1: the mesh vertices alone, whose
    chords cut the curved elements)."""
    hessian: Literal[tuple(PROJECTIONS)] = "projected"
    """The barrier's and the friction's Hessians in Newton's tangent: ``projected`` on the
    positive semi-definite cone pair by pair, as IPC does, or ``exact``. Where the fabric is
    held between two bodies (a grip) the projected tangent overstates the barrier's stiffness
    and Newton converges only linearly; the exact one converges there (docs/theory.md §7)."""
    pairs: Literal[PAIR_SETS] = "ipc"
    """Which contact pairs push: ``ipc``, every pair of primitives within reach in full (a point
    resting on a triangulated body is pushed once per triangle, edge and vertex near it, and
    harder as it passes a body's edge); ``per_point``, each fabric contact point once, by its
    distance to the body, continuous across the body's edges, with friction only on planes and
    half-spaces (docs/theory.md §7)."""
    body: list[BodySpec] = []
    """``[[contact.body]]``: the rigid bodies."""

    @model_validator(mode="after")
    def _unique_names(self):
        names = [b.name for b in self.body]
        twice = sorted({n for n in names if names.count(n) > 1})
        if twice:
            raise _rule(f"contact.body names must be unique: {', '.join(twice)} given twice")
        if self.pairs == "per_point":
            rough = [f"body {b.name!r}" for b in self.body if b.mu > 0 and b.shape not in FLAT_SHAPES]
            if self.self_contact and self.mu_self > 0:
                rough.insert(0, "the fabric itself (mu_self)")
            if rough:
                raise _rule(f"contact.pairs = \"per_point\" takes friction only on a plane or half-space: "
                            f"{rough[0]} has mu > 0 (on a faceted body its Coulomb limit is not met: a strip "
                            "round a post slips at 0.85 e^(mu theta); docs/theory.md §7)")
        return self
