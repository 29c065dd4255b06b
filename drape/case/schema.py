"""The tables of a case file other than ``[load]``: their keys, units, defaults and rules.

Every table rejects unknown keys. Numbers are SI (m, kg, s, N); any dimensional number may
instead be written as a string with units (``length = "5 cm"``), converted with pint. A key's
docstring is its documentation (``python -m drape.run --help-case``). The ``[load]`` tables
are in :mod:`drape.case.loads`, ``[mesh]`` in :mod:`drape.case.mesh_tables`, ``[material]`` in
:mod:`drape.case.material_tables`; the whole case and its cross-table rules in :mod:`drape.case.case`.
"""
from __future__ import annotations

import re
from typing import Annotated, Literal, Union

from pydantic import (
    Field,
    PlainValidator,
    WithJsonSchema,
    field_validator,
    model_validator,
)

from drape.analyses import ANALYSES
from drape.case.quantities import Q, _quantity, _rule, _Section

__all__ = ['CaseInfo', 'Damping', 'Membrane', 'ModelSpec', 'SolverSpec', 'OutputSpec', 'MeasuredSpec', 'DEFAULT_OUT_OF_BALANCE', 'StopSpec']


# --------------------------------------------------------------------------- [case]
class CaseInfo(_Section):
    """[case]: what this run is."""

    name: str
    """File stem of the outputs (``<name>_NNNN.vtu``, ``<name>.pvd``) and the default output
    folder ``out/<name>``: letters, digits, ``_.-``, starting with a letter or digit."""
    description: str = ""
    """Free text, copied into summary.json."""
    analysis: str = "none"
    """Post-processing after the run: ``peirce`` (cantilever bending length), ``cusick``
    (drape coefficient and folds), ``kes`` (B and 2HB of the simulated moment-curvature loop),
    ``cycle`` (probe displacements at every point of load.gravity.history: the residual
    deformation friction leaves after unloading), ``none``."""

    @field_validator("name")
    @classmethod
    def _plain_file_name(cls, value):  # it names files and the default folder out/<name>
        if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,99}", value):
            raise ValueError("must be a plain file name of at most 100 letters, digits, '_', '.' "
                             "or '-', starting with a letter or digit (no '/', no '..')")
        return value

    @field_validator("analysis")
    @classmethod
    def _known_analysis(cls, value):  # the registry is read at validation: scripts may add to it

        if value not in ANALYSES:
            raise ValueError(f"must be one of {', '.join(repr(a) for a in ANALYSES)}")
        return value


# --------------------------------------------------------------------------- [mesh]


class RigidityVariationSpec(_Section):
    """[model.rigidity_variation]: the specimen's bending rigidity varying from place to place,
    a seeded log-normal field of mean 1 on the bending moment (elastic and friction together,
    so 2HB/B stays; drape/models/rigidity.py); large kinematics only."""

    cv: float = Field(ge=0, le=1)
    """Coefficient of variation of the rigidity over the specimen (0: uniform)."""
    correlation_length: Q("m", gt=0)
    """Length ℓ over which the rigidity stays alike, e.g. "2 cm"."""
    seed: int | None = Field(None, ge=0)
    """Seed of the field: another seed, another specimen. Absent: the seed of
    [load.perturbation] (else 0), so that one seed is one specimen, its imperfections
    together (the seed ensembles and sweeps vary both)."""


