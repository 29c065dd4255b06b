"""The TOML case file: schema, validation with readable errors, dotted overrides.

A case file describes one simulation: the specimen mesh, the fabric, the structural model,
the loads, the time integration, what to write and when to stop. Every table rejects unknown
keys. Numbers are SI (m, kg, s, N); any dimensional number may instead be written as a
string with units, e.g. ``length = "5 cm"`` or ``rate = "0.5 1/cm/s"``, converted with pint.

A minimal case (``python -m drape.run --help-case`` lists every table and key)::

    [case]
    name = "cantilever"
    analysis = "peirce"          # post-processing: none | peirce | cusick | kes | cycle
    [mesh]
    kind = "strip"               # strip | rectangle | cusick | file
    length = "2 cm"
    width = "2.5 cm"
    nx = 8
    ny = 4
    [material]
    name = "fabric1"             # cases/materials/fabric1.toml
    [model]
    kinematics = "large"
    supports = { clamped = "clamped" }
    [load.gravity]
    ramp_time = 0.2
    [solver]
    dt = 0.005
    t_end = 2.0
    [stop]
    kinetic_fraction = 1e-9

Errors name the dotted key and the rule it breaks, one line per problem:

>>> good = {"case": {"name": "x"}, "material": {"name": "fabric1"},
...         "mesh": {"kind": "strip", "length": 0.05, "width": 0.02, "nx": 4},
...         "solver": {"dt": 0.01, "t_end": 0.1}}
>>> parse_case(good).mesh.length
0.05
>>> def check(section, **values):
...     data = {**good, section: {**good.get(section, {}), **values}}
...     try:
...         parse_case(data)
...     except CaseError as err:
...         print(err)
>>> check("mesh", length=-1.0)
mesh.length = -1.0: must be > 0
>>> check("model", dampin={})
unknown key 'model.dampin' (did you mean 'damping'?)
>>> check("mesh", width="2 cm")   # units are converted

Overrides use dotted keys and TOML values:

>>> data = {"solver": {"dt": 0.01}}
>>> apply_overrides(data, ["solver.dt=1e-3", "case.name=short", "output.fields=['curvature']"])
>>> data
{'solver': {'dt': 0.001}, 'case': {'name': 'short'}, 'output': {'fields': ['curvature']}}
"""
from __future__ import annotations

import difflib
import tomllib
import typing
from pathlib import Path
from typing import Annotated, Any, Literal, Union

from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

__all__ = [
    "Case",
    "CaseError",
    "load_case",
    "parse_case",
    "apply_overrides",
    "check_boundaries",
    "dump_case",
    "describe_schema",
]


class CaseError(ValueError):
    """A case file breaks the schema; the message names each offending dotted key and rule."""


# --------------------------------------------------------------------------- quantities
def _ureg():
    from constitutive.units import ureg  # one registry for the project (knows gf, gmf)

    return ureg


def _quantity(unit: str):
    """Before-validator: accept a number (SI) or a string with units convertible to ``unit``."""

    def convert(value):
        if isinstance(value, str):
            import pint

            try:
                q = _ureg().Quantity(value)
                return float(q.to(unit).magnitude)
            except (pint.errors.PintError, ValueError, AttributeError, TypeError) as exc:
                raise ValueError(
                    f"cannot read {value!r} as a quantity in {unit or 'dimensionless'} units ({exc})"
                ) from None
        return value

    return BeforeValidator(convert)


def Q(unit: str, **field_kwargs):
    """A float field in SI ``unit`` that also accepts unit strings (``"5 cm"``)."""
    return Annotated[float, _quantity(unit), Field(**field_kwargs)]


_CONFIG = ConfigDict(extra="forbid", strict=True, use_attribute_docstrings=True)


class _Section(BaseModel):
    model_config = _CONFIG


def _rule(message: str):
    """Cross-key rule error; ``@.`` in ``message`` becomes the dotted path of the table."""
    return ValueError(message)


# --------------------------------------------------------------------------- [case]
class CaseInfo(_Section):
    """[case]: what this run is."""

    name: str = Field(pattern=r"^[A-Za-z0-9_.-]+$")
    """File stem of the outputs (``<name>_NNNN.vtu``, ``<name>.pvd``); letters, digits, ``_.-``."""
    description: str = ""
    """Free text, copied into summary.json."""
    analysis: str = "none"
    """Post-processing after the run: ``peirce`` (cantilever bending length), ``cusick``
    (drape coefficient and folds), ``kes`` (B and 2HB of the simulated moment-curvature loop),
    ``cycle`` (probe displacements at every point of load.gravity.history: the residual
    deformation friction leaves after unloading), ``none``."""

    @field_validator("analysis")
    @classmethod
    def _known_analysis(cls, value):
        from drape.analyses import ANALYSES

        if value not in ANALYSES:
            raise ValueError(f"must be one of {', '.join(repr(a) for a in ANALYSES)}")
        return value


# --------------------------------------------------------------------------- [mesh]
class _MeshBase(_Section):
    element: Literal["morley", "argyris"] = "argyris"
    """Finite element: ``morley`` (quadratic, small deflection only) or ``argyris`` (quintic)."""


class StripMesh(_MeshBase):
    """[mesh] kind = "strip": [0, length] x [0, width]; boundaries ``clamped`` (= ``left``, x = 0),
    ``free_end`` (= ``right``), ``bottom``, ``top``."""

    kind: Literal["strip"]
    length: Q("m", gt=0)
    """Strip length along x (warp) [m]."""
    width: Q("m", gt=0)
    """Strip width along y [m]."""
    nx: int = Field(ge=1)
    """Divisions along the length."""
    ny: int = Field(1, ge=1)
    """Divisions across the width."""