class Damping(_Section):
    """[model.damping]: Rayleigh damping C = (alpha + air_drag / areal mass) M + beta K0
    (added to the law's own d), or with drag_coefficient still air's quadratic drag."""

    alpha: Q("1/s", ge=0) = 0.0
    """Mass-proportional coefficient [1/s]."""
    air_drag: Q("N*s/m^3", ge=0) = 0.0
    """Linear air drag: a force −c v per unit area of fabric [N·s/m³], the same for every
    fabric; it enters as the mass-proportional coefficient c / areal mass."""
    beta: Q("s", ge=0) = 0.0
    """Stiffness-proportional coefficient [s] (K0: tangent stiffness at rest)."""
    drag_coefficient: float = Field(0.0, ge=0)
    """C_d of still air's quadratic drag ½ ρ_air C_d |v·n| v·n per unit area, normal to the
    deformed fabric (flat plate broadside: 1.2); large kinematics only. 0: none."""

    @model_validator(mode="after")
    def _one_air_drag(self):
        if self.air_drag and self.drag_coefficient:
            raise _rule("@: give air_drag (linear) or drag_coefficient (quadratic), not both")
        return self


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


def _membrane_tension(value):
    """``auto``, ``secant``, or a positive tension in N/m (a number, or a string with units)."""
    if value in ("auto", "secant"):
        return value
    rule = "must be 'auto', 'secant' or a tension > 0 (a number in N/m or a string like '0.05 N/m')"
    try:
        tension = _quantity("N/m").func(value)
    except ValueError as err:
        raise ValueError(f"{rule}; {err}") from None
    if isinstance(tension, bool) or not isinstance(tension, (int, float)) or not tension > 0:
        raise ValueError(rule)
    return float(tension)


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
    membrane_tension: Annotated[Union[Literal["auto", "secant"], float], PlainValidator(_membrane_tension),
                                WithJsonSchema({"anyOf": [{"enum": ["auto", "secant"]},
                                                          {"type": "number"}]})] = "auto"
    """Large kinematics: the tension [N/m] at which E11 and E22 are taken on the fabric's
    tensile curve (a KES sheet's EMT, LT, WT, else the default curve; a stiffness given as a
    number is kept). ``auto``: on a Cusick mesh the mean tension of the hanging skirt
    (ρ_A g (2R + r_d)(R − r_d) / (3 (R + r_d)), about 0.05 N/m), elsewhere ``secant``;
    ``secant``: the linear stiffness that stores the KES test's energy (default 1e4 N/m)."""
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

    rigidity_variation: RigidityVariationSpec | None = None
    """The specimen's rigidity varying from place to place (see [model.rigidity_variation]);
    absent: uniform."""

    bending_friction: Literal["tensor", "per_direction"] = "tensor"
    """Large kinematics: how the bending law's dry friction sees the curvature. ``tensor``:
    one frame-invariant law on the curvature tensor, which is each direction's law where the
    fabric bends along a yarn (KES-FB, Peirce), so B and 2HB calibrate it as before;
    ``per_direction``: each direction's law on its own curvature, twist frictionless (a sheet
    with equal warp and weft is then square-symmetric; docs/theory.md §2)."""

    friction_tangent: Literal["consistent", "nonnegative", "stick"] = "consistent"
    """Newton's tangent of the friction moment: ``nonnegative`` floors it at zero where the
    law softens (the moment falls with curvature after a reversal, e.g. Fabric 2's weft as
    printed: −51 k1), which otherwise sends Newton off. The solution is unchanged."""

    viscous_tangent: Literal["symmetric", "full"] = "symmetric"
    """Large kinematics, laws with viscosity d (or curvature inertia m): Newton's tangent of
    ``d κ̇ + m κ̈``. ``symmetric`` keeps the symmetric part of K (the rate terms' configuration
    dependence is the only unsymmetric one), so a symmetric factorisation serves;
    ``full``: the exact, unsymmetric tangent. The solution is unchanged."""

    @model_validator(mode="after")
    def _membrane_needs_large(self):
        if self.membrane_stabilization and self.membrane_strain_degree is None:
            raise _rule("@.membrane_stabilization needs @.membrane_strain_degree")
        # options of the large-rotation shell, against their defaults
        for key, default in (("membrane", None), ("membrane_strain_degree", None),
                             ("viscous_tangent", "symmetric"), ("membrane_tension", "auto"),
                             ("bending_friction", "tensor"), ("rigidity_variation", None)):
            if getattr(self, key) != default and self.kinematics != "large":
                raise _rule(
                    f"@.{key} is only used with @.kinematics = 'large' (got '{self.kinematics}')"
                )
        return self


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
    tangent_reuse: float = Field(0.5, ge=0, lt=1)
    """Newton keeps its factorised tangent for the next iteration, and the next step of the same
    size, while each full step contracts the correction by at least this factor (modified
    Newton: an iteration then costs a residual and a back-substitution, not a tangent's assembly
    and factorisation); a kept tangent that contracts less is replaced at once. 0: a fresh
    tangent every iteration."""
    max_cuts: int = Field(6, ge=0)
    """Step halvings before the run stops with a convergence error."""
    error_tolerance: float | None = Field(None, gt=0, lt=1)
    """Step size from the local error estimate ``|β − 1/6| Δt² ‖a₁ − a₀‖`` (Zienkiewicz & Xie
    1991), kept below this fraction of ``‖u‖``: the step grows where the motion is smooth and
    shrinks where it changes fast; absent: the step is cut only when Newton fails and grows
    back after 4 converged steps."""
    linear_solver: Literal["auto", "pardiso", "superlu"] = "auto"
    """Direct solver of Newton's systems: MKL PARDISO (``pypardiso``, x86-64), SciPy's SuperLU,
    or ``auto`` (PARDISO where it loads)."""
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