class RectangleMesh(_MeshBase):
    """[mesh] kind = "rectangle": [0, length] x [0, width]; boundaries ``left``, ``right``,
    ``bottom``, ``top``."""

    kind: Literal["rectangle"]
    length: Q("m", gt=0)
    """Side along x (warp) [m]."""
    width: Q("m", gt=0)
    """Side along y (weft) [m]."""
    nx: int = Field(ge=1)
    """Divisions along x."""
    ny: int = Field(ge=1)
    """Divisions along y."""


class CusickMesh(_MeshBase):
    """[mesh] kind = "cusick": the overhanging annulus, centred at 0; boundaries ``disc``, ``hem``."""

    kind: Literal["cusick"]
    specimen_diameter: Q("m", gt=0) = 0.30
    """Specimen diameter [m] (standard: 0.24, 0.30 or 0.36)."""
    disc_diameter: Q("m", gt=0) = 0.18
    """Support disc diameter [m]."""
    target_size: Q("m", gt=0) = 0.01
    """Nominal element size [m]; sets the divisions not given explicitly."""
    n_radial: int | None = Field(None, ge=1)
    """Element rings across the overhang (default: overhang / target_size)."""
    n_circumferential: int | None = Field(None, ge=8)
    """Divisions around the circumference, even (default: mid circumference / target_size)."""
    refine: int = Field(0, ge=0)
    """Uniform refinements (divisions × 2**refine) for convergence studies."""
    radial_grading: float = Field(1.0, ge=1.0)
    """Outermost over innermost ring width (1: uniform); finer rings at the clamped disc edge,
    where a limp fabric turns down within about one bending length."""

    @model_validator(mode="after")
    def _disc_inside(self):
        if self.disc_diameter >= self.specimen_diameter:
            raise _rule(
                f"@.disc_diameter = {self.disc_diameter} must be smaller than "
                f"@.specimen_diameter = {self.specimen_diameter}"
            )
        return self


class FileMesh(_MeshBase):
    """[mesh] kind = "file": an external triangle mesh read with meshio (gmsh .msh, .vtu, ...);
    boundaries are the file's named line groups."""

    kind: Literal["file"]
    path: str
    """Mesh file; relative paths are taken from the case file's directory."""
    scale: float = Field(1.0, gt=0)
    """Factor taking the file's coordinates to metres (0.01 for a file in cm)."""


MeshSpec = Annotated[
    Union[StripMesh, RectangleMesh, CusickMesh, FileMesh], Field(discriminator="kind")
]


# --------------------------------------------------------------------------- [material]
class LawOverride(_Section):
    """Bending-law parameters replacing those of the material (SI; all optional)."""

    k1: Q("N*m", gt=0) | None = None
    """Linear bending rigidity [N·m]."""
    k3: Q("N*m**3", ge=0) | None = None
    """Cubic coefficient [N·m³]."""
    d: Q("N*m*s", ge=0) | None = None
    """Viscous coefficient [N·m·s]."""
    m: Q("N*m*s**2", ge=0) | None = None
    """Curvature-inertia coefficient [N·m·s²]."""
    f1: Q("N", ge=0) | None = None
    """Friction moment of the first (fast) state [N·m/m = N]; must exceed f2."""
    f2: Q("N", ge=0) | None = None
    """Friction moment of the second state [N]."""
    eps_f: Q("1/m", gt=0) | None = None
    """Friction curvature length ε_f [1/m]."""
    eta: float | None = Field(None, gt=0, lt=1)
    """Ratio of the two friction lengths, 0 < η < 1."""

    @model_validator(mode="after")
    def _dissipative(self):
        if self.f1 is not None and self.f2 is not None and not self.f1 > self.f2:
            raise _rule(f"@.f1 = {self.f1} must exceed @.f2 = {self.f2} (dissipativity, 3.18)")
        return self


class KesSummary(_Section):
    """[material.kes]: a fabric known only from KES-FB summary values, in KES units as on the
    tester's print-out (``constitutive.material.material_from_kes``: k3 = d = 0, first-order
    friction calibrated so that the simulated KES-FB loop gives exactly B and 2HB)."""

    B_warp: float = Field(gt=0)
    """Bending rigidity B, warp direction [gf·cm²/cm]."""
    B_weft: float = Field(gt=0)
    """Bending rigidity B, weft direction [gf·cm²/cm]."""
    HB2_warp: float = Field(ge=0)
    """Hysteresis width 2HB at |κ| = 1 cm⁻¹, warp [gf·cm/cm]."""
    HB2_weft: float = Field(ge=0)
    """Hysteresis width 2HB, weft [gf·cm/cm]."""
    weight: float = Field(gt=0)
    """Fabric weight W [gf/cm²] (areal mass = 10 × W kg/m²; 1 mg/cm² = 0.001 gf/cm²), as in the
    material library (cases/materials/*.toml) and thesis Table 4.2."""
    thickness: float | None = Field(None, gt=0)
    """Thickness [cm] (optional), as in the material library."""
    eps_f: float = Field(0.2, gt=0)
    """Friction length ε_f [cm⁻¹] of the calibrated friction (a1 = ε_f η)."""
    eta: float = Field(0.5, gt=0, lt=1)
    """Ratio η of the friction lengths."""


class MaterialSpec(LawOverride):
    """[material]: the fabric. Give exactly one of ``name``, ``path`` or a ``[material.kes]`` table.

    Law keys at this level (k1, k3, d, m, f1, f2, eps_f, eta) override both directions;
    ``[material.warp]`` / ``[material.weft]`` override one direction and win over them.
    """

    name: str | None = None
    """Material from the library in cases/materials (e.g. ``fabric1``)."""
    path: str | None = None
    """Material file; relative paths are taken from the case file's directory."""
    kes: KesSummary | None = None
    """Inline KES summary values (see [material.kes])."""
    areal_mass: Q("kg/m**2", gt=0) | None = None
    """Override the areal mass ρ_A [kg/m²]."""
    thickness: Q("m", gt=0) | None = None
    """Override the thickness [m]."""
    friction: bool = True
    """``false`` drops the hysteretic friction moment (for friction-free comparisons)."""
    bending_scale: float = Field(1.0, gt=0)
    """Multiplies every bending moment of both laws (k1, k3, d, m, f1, f2; not ε_f, η), after the
    overrides: the same fabric made stiffer or limper (bending length × bending_scale^(1/3))."""
    warp: LawOverride = LawOverride()
    """Overrides of the warp law (acts on κ_xx)."""
    weft: LawOverride = LawOverride()
    """Overrides of the weft law (acts on κ_yy)."""

    @model_validator(mode="after")
    def _one_source(self):
        given = [k for k in ("name", "path", "kes") if getattr(self, k) is not None]
        if len(given) != 1:
            raise _rule(
                "@: give exactly one of name, path or [material.kes]"
                + (f" (got {', '.join(given)})" if given else "")
            )
        friction_keys = ("f1", "f2", "eps_f", "eta")
        if not self.friction:
            for direction in ("warp", "weft"):
                given = [k for k in friction_keys if k in self.law_overrides(direction)]
                if given:
                    raise _rule(f"@.friction = false contradicts the friction override {given[0]}")
        for direction in ("warp", "weft"):
            law = self.law_overrides(direction)
            f1, f2 = law.get("f1"), law.get("f2")
            if f1 is not None and f2 is not None and not f1 > f2:
                k1 = f"@.{direction}.f1" if getattr(self, direction).f1 is not None else "@.f1"
                k2 = f"@.{direction}.f2" if getattr(self, direction).f2 is not None else "@.f2"
                raise _rule(f"{k1} = {f1} must exceed {k2} = {f2} (dissipativity, 3.18)")
        return self

    def law_overrides(self, direction: str) -> dict:
        """Effective overrides for ``direction`` ('warp' or 'weft'): shared keys, then per-direction."""
        shared = {k: getattr(self, k) for k in LawOverride.model_fields}
        own = getattr(self, direction).model_dump(exclude_none=True)
        merged = {k: v for k, v in shared.items() if v is not None}
        merged.update(own)
        return merged


# --------------------------------------------------------------------------- [model]
class Damping(_Section):
    """[model.damping]: Rayleigh damping C = alpha M + beta K0 (added to the law's own d)."""

    alpha: Q("1/s", ge=0) = 0.0
    """Mass-proportional coefficient [1/s]."""
    beta: Q("s", ge=0) = 0.0
    """Stiffness-proportional coefficient [s] (K0: tangent stiffness at rest)."""


class Membrane(_Section):
    """[model.membrane]: orthotropic membrane stiffness of the large-rotation model [N/m];
    keys not given keep the material's values (default E11 = E22 = 1e4 N/m, ν12 = 0, G12 = 50 N/m)."""

    E11: Q("N/m", gt=0) | None = None
    """Tensile stiffness along the warp [N/m]."""
    E22: Q("N/m", gt=0) | None = None
    """Tensile stiffness along the weft [N/m]."""
    nu12: float | None = Field(None, ge=0, lt=1)
    """In-plane Poisson ratio."""
    G12: Q("N/m", gt=0) | None = None
    """In-plane shear stiffness [N/m] (woven fabric: soft in shear)."""


class ModelSpec(_Section):
    """[model]: the structural model."""

    kinematics: Literal["small", "large"] = "small"
    """``small``: Kirchhoff plate, scalar deflection w (thesis ch. 5). ``large``: geometrically
    exact Kirchhoff–Love plate with membrane coupling (needs mesh.element = "argyris")."""
    supports: dict[str, Literal["clamped", "simply_supported", "free"]] = {}
    """Boundary conditions per named mesh boundary, e.g. ``supports = { clamped = "clamped" }``:
    ``clamped`` (w and slope fixed), ``simply_supported`` (w fixed; small kinematics only),
    ``free``. Unlisted boundaries are free."""
    damping: Damping = Damping()
    """Rayleigh damping (see [model.damping])."""
    twist_rigidity: Q("N*m", gt=0) | None = None
    """Linear twist rigidity D_t [N·m]; default sqrt(k1_warp k1_weft)."""
    membrane: Membrane | None = None
    """Membrane stiffness (large kinematics only); default: the material's, else
    E11 = E22 = 1e4 N/m, G12 = 50 N/m."""
    translational_inertia: bool = True
    """``false`` drops the areal mass from the inertia (pure bending, as in the KES-FB
    tester; small kinematics only)."""
    membrane_strain_degree: int | None = Field(None, ge=0, le=4)
    """Large kinematics: project the membrane strain per triangle onto polynomials of this
    degree (assumed strain against membrane locking of folds on coarse meshes); absent: the
    consistent strain."""
    membrane_stabilization: float = Field(0.0, ge=0, le=1)
    """With @.membrane_strain_degree: weight γ kept on the strain the projection removes
    (0: pure assumed strain; 0.01–0.1 suppresses the spurious in-plane modes of degrees 0–2;
    1: the consistent strain)."""

    friction_tangent: Literal["consistent", "nonnegative"] = "consistent"
    """Newton's tangent of the friction moment: ``nonnegative`` floors it at zero where the
    law softens (the moment falls with curvature after a reversal, e.g. Fabric 2's weft as
    printed: −51 k1), which otherwise sends Newton off. The solution is unchanged."""

    @model_validator(mode="after")
    def _membrane_needs_large(self):
        if self.membrane_stabilization and self.membrane_strain_degree is None:
            raise _rule("@.membrane_stabilization needs @.membrane_strain_degree")
        for key in ("membrane", "membrane_strain_degree"):
            if getattr(self, key) is not None and self.kinematics != "large":
                raise _rule(
                    f"@.{key} is only used with @.kinematics = 'large' (got '{self.kinematics}')"
                )
        return self