# --------------------------------------------------------------------------- [measured]
class MeasuredSpec(_Section):
    """[measured]: what the real test of this specimen gave, for comparison. Not used by the
    run; copied into summary.json and shown beside the simulated values by ``drape.batch.validation_set``."""

    DC_percent: float | None = Field(None, ge=0, le=100)
    """Measured drape coefficient [%] (the mean over the specimens tested)."""
    nodes: int | None = Field(None, ge=0)
    """Measured number of nodes (folds)."""
    source: str = ""
    """Where the measured values come from (publication, table)."""
    setup: str = ""
    """How they were measured (tester, specimen and disc diameters, standard)."""


# --------------------------------------------------------------------------- [stop]
#: Default ``stop.out_of_balance``: the static out-of-balance force, as a fraction of the weight,
#: below which a run counts as settled. Measured (BENCHMARKS.md, "Settling rule"): a creeping
#: viscous strip's tip is short of rest by about this fraction (0.1 %); Fabric 1's Cusick drape
#: lingers in an unbalanced 9-node state whose out-of-balance never falls below 1.9e-3.
DEFAULT_OUT_OF_BALANCE = 1e-3


class StopSpec(_Section):
    """[stop]: end a dynamic run early once the fabric has settled (:mod:`drape.run.settling`)."""

    out_of_balance: float = Field(DEFAULT_OUT_OF_BALANCE, ge=0, lt=1)
    """Settled when the static out-of-balance force (internal + friction − external, without
    inertia and viscous terms; norm over the free dofs) falls below this fraction of the weight
    (norm of the self-weight force vector). 0: never stop early, run to t_end."""
    after: Q("s", ge=0) | None = None
    """Check only after this time [s]; default: when the loads stop changing and the contact
    bodies stop moving."""
    steps: int = Field(5, ge=1)
    """Consecutive converged steps that must satisfy the rule."""

    @model_validator(mode="before")
    @classmethod
    def _kinetic_rule_removed(cls, data):
        for key in ("kinetic_energy", "kinetic_fraction"):
            if isinstance(data, dict) and key in data:
                raise ValueError(
                    f"@.{key} is no longer read: a run settles when the static out-of-balance "
                    f"force is small, not the kinetic energy; write @.out_of_balance = <fraction "
                    f"of the weight> instead (default {DEFAULT_OUT_OF_BALANCE:g})")
        return data

    @property
    def active(self) -> bool:
        return self.out_of_balance > 0