# --------------------------------------------------------------------------- [load]
def _check_history(history):
    if history is None:
        return history
    times = [row[0] for row in history]
    if any(b <= a for a, b in zip(times, times[1:])):
        raise ValueError("history times must increase strictly")
    return history


History = Annotated[
    list[Annotated[list[float], Field(min_length=2, max_length=2)]] | None,
    Field(min_length=2),
]


class Amplitude(_Section):
    """A load amplitude in time: ``factor`` reached over a smooth ``ramp_time``, or a ``history``."""

    ramp_time: Q("s", ge=0) = 0.0
    """Duration of the smooth (C¹, cubic) ramp from 0 to full load [s]; 0 = applied at once."""
    history: History = None
    """Amplitude table ``[[t0, f0], [t1, f1], ...]`` (times in s); replaces the ramp.
    Outside the table the end values hold."""
    smooth: bool = True
    """Blend each history segment with the C¹ cubic of ``ramp_time`` (zero load rate at every
    table point, no jerk into the dynamics); ``false``: piecewise linear."""

    _check = field_validator("history")(classmethod(lambda cls, v: _check_history(v)))

    @model_validator(mode="after")
    def _ramp_or_history(self):
        if self.history is not None and "ramp_time" in self.model_fields_set:
            raise _rule("@: give ramp_time or history, not both")
        return self

    def amplitude(self, t: float) -> float:
        """Load factor at time ``t`` (multiplies ``factor``/``value``).

        >>> Amplitude(ramp_time=1.0).amplitude(0.5), Amplitude().amplitude(0.0)
        (0.5, 1.0)
        >>> Amplitude(history=[[0, 0], [1, 1], [2, -1]]).amplitude(1.5)
        0.0
        >>> Amplitude(history=[[0, 0], [1, 1]], smooth=False).amplitude(0.25)
        0.25
        >>> Amplitude(history=[[0, 0], [1, 1]]).amplitude(0.25)
        0.15625
        """
        if self.history is not None:
            import numpy as np

            ts, fs = (np.array(c, dtype=float) for c in zip(*self.history))
            if not self.smooth or t <= ts[0] or t >= ts[-1]:
                return float(np.interp(t, ts, fs))
            i = int(np.searchsorted(ts, t, side="right")) - 1
            s = (t - ts[i]) / (ts[i + 1] - ts[i])
            return float(fs[i] + (fs[i + 1] - fs[i]) * s * s * (3.0 - 2.0 * s))
        if self.ramp_time <= 0:
            return 1.0
        s = min(max(t / self.ramp_time, 0.0), 1.0)
        return s * s * (3.0 - 2.0 * s)

    def end_time(self) -> float:
        """Time after which the amplitude no longer changes."""
        return self.history[-1][0] if self.history is not None else self.ramp_time


class Gravity(Amplitude):
    """[load.gravity]: self-weight −ρ_A g e_z (g = 9.80665 m/s²) times factor × amplitude(t).

    A gravity cycle (load, unload, reverse) is a ``history`` such as
    ``[[0, 0], [1, 1], [2, 1], [3, 0], [4, -1], [5, -1], [6, 0]]``.
    """

    factor: float = 1.0
    """Multiplier of the self-weight (negative turns the fabric upside down)."""


class Pressure(Amplitude):
    """[load.pressure]: uniform pressure along +z [N/m²] times amplitude(t)."""

    value: Q("N/m**2")
    """Pressure along +z [N/m²]."""


class EndMoment(Amplitude):
    """[load.end_moment]: follower moment per unit width on a boundary [N·m/m = N]."""

    value: Q("N")
    """Moment per unit width [N]; positive curls the fabric face-up (towards +z)."""
    boundary: str = "free_end"
    """Boundary carrying the moment."""


class KesDrive(_Section):
    """[load.kes]: drive a strip through the KES-FB pure-bending profile by imposed end rotation.

    Both ends are held in clamps rotated by ±κ(t) L / 2, which bends an unloaded uniform strip
    to the uniform curvature κ(t) of the KES profile 0 → K+ → K− → 0
    (``drape.plate.pure_bending_rotations``; small kinematics).
    """

    ends: list[str] = Field(["left", "right"], min_length=2, max_length=2)
    """The two strip ends (mesh boundary names) held in the rotating clamps."""
    k_max: Q("1/m", gt=0) = 250.0
    """Turning curvature K+ [1/m] (KES-FB: 2.5 cm⁻¹)."""
    k_min: Q("1/m", lt=0) | None = None
    """Turning curvature K− [1/m]; default −k_max."""
    rate: Q("1/m/s", gt=0) = 50.0
    """Curvature rate v [1/m/s] (KES-FB: 0.5 cm⁻¹/s)."""
    accel_time: Q("s", gt=0) = 0.5
    """Acceleration/deceleration time T at each turning point [s] (equipment constant)."""

    def profile_kwargs(self) -> dict:
        """Keyword arguments of ``constitutive.kes.kes_profile``."""
        return dict(rate=self.rate, accel_time=self.accel_time, k_max=self.k_max,
                    k_min=-self.k_max if self.k_min is None else self.k_min)

    def duration(self) -> float:
        """Length of the test 0 → K+ → K− → 0 [s] (the end of ``kes_profile``'s last phase).

        >>> KesDrive().duration()
        21.5
        """
        from constitutive.kes import kes_profile

        return float(kes_profile(t=[0.0], **self.profile_kwargs()).phase_times[-1])


class Perturbation(_Section):
    """[load.perturbation]: seeded out-of-plane imperfection of a Cusick specimen
    (``drape.perturbation.FoldPerturbation``) so that the symmetric drape can buckle into folds:
    ``w = A s(ρ) g(φ)`` with s = ((ρ − r_disc)/(R − r_disc))², zero with its slope at the disc."""

    kind: Literal["none", "lobed", "random"] = "random"
    """``lobed``: one mode cos(n φ + φ0) (imposes n folds); ``random``: modes k_min..k_max with
    seeded amplitudes and phases (the fabric picks its node count)."""
    amplitude: float = Field(1e-3, ge=0)
    """A: fraction of the weight (target force), metres (displacement) or m/s (velocity)."""
    seed: int = 0
    """Random seed of the phases/amplitudes (same seed, same field)."""
    n_lobes: int = Field(6, ge=1)
    """Mode number for kind = "lobed"."""
    k_min: int = Field(2, ge=1)
    """Lowest mode for kind = "random"."""
    k_max: int = Field(12, ge=1)
    """Highest mode for kind = "random"."""
    target: Literal["force", "displacement", "velocity"] = "displacement"
    """``force``: transient load A ρ_A g s g(φ) sin²(π t / duration) on [0, duration] (starts at
    rest, same on every mesh; recommended); ``displacement``/``velocity``: initial u_z/v_z."""
    duration: Q("s", gt=0) = 0.2
    """Length of the transient load of target = "force"."""

    @model_validator(mode="after")
    def _modes(self):
        if self.k_min > self.k_max:
            raise _rule(f"@.k_min = {self.k_min} must not exceed @.k_max = {self.k_max}")
        return self


class LoadSpec(_Section):
    """[load]: external actions (any combination)."""

    gravity: Gravity | None = None
    """Self-weight, see [load.gravity]."""
    pressure: Pressure | None = None
    """Uniform pressure, see [load.pressure]."""
    end_moment: EndMoment | None = None
    """Follower end moment, see [load.end_moment]."""
    kes: KesDrive | None = None
    """KES-FB imposed-rotation drive, see [load.kes]."""
    perturbation: Perturbation | None = None
    """Initial fold imperfection of a Cusick specimen, see [load.perturbation]."""

    def end_time(self) -> float:
        """Time after which no load changes any more (0 if unloaded)."""
        parts = [self.gravity, self.pressure, self.end_moment]
        ends = [p.end_time() for p in parts if p is not None]
        if self.kes is not None:
            ends.append(self.kes.duration())
        if self.perturbation is not None and self.perturbation.target == "force":
            ends.append(self.perturbation.duration)
        return max(ends, default=0.0)


# --------------------------------------------------------------------------- [solver]
class SolverSpec(_Section):
    """[solver]: time integration (Newmark / HHT-α with Newton iterations)."""

    dt: Q("s", gt=0)
    """Initial and largest time step [s] (after a cut the step grows back to it); only the
    settling phase goes beyond it, up to ``settling_dt``."""
    t_end: Q("s", gt=0)
    """End of the simulated time [s] (a [stop] rule may end the run earlier)."""
    alpha_hht: float = Field(0.0, ge=-1.0 / 3.0, le=0.0)
    """HHT-α parameter in [−1/3, 0]; negative values damp high-frequency modes."""
    beta: float | None = Field(None, gt=0, le=0.5)
    """Newmark β; default (1 − α)²/4 (¼, average acceleration, for α = 0)."""
    gamma: float | None = Field(None, ge=0.5, le=1.0)
    """Newmark γ; default ½ − α."""
    rtol: float = Field(1e-9, gt=0, lt=1)
    """Newton: relative residual tolerance (to the first residual of the step)."""
    atol: float = Field(0.0, ge=0)
    """Newton: absolute residual tolerance [N]."""
    du_rtol: float = Field(1e-9, ge=0, lt=1)
    """Newton: relative increment tolerance (to the step's displacement change)."""
    du_atol: float = Field(0.0, ge=0)
    """Newton: absolute increment tolerance [m]."""
    max_iter: int = Field(25, ge=1)
    """Newton iterations before the step is cut."""
    max_cuts: int = Field(6, ge=0)
    """Step halvings before the run stops with a convergence error."""
    quasi_static: bool = False
    """Equilibrium path (no inertia, no damping): load steps of ``dt`` in pseudo-time up to t_end."""
    settling_dt: Q("s", gt=0) | None = None
    """Longest time step once every load has stopped changing (the settling phase); default
    ``dt``. From there the step doubles after every 4 converged steps up to this value: what
    moves then is a slow, overdamped creep into equilibrium, and as the step grows the
    update tends to Newton's on the static equilibrium (pseudo-transient continuation).
    Output marks (``every_dt``) are not landed on in this phase."""

    @model_validator(mode="after")
    def _stable(self):
        if self.dt > self.t_end:
            raise _rule(f"@.dt = {self.dt}: must not exceed @.t_end = {self.t_end}")
        if self.settling_dt is not None and self.settling_dt < self.dt:
            raise _rule(f"@.settling_dt = {self.settling_dt}: must not be shorter than @.dt = {self.dt}")
        if self.settling_dt is not None and self.quasi_static:
            raise _rule("@.settling_dt: only for dynamic runs (quasi_static = true has no settling phase)")
        gamma = self.newmark_gamma
        beta = self.newmark_beta
        if beta < gamma / 2 - 1e-12:
            raise _rule(
                f"@.beta = {beta}: must be >= gamma/2 = {gamma / 2} "
                "(unconditional stability needs 2β ≥ γ ≥ ½)"
            )
        return self

    @property
    def newmark_gamma(self) -> float:
        return self.gamma if self.gamma is not None else 0.5 - self.alpha_hht

    @property
    def newmark_beta(self) -> float:
        return self.beta if self.beta is not None else (1.0 - self.alpha_hht) ** 2 / 4.0


# --------------------------------------------------------------------------- [output]
class OutputSpec(_Section):
    """[output]: what is written and when."""

    every: int = Field(1, ge=1)
    """Write a VTU every N converged steps (ignored when every_dt is given)."""
    every_dt: Q("s", gt=0) | None = None
    """Write a VTU each time simulated time passes a multiple of every_dt [s]."""
    fields: list[str] | None = None
    """Fields kept in the VTU files (displacement is always kept); default: all the model gives."""


# --------------------------------------------------------------------------- [stop]
class StopSpec(_Section):
    """[stop]: end the run early once the fabric has settled."""

    kinetic_energy: Q("J", gt=0) | None = None
    """Settled when the kinetic energy falls below this value [J]."""
    kinetic_fraction: float | None = Field(None, gt=0, lt=1)
    """Settled when the kinetic energy falls below this fraction of E_ref = ρ_A g A L: the
    energy the free fabric (area A) would release falling its span L (strip/rectangle length,
    Cusick overhang). 1e-6 means a mean speed of about sqrt(2e-6 g L) (~1 mm/s for L = 6 cm)."""
    after: Q("s", ge=0) | None = None
    """Check only after this time [s]; default: when the loads stop changing."""
    steps: int = Field(5, ge=1)
    """Consecutive converged steps that must satisfy the rule."""

    @property
    def active(self) -> bool:
        return self.kinetic_energy is not None or self.kinetic_fraction is not None


# --------------------------------------------------------------------------- the case
class Case(_Section):
    """A whole case file."""

    case: CaseInfo
    """[case]: name, description and analysis."""
    mesh: MeshSpec
    """[mesh]: geometry, selected by ``kind`` = strip | rectangle | cusick | file."""
    material: MaterialSpec
    """[material]: the fabric."""
    model: ModelSpec = ModelSpec()
    """[model]: kinematics, supports, damping."""
    load: LoadSpec = LoadSpec()
    """[load]: gravity, pressure, end moment, KES drive."""
    solver: SolverSpec
    """[solver]: time stepping."""
    output: OutputSpec = OutputSpec()
    """[output]: VTU / history options."""
    stop: StopSpec = StopSpec()
    """[stop]: settling criterion."""

    @model_validator(mode="after")
    def _consistent(self):
        if self.model.kinematics == "large" and self.mesh.element != "argyris":
            raise _rule(
                f"mesh.element = '{self.mesh.element}' cannot carry model.kinematics = 'large' "
                "(needs 'argyris')"
            )
        self._model_can_do_it()
        if self.load.kes is not None and self.mesh.kind != "strip":
            raise _rule(f"load.kes needs mesh.kind = 'strip' (got '{self.mesh.kind}')")
        if self.solver.quasi_static and self.stop.active:
            raise _rule(
                "stop.kinetic_energy / stop.kinetic_fraction need a dynamic run: "
                "solver.quasi_static = true has no kinetic energy"
            )
        if self.load.perturbation is not None and self.mesh.kind != "cusick":
            raise _rule(f"load.perturbation needs mesh.kind = 'cusick' (got '{self.mesh.kind}')")
        if self.case.analysis == "kes" and self.load.kes is None:
            raise _rule("case.analysis = 'kes' needs a [load.kes] drive")
        if self.case.analysis == "cycle" and (self.load.gravity is None
                                               or self.load.gravity.history is None):
            raise _rule("case.analysis = 'cycle' needs a load.gravity.history")
        if self.case.analysis == "cusick" and self.mesh.kind != "cusick":
            raise _rule(f"case.analysis = 'cusick' needs mesh.kind = 'cusick' (got '{self.mesh.kind}')")
        return self

    def _model_can_do_it(self):
        """Loads and supports each kinematics offers (plate: drape.plate, shell: drape.shell)."""
        load, model = self.load, self.model
        if model.kinematics == "large":
            for key, value in (("load.pressure", load.pressure), ("load.kes", load.kes)):
                if value is not None:
                    raise _rule(f"{key} is not available with model.kinematics = 'large'")
            for name, kind in model.supports.items():
                if kind not in ("clamped", "free"):
                    raise _rule(f"model.supports.{name} = '{kind}': the large-rotation model "
                                "offers only 'clamped' and 'free'")
            if not model.translational_inertia:
                raise _rule("model.translational_inertia = false needs model.kinematics = 'small'")
        else:
            if load.end_moment is not None:
                raise _rule("load.end_moment needs model.kinematics = 'large' (a follower moment)")
            if load.perturbation is not None:
                raise _rule("load.perturbation needs model.kinematics = 'large'")

    def boundary_names(self) -> dict[str, str]:
        """Every boundary name the case refers to, keyed by the dotted key that names it."""
        names = {f"model.supports.{b}": b for b in self.model.supports}
        if self.load.end_moment is not None:
            names["load.end_moment.boundary"] = self.load.end_moment.boundary
        if self.load.kes is not None:
            for i, end in enumerate(self.load.kes.ends):
                names[f"load.kes.ends[{i}]"] = end
        return names


# --------------------------------------------------------------------------- errors
_RULES = {
    "greater_than": "must be > {gt}",
    "greater_than_equal": "must be >= {ge}",
    "less_than": "must be < {lt}",
    "less_than_equal": "must be <= {le}",
    "int_type": "must be an integer",
    "int_from_float": "must be an integer",
    "float_type": "must be a number",
    "string_type": "must be a string",
    "bool_type": "must be true or false",
    "list_type": "must be an array",
    "dict_type": "must be a table",
    "model_type": "must be a table",
    "model_attributes_type": "must be a table",
    "missing": "is required",
    "string_pattern_mismatch": "must match {pattern}",
    "too_short": "needs at least {min_length} entries",
    "too_long": "takes at most {max_length} entries",
}


def _dotted(loc) -> str:
    parts = []
    for item in loc:
        if isinstance(item, int):
            parts[-1] = f"{parts[-1]}[{item}]" if parts else f"[{item}]"
        else:
            parts.append(str(item))
    return ".".join(parts)


_MESH_VARIANTS = {"strip": StripMesh, "rectangle": RectangleMesh, "cusick": CusickMesh,
                  "file": FileMesh}


def _model_at(loc) -> type[BaseModel] | None:
    """The pydantic model class owning the table at ``loc`` (None if it is not a table)."""
    cls: Any = Case
    for i, item in enumerate(loc):
        if isinstance(item, int) or cls is None:
            return None
        if i == 1 and loc[0] == "mesh":
            cls = _MESH_VARIANTS.get(item)  # union tag inserted by pydantic
            continue
        field = cls.model_fields.get(item)
        cls = None if field is None else _model_class(field.annotation)
    return cls


def _model_class(annotation):
    for arg in (annotation, *typing.get_args(annotation)):
        if isinstance(arg, type) and issubclass(arg, BaseModel):
            return arg
        if typing.get_origin(arg) is Annotated:
            found = _model_class(typing.get_args(arg)[0])
            if found is not None:
                return found
    return None


def _clean_loc(loc) -> tuple:
    # pydantic puts the union tag into the location (mesh.strip.length): drop it
    loc = list(loc)
    if len(loc) >= 2 and loc[0] == "mesh" and loc[1] in _MESH_VARIANTS:
        loc.pop(1)
    return tuple(loc)


def _format_error(err: dict) -> str:
    raw_loc = tuple(err["loc"])
    loc = _clean_loc(raw_loc)
    key = _dotted(loc)
    kind = err["type"]
    if kind == "extra_forbidden":
        owner = _model_at(raw_loc[:-1])
        known = list(owner.model_fields) if owner is not None else []
        guess = difflib.get_close_matches(str(loc[-1]), known, n=2, cutoff=0.7)
        hint = (" (did you mean " + " or ".join(f"'{g}'" for g in guess) + "?)") if guess else (
            f"; known keys: {', '.join(known)}" if known else "")
        return f"unknown key '{key}'{hint}"
    if kind in ("value_error", "assertion_error"):
        msg = str(err.get("ctx", {}).get("error", err["msg"]))
        prefix = key
        if "@" in msg:
            msg = msg.replace("@.", f"{prefix}." if prefix else "").replace("@", prefix or "case")
            return msg
        return f"{key} = {_show(err.get('input'))}: {msg}" if key else msg
    if kind == "union_tag_invalid":
        return (f"{key}.kind = {_show(err['ctx']['tag'])}: must be one of "
                f"{err['ctx']['expected_tags']}")
    if kind == "union_tag_not_found":
        return f"{key}.kind is required (one of strip, rectangle, cusick, file)"
    if kind == "literal_error":
        return f"{key} = {_show(err.get('input'))}: must be one of {err['ctx']['expected']}"
    if kind == "missing":
        return f"{key} is required"
    rule = _RULES.get(kind)
    if rule is not None:
        try:
            rule = rule.format(**err.get("ctx", {}))
        except (KeyError, IndexError):
            pass
    else:
        rule = err["msg"][0].lower() + err["msg"][1:]
    return f"{key} = {_show(err.get('input'))}: {rule}"


def _show(value) -> str:
    if isinstance(value, str):
        return repr(value)
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "{...}"
    return str(value)


# --------------------------------------------------------------------------- loading
def parse_case(data: dict, base_dir: Path | str | None = None) -> Case:
    """Validate a case dictionary (as read from TOML); raise :class:`CaseError` on any problem.

    Relative ``mesh.path`` / ``material.path`` are resolved against ``base_dir``.
    """
    try:
        case = Case.model_validate(data)
    except ValidationError as exc:
        lines = []
        for err in exc.errors(include_url=False):
            line = _format_error(err)
            if line not in lines:
                lines.append(line)
        raise CaseError("\n".join(lines)) from None
    if base_dir is not None:
        base = Path(base_dir)
        if case.mesh.kind == "file" and not Path(case.mesh.path).is_absolute():
            case.mesh.path = str((base / case.mesh.path).resolve())
        if case.material.path is not None and not Path(case.material.path).is_absolute():
            case.material.path = str((base / case.material.path).resolve())
    return case


def _toml_value(text: str):
    """A ``--set`` value: TOML if it parses as one, otherwise the bare string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def apply_overrides(data: dict, overrides: list[str] | None) -> None:
    """Apply ``key.sub=value`` overrides in place (values TOML-parsed, tables created)."""
    for item in overrides or []:
        if "=" not in item:
            raise CaseError(f"--set {item!r}: expected KEY=VALUE with a dotted KEY")
        key, text = item.split("=", 1)
        parts = [p.strip() for p in key.strip().split(".")]
        if not all(parts):
            raise CaseError(f"--set {item!r}: empty part in key {key!r}")
        node = data
        for i, part in enumerate(parts[:-1]):
            nxt = node.setdefault(part, {})
            if not isinstance(nxt, dict):
                raise CaseError(
                    f"--set {item!r}: '{'.'.join(parts[: i + 1])}' is a value, not a table"
                )
            node = nxt
        node[parts[-1]] = _toml_value(text.strip())


def load_case(path, overrides: list[str] | None = None) -> Case:
    """Read a TOML case file, apply ``--set`` overrides, validate.

    Raises
    ------
    CaseError
        Unreadable TOML or any schema violation (message names the key and the rule).
    """
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise CaseError(f"case file {str(path)!r} does not exist") from None
    except tomllib.TOMLDecodeError as exc:
        raise CaseError(f"{path}: not valid TOML ({exc})") from None
    apply_overrides(data, overrides)
    return parse_case(data, base_dir=path.parent)


def dump_case(case: Case) -> str:
    """The resolved case as TOML (defaults filled in, paths absolute); loads back to ``case``."""
    import tomli_w

    return tomli_w.dumps(case.model_dump(mode="json", exclude_none=True))


def check_boundaries(case: Case, mesh) -> None:
    """Every boundary the case names must exist on the mesh.

    >>> from skfem import MeshTri
    >>> mesh = MeshTri().with_boundaries({"left": lambda x: x[0] == 0})
    >>> case = parse_case({"case": {"name": "x"}, "mesh": {"kind": "rectangle", "length": 1.0,
    ...     "width": 1.0, "nx": 1, "ny": 1}, "material": {"name": "fabric1"},
    ...     "model": {"supports": {"lft": "clamped"}}, "solver": {"dt": 0.1, "t_end": 1.0}})
    >>> check_boundaries(case, mesh)
    Traceback (most recent call last):
    ...
    drape.case.CaseError: model.supports names boundary 'lft' which the mesh does not have; available: left
    """
    available = sorted((getattr(mesh, "boundaries", None) or {}).keys())
    for key, name in case.boundary_names().items():
        if name not in available:
            where = "model.supports" if key.startswith("model.supports.") else key
            raise CaseError(
                f"{where} names boundary '{name}' which the mesh does not have; "
                f"available: {', '.join(available) or '(none)'}"
            )


# --------------------------------------------------------------------------- documentation
def _type_name(annotation) -> str:
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin is Annotated:
        return _type_name(args[0])
    if origin is Literal:
        return " | ".join(repr(a).replace("'", '"') for a in args)
    if origin in (Union, getattr(__import__("types"), "UnionType")):
        names = [_type_name(a) for a in args if a is not type(None)]
        return " | ".join(names)
    if origin is list:
        return f"array of {_type_name(args[0])}" if args else "array"
    if origin is dict:
        return f"table of {_type_name(args[1])}" if args else "table"
    return {float: "number", int: "integer", str: "string", bool: "boolean"}.get(
        annotation, getattr(annotation, "__name__", str(annotation))
    )


def _default(field) -> str:
    if field.is_required():
        return "required"
    value = field.default
    if isinstance(value, BaseModel):
        return ""
    if value is None:
        return "optional"
    if isinstance(value, str):
        return f'default "{value}"'
    if isinstance(value, bool):
        return f"default {'true' if value else 'false'}"
    return f"default {value!r}"


def _describe(cls: type[BaseModel], prefix: str, lines: list[str]) -> None:
    doc = (cls.__doc__ or "").strip()
    head = doc.splitlines()[0] if doc else ""
    if head.startswith(f"[{prefix}]"):
        head = head[len(prefix) + 2:].lstrip(" :")
    lines.append(f"[{prefix}]" + (f"  {head}" if head else ""))
    for line in doc.splitlines()[1:]:
        if line.strip():
            lines.append(f"    {line.strip()}")
    nested = []
    for name, field in cls.model_fields.items():
        sub = _model_class(field.annotation)
        if sub is not None and sub not in (StripMesh,):
            nested.append((name, sub))
            continue
        default = _default(field)
        lines.append(f"  {name} : {_type_name(field.annotation)}" + (f"  ({default})" if default else ""))
        for line in (field.description or "").strip().splitlines():
            lines.append(f"      {line.strip()}")
    lines.append("")
    for name, sub in nested:
        _describe(sub, f"{prefix}.{name}", lines)


def describe_schema() -> str:
    """Every table and key of a case file with its type, default and meaning (``--help-case``).

    >>> text = describe_schema()
    >>> "[solver]" in text and "  dt : number  (required)" in text
    True
    """
    lines = [
        "Case file schema (TOML). Numbers are SI; a dimensional number may also be a string",
        'with units, e.g. length = "5 cm". Unknown keys are errors.',
        "",
    ]
    lines.append("[case]  what this run is.")
    for name, field in CaseInfo.model_fields.items():
        lines.append(f"  {name} : {_type_name(field.annotation)}  ({_default(field)})")
        for line in (field.description or "").strip().splitlines():
            lines.append(f"      {line.strip()}")
    lines.append("")
    lines.append("[mesh]  geometry; the keys depend on kind:")
    for variant in (StripMesh, RectangleMesh, CusickMesh, FileMesh):
        lines.append(f"  {(variant.__doc__ or '').strip()}")
        for name, field in variant.model_fields.items():
            if name == "kind":
                continue
            lines.append(f"    {name} : {_type_name(field.annotation)}  ({_default(field)})")
            for line in (field.description or "").strip().splitlines():
                lines.append(f"        {line.strip()}")
    lines.append("")
    for name in ("material", "model", "load", "solver", "output", "stop"):
        _describe(_model_class(Case.model_fields[name].annotation), name, lines)
    return "\n".join(lines).rstrip() + "\n"

