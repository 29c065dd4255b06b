"""Run a case file: ``python -m drape.run CASE.toml [--out DIR] [--set key=value ...]``.

The runner only wires parts together: mesh (:mod:`meshes`) → material
(:mod:`constitutive.material`) → structural model (:class:`drape.plate.KirchhoffPlate`
for ``kinematics = "small"``, :class:`drape.shell.KirchhoffLoveShell` for ``"large"``) →
integrator (:func:`drape.newmark.integrate` or :func:`drape.newmark.quasi_static`) →
writer (:class:`drape.output.OutputWriter`). Every converged step is appended to
``history.csv``; output steps are written as VTU with the PVD index rewritten each time, so a
run that stops early (no convergence, Ctrl-C) leaves everything up to its last converged step.

Exit codes: 0 completed or settled, 1 bad input (case file, material, mesh), 2 the integrator
failed to converge (``summary.json`` has ``status = "failed"`` and the reason), 130 interrupted.
Any other error during the integration also leaves ``summary.json`` (``status = "error"``).

After the run a case-specific analysis (``[case] analysis``) adds its results to
``summary.json``; analyses live in :data:`ANALYSES` and new ones are added with
:func:`register_analysis`.
"""
from __future__ import annotations

import argparse
import inspect
import logging
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from constitutive.units import G0

from drape import case as case_module
from drape.case import Case, CaseError, check_boundaries, describe_schema, dump_case, load_case
from drape.output import OutputSchedule, OutputWriter

__all__ = ["RunContext", "Analysis", "ANALYSES", "register_analysis", "unregister_analysis", "build",
           "run_case", "main"]

log = logging.getLogger("drape.run")

#: Standard gravity [m/s²] (CONVENTIONS.md).
G_STANDARD = G0


class RunInputError(ValueError):
    """Something the case names cannot be built (material, mesh file, boundary, option)."""


# --------------------------------------------------------------------------- analyses
@dataclass
class RunContext:
    """What an analysis sees: the case, the built parts, the final state and the history."""

    case: Case
    mesh: Any
    material: Any
    model: Any
    out_dir: Path
    state: Any = None
    history: list[dict] = field(default_factory=list)

    def fields(self) -> dict:
        """Model output fields of the final state (flat ``name -> array``)."""
        s = self.state
        return flatten_fields(self.model.fields(s.u, s.v, s.a))


@dataclass
class Analysis:
    """A post-processing hook.

    ``probe(ctx, fields)`` returns extra scalar history columns for every converged step
    (``fields`` are the flat model fields of that step); ``finish(ctx)`` returns the entries that
    go under ``summary["analysis"]``.
    """

    name: str
    finish: Callable[[RunContext], dict]
    probe: Callable[[RunContext, dict], dict] | None = None


#: Registered analyses by ``[case] analysis`` name.
ANALYSES: dict[str, Analysis] = {}


def register_analysis(name: str, probe=None):
    """Decorator registering ``finish(ctx) -> dict`` as analysis ``name`` (with an optional probe).

    >>> @register_analysis("demo")
    ... def _demo(ctx):
    ...     return {"answer": 42}
    >>> ANALYSES["demo"].finish(None)
    {'answer': 42}
    >>> unregister_analysis("demo")
    """

    def wrap(finish):
        ANALYSES[name] = Analysis(name, finish, probe)
        if name not in case_module.ANALYSES:
            case_module.ANALYSES.append(name)
        return finish

    return wrap


def unregister_analysis(name: str) -> None:
    """Remove analysis ``name`` (registered with :func:`register_analysis`)."""
    del ANALYSES[name]
    case_module.ANALYSES.remove(name)


register_analysis("none")(lambda ctx: {})


def _mean_component(fields: dict, names: tuple[str, ...]) -> float:
    for name in names:
        if name in fields:
            return float(np.mean(fields[name]))
    raise KeyError(f"the model gives none of the fields {names}")


def _kes_probe(ctx: RunContext, fields: dict) -> dict:
    # uniform curvature along a pure-bending strip: the mean over cells is the material value
    return {
        "kappa": _mean_component(fields, ("curvature_xx",)),
        "moment": _mean_component(fields, ("moment_xx",)),
    }


@register_analysis("kes", probe=_kes_probe)
def _kes_finish(ctx: RunContext) -> dict:
    """B and 2HB of the simulated moment–curvature loop (constitutive.kes.kes_values).

    Beside them: the same values from the constitutive driver (``run_kes`` on the warp law,
    profile sampled at the run's step times) and the largest moment difference between the two
    along the loop, relative to the largest moment — FE and law must agree.
    """
    from constitutive.kes import kes_profile, kes_values, run_kes
    from constitutive.units import to_kes

    t = np.array([row["t"] for row in ctx.history])
    kappa = np.array([row["kappa"] for row in ctx.history])
    moment = np.array([row["moment"] for row in ctx.history])
    values = kes_values(kappa, moment)
    drive = ctx.case.load.kes
    profile = kes_profile(t=np.clip(t, 0.0, drive.duration()), **drive.profile_kwargs())
    loop = run_kes(ctx.material.warp, profile)
    driver = kes_values(loop.kappa, loop.moment)
    return {"B": values.B, "HB2": values.HB2,
            "B_kes_gf_cm2_per_cm": to_kes(values.B, "B"),
            "HB2_kes_gf_cm_per_cm": to_kes(values.HB2, "HB2"),
            "sides": _plain(values),
            "driver_B": driver.B, "driver_HB2": driver.HB2,
            "max_moment_difference_rel": float(np.max(np.abs(moment - loop.moment))
                                               / np.max(np.abs(loop.moment)))}


@register_analysis("cycle")
def _cycle_finish(ctx: RunContext) -> dict:
    """Probe displacements at every point of the gravity history table (load levels reached).

    At a zero level after loading, what is left is the residual deformation: held by friction
    in a quasi-static run (plus unrecovered viscous creep in a dynamic one).
    """
    gravity = ctx.case.load.gravity
    rows = ctx.history
    times = np.array([row["t"] for row in rows])
    points = []
    for t, level in gravity.history:
        if t > times[-1] + 1e-9 * max(1.0, abs(t)):
            break
        row = rows[int(np.argmin(np.abs(times - t)))]
        points.append({"t": row["t"], "gravity_factor": gravity.factor * level,
                       **{k: v for k, v in row.items() if k.startswith(("tip_", "centre_", "uz_"))}})
    loaded = False
    residual = []
    for point in points:
        if loaded and point["gravity_factor"] == 0:
            residual.append(point)
        loaded = loaded or point["gravity_factor"] != 0
    return {"levels": points, "residual_after_unloading": residual}


@register_analysis("peirce")
def _peirce_finish(ctx: RunContext) -> dict:
    """Peirce / ASTM D1388 summary of a settled cantilever strip (drape.peirce).

    The strip overhangs from its clamped boundary to ``free_end``; B_KES is the slope of the
    simulated KES-FB loop of the material's law along the strip (warp for a strip along x).
    """
    from drape import peirce

    if ctx.case.mesh.kind != "strip":
        raise RunInputError("case.analysis = 'peirce' needs mesh.kind = 'strip'")
    clamped = [b for b, kind in ctx.case.model.supports.items() if kind == "clamped"]
    if len(clamped) != 1:
        raise RunInputError("case.analysis = 'peirce' needs exactly one clamped boundary")
    s = ctx.state
    if hasattr(ctx.model, "nodal_displacement"):
        # the shell picks the warp or weft B from the strip's direction
        out = peirce.shell_peirce_summary(ctx.model, s.u, clamped=clamped[0], free="free_end")
    else:
        B_kes = float(ctx.material.simulated_kes()["warp"].B)   # plate strips run along x (warp)
        gravity = ctx.case.load.gravity
        W = ctx.material.areal_mass * G_STANDARD * (
            0.0 if gravity is None else gravity.factor * gravity.amplitude(s.t))
        out = peirce.peirce_summary(ctx.mesh, ctx.fields()["displacement"], W, B_kes=B_kes,
                                    clamped=clamped[0], free="free_end")
    return _plain(out)


@register_analysis("cusick")
def _cusick_finish(ctx: RunContext) -> dict:
    """Drape coefficient, nodes and top view of a settled Cusick specimen (drape.cusick)."""
    from drape.cusick import cusick_post

    spec = ctx.case.mesh
    table = {"specimen_diameter": spec.specimen_diameter, "disc_diameter": spec.disc_diameter}
    # the shadow of the computed surface, not of its vertex triangles (large kinematics)
    sample = getattr(ctx.model, "deformed_surface", None)
    out = cusick_post(ctx.mesh, ctx.fields()["displacement"], table, ctx.out_dir,
                      name=ctx.case.case.name,
                      surface=None if sample is None else sample(ctx.state.u))
    return _plain(out)


def _plain(obj):
    """Summary-friendly copy: dataclasses and mappings to dicts, numpy to Python."""
    import dataclasses

    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        obj = dataclasses.asdict(obj)
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if hasattr(obj, "_asdict"):
        return _plain(obj._asdict())
    return obj


# --------------------------------------------------------------------------- fields
_COMPONENTS = {3: ("xx", "yy", "xy"), 2: ("xx", "yy")}


def flatten_fields(fields: dict) -> dict:
    """Model fields as one flat ``name -> array`` dict.

    Accepts ``{"point_data": ..., "cell_data": ...}`` or a flat dict; cell data given as
    ``(n_cells, 3)`` tensors (``curvature``, ``moment``) or ``(n_cells, 2)`` pairs
    (``friction_moment``) are split into ``_xx``, ``_yy`` (``_xy``) scalars so that every model
    writes the same names.

    >>> f = flatten_fields({"point_data": {"displacement": np.zeros((4, 3))},
    ...                     "cell_data": {"moment": np.ones((2, 3))}})
    >>> sorted(f)
    ['displacement', 'moment_xx', 'moment_xy', 'moment_yy']
    """
    if "point_data" in fields or "cell_data" in fields:
        flat = dict(fields.get("point_data", {}))
        cells = dict(fields.get("cell_data", {}))
    else:
        flat, cells = {}, dict(fields)
    for name, value in cells.items():
        arr = np.asarray(value)
        if (name not in ("displacement", "velocity", "acceleration") and arr.ndim == 2
                and arr.shape[1] in _COMPONENTS):
            for i, suffix in enumerate(_COMPONENTS[arr.shape[1]]):
                flat[f"{name}_{suffix}"] = arr[:, i]
        else:
            flat[name] = arr
    return flat


def _probe_point(case: Case, mesh) -> int | None:
    """Vertex whose displacement goes into history.csv as tip_* (strip) or centre_* (rectangle)."""
    spec = case.mesh
    if spec.kind == "strip":
        target = np.array([mesh.p[0].max(), 0.5 * (mesh.p[1].min() + mesh.p[1].max())])
    elif spec.kind == "rectangle":
        target = 0.5 * (mesh.p.min(axis=1) + mesh.p.max(axis=1))
    else:
        return None
    return int(np.argmin(np.linalg.norm(mesh.p.T - target, axis=1)))


def _probes(case: Case, mesh, fields: dict, vertex: int | None) -> dict:
    u = np.asarray(fields["displacement"])
    out = {"uz_min": float(u[:, 2].min()), "uz_max": float(u[:, 2].max())}
    if vertex is not None:
        label = "tip" if case.mesh.kind == "strip" else "centre"
        out.update({f"{label}_ux": float(u[vertex, 0]), f"{label}_uz": float(u[vertex, 2])})
    return out


# --------------------------------------------------------------------------- building
def build_mesh(case: Case):
    """The reference mesh described by ``[mesh]`` (boundaries named by :mod:`meshes`)."""
    import meshes

    try:
        mesh = _make_mesh(case.mesh)
    except RunInputError:
        raise
    except ValueError as err:
        raise RunInputError(f"mesh: {err}") from None
    check_boundaries(case, mesh)
    return mesh


def _make_mesh(spec):
    import meshes

    if spec.kind == "strip":
        mesh = meshes.strip(spec.length, spec.width, spec.nx, spec.ny)
    elif spec.kind == "rectangle":
        mesh = meshes.rectangle(spec.length, spec.width, spec.nx, spec.ny)
    elif spec.kind == "cusick":
        mesh = meshes.cusick_annulus(spec.specimen_diameter, spec.disc_diameter,
                                     n_radial=spec.n_radial,
                                     n_circumferential=spec.n_circumferential,
                                     target_size=spec.target_size, refine=spec.refine,
                                     radial_grading=spec.radial_grading)
    else:
        try:
            mesh = meshes.load_mesh(spec.path, scale=spec.scale)
        except FileNotFoundError:
            raise RunInputError(f"mesh.path = {spec.path!r}: file not found") from None
        except ValueError as err:
            raise RunInputError(f"mesh.path = {spec.path!r}: {err}") from None
    return mesh


def build_material(case: Case):
    """The fabric of ``[material]`` with the case's overrides applied (SI)."""
    from constitutive.material import KesSpec, MaterialSpec, load_material, material_from_spec

    spec = case.material
    if spec.kes is not None:
        # the same builder (and KES -> SI conversion) as a material file's [kes] table
        k = spec.kes.model_dump()
        weight, thickness = k.pop("weight"), k.pop("thickness")
        material = material_from_spec(MaterialSpec(
            name=case.case.name, description=case.case.description, source="case file [material.kes]",
            weight=weight, thickness=thickness, kes=KesSpec(**k)), where="material.kes")
    else:
        material = load_material(spec.name if spec.name is not None else spec.path)
    changes = {}
    for direction in ("warp", "weft"):
        over = spec.law_overrides(direction)
        law = getattr(material, direction)
        if over or not spec.friction:
            law = _override_law(law, over, spec.friction, direction)
        if spec.bending_scale != 1.0:
            law = law.scaled(spec.bending_scale)
        if law is not getattr(material, direction):
            changes[direction] = law
    for key, value in (("areal_mass", spec.areal_mass), ("thickness", spec.thickness),
                       ("twist_rigidity", case.model.twist_rigidity)):
        if value is not None:
            changes[key] = value
    if case.model.membrane is not None:
        changes.update(case.model.membrane.model_dump(exclude_none=True))
    if not changes:
        return material
    try:
        return material.replace(**changes)
    except ValueError as err:
        raise RunInputError(f"material after the case's overrides: {err}") from None


_FRICTION_KEYS = ("f1", "f2", "eps_f", "eta")


def _override_law(law, over: dict, friction: bool, direction: str):
    """``law`` with the overridden parameters (and friction dropped if ``friction`` is False)."""
    import dataclasses

    from constitutive.friction import FrictionParams

    over = dict(over)
    new_friction = {k: over.pop(k) for k in _FRICTION_KEYS if k in over}
    fr = law.friction
    try:
        if not friction:
            fr = None
        elif new_friction:
            base = {} if fr is None else {k: getattr(fr, k) for k in _FRICTION_KEYS}
            base.update(new_friction)
            missing = [k for k in _FRICTION_KEYS if k not in base]
            if missing:
                raise RunInputError(
                    f"material.{direction}: the material has no friction, so an override must give "
                    f"all of f1, f2, eps_f, eta (missing {', '.join(missing)})")
            fr = FrictionParams(**base)
        return dataclasses.replace(law, friction=fr, **over)
    except RunInputError:
        raise
    except ValueError as err:
        raise RunInputError(f"material.{direction} after the case's overrides: {err}") from None


def load_amplitudes(case: Case) -> dict[str, Callable[[float], float]]:
    """Time functions of the loads: ``gravity`` (factor), ``pressure`` [Pa], ``end_moment`` [N]."""
    load = case.load
    out: dict[str, Callable[[float], float]] = {}
    if load.gravity is not None:
        g = load.gravity
        out["gravity"] = lambda t, g=g: g.factor * g.amplitude(t)
    if load.pressure is not None:
        p = load.pressure
        out["pressure"] = lambda t, p=p: p.value * p.amplitude(t)
    if load.end_moment is not None:
        m = load.end_moment
        out["end_moment"] = lambda t, m=m: m.value * m.amplitude(t)
    return out


def kes_curvature(case: Case) -> Callable[[float], tuple[float, float, float]]:
    """``t -> (κ, κ̇, κ̈)`` of the KES-FB profile of ``[load.kes]`` (constitutive.kes.kes_profile).

    The exact rates let the plate lift the imposed motion exactly, so the law's d κ̇ and m κ̈
    see the profile's rates, not Newmark's estimates of them.
    """
    from constitutive.kes import kes_profile

    kwargs = case.load.kes.profile_kwargs()
    t_end = case.load.kes.duration()

    def kappa(t: float) -> tuple[float, float, float]:
        if t >= t_end:  # the test is over: held at its final value (0), at rest
            p = kes_profile(t=[t_end], **kwargs)
            return float(p.kappa[0]), 0.0, 0.0
        p = kes_profile(t=[max(t, 0.0)], **kwargs)
        return float(p.kappa[0]), float(p.kappa_dot[0]), float(p.kappa_ddot[0])

    return kappa


def build_model(case: Case, mesh, material):
    """The structural model for ``[model] kinematics`` with supports, loads and damping."""
    spec = case.model
    loads = load_amplitudes(case)
    rayleigh = (spec.damping.alpha, spec.damping.beta)
    if spec.kinematics == "small":
        from drape.plate import KirchhoffPlate, pure_bending_rotations

        rotations = None
        if case.load.kes is not None:
            rotations = pure_bending_rotations(kes_curvature(case), case.mesh.length,
                                               ends=tuple(case.load.kes.ends))
        return KirchhoffPlate(
            mesh, material, element=case.mesh.element, supports=dict(spec.supports),
            rotations=rotations, gravity=loads.get("gravity", 0.0),
            pressure=loads.get("pressure", 0.0), rayleigh=rayleigh,
            translational_inertia=spec.translational_inertia,
            friction_tangent=spec.friction_tangent,
        )
    from drape.shell import KirchhoffLoveShell

    # what the shell cannot do is rejected by the case schema (drape.case.Case._consistent)
    clamped = tuple(b for b, kind in spec.supports.items() if kind == "clamped")
    kwargs = {}
    fold = fold_perturbation(case)
    if fold is not None and fold.target == "force":
        weight = float(material.areal_mass) * G_STANDARD
        kwargs.update(surface_load=(lambda x: fold.traction(x, weight), fold.time_profile))
    if case.load.end_moment is not None:
        kwargs.update(end_moment=loads["end_moment"], load_boundary=case.load.end_moment.boundary)
    return KirchhoffLoveShell(mesh, material, clamped=clamped,
                              gravity=loads.get("gravity", 0.0), rayleigh=rayleigh,
                              membrane_strain_degree=spec.membrane_strain_degree,
                              membrane_stabilization=spec.membrane_stabilization,
                              friction_tangent=spec.friction_tangent, **kwargs)


def fold_perturbation(case: Case):
    """The ``[load.perturbation]`` field (``drape.perturbation.FoldPerturbation``) or None."""
    p = case.load.perturbation
    if p is None or p.kind == "none":
        return None
    from drape.perturbation import FoldPerturbation

    return FoldPerturbation(disc_radius=0.5 * case.mesh.disc_diameter,
                            specimen_radius=0.5 * case.mesh.specimen_diameter, **p.model_dump())


def initial_fields(case: Case, model):
    """Initial (u0, v0): zero, or the fold perturbation of target displacement / velocity.

    The perturbation (``drape.perturbation.FoldPerturbation``) is interpolated on the model's
    basis (``model.basis``); target "force" is a load (:func:`build_model`), not a start.
    """
    fold = fold_perturbation(case)
    if fold is None or fold.target == "force":
        return None, None
    from drape.perturbation import perturbation_dofs

    if not hasattr(model, "basis"):
        raise RunInputError("load.perturbation needs a model with a `basis` (the large-rotation shell)")
    x0 = perturbation_dofs(model.basis, fold)
    return (x0, None) if fold.target == "displacement" else (None, x0)


# --------------------------------------------------------------------------- running
class _Settling:
    """[stop] rule: kinetic energy below the threshold for ``steps`` consecutive steps."""

    def __init__(self, case: Case, threshold: float | None):
        self.threshold = threshold
        stop = case.stop
        self.after = stop.after if stop.after is not None else case.load.end_time()
        self.needed = stop.steps
        self.count = 0

    def __call__(self, t: float, kinetic: float) -> bool:
        if self.threshold is None or t < self.after:
            return False
        self.count = self.count + 1 if kinetic < self.threshold else 0
        return self.count >= self.needed


def settling_threshold(case: Case, mesh, material) -> float | None:
    """Kinetic-energy threshold [J] of ``[stop]``: absolute, or a fraction of ρ_A g A L.

    A is the fabric's (mesh) area, L its span: strip/rectangle length, Cusick overhang (then
    ρ_A g A L is ``drape.cusick.kinetic_energy_threshold``'s reference), else the largest extent.
    """
    stop = case.stop
    if stop.kinetic_energy is not None:
        return stop.kinetic_energy
    if stop.kinetic_fraction is None:
        return None
    spec = case.mesh
    if spec.kind == "cusick":
        span = 0.5 * (spec.specimen_diameter - spec.disc_diameter)
    elif spec.kind in ("strip", "rectangle"):
        span = spec.length
    else:
        span = float(np.ptp(mesh.p, axis=1).max())
    area = float(np.sum(mesh_areas(mesh)))
    return stop.kinetic_fraction * float(material.areal_mass) * G_STANDARD * area * span


def mesh_areas(mesh) -> np.ndarray:
    """Triangle areas of an ``skfem.MeshTri`` (:func:`meshes.quality.triangle_areas`, unsigned).

    >>> from skfem import MeshTri
    >>> float(mesh_areas(MeshTri()).sum())
    1.0
    """
    from meshes.quality import triangle_areas
    return np.abs(triangle_areas(mesh.p, mesh.t))


def _setup_logging(out_dir: Path) -> logging.Handler:
    handler = logging.FileHandler(out_dir / "run.log", mode="w")
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    root = logging.getLogger("drape")
    root.setLevel(logging.INFO)
    root.addHandler(handler)
    return handler


@dataclass
class Parts:
    """The built pieces of a case."""

    mesh: Any
    material: Any
    model: Any


def build(case: Case) -> Parts:
    """Mesh → material → model for ``case`` (raises CaseError / ValueError on bad input)."""
    mesh = build_mesh(case)
    log.info("mesh: %d vertices, %d triangles, boundaries %s", mesh.p.shape[1],
             mesh.t.shape[1], sorted(mesh.boundaries or {}))
    material = build_material(case)
    model = build_model(case, mesh, material)
    log.info("model: %s with %d dofs (%d fixed)", type(model).__name__, model.ndofs,
             len(model.fixed_dofs))
    return Parts(mesh, material, model)


def run_case(case: Case, out_dir, quiet: bool = False, parts: Parts | None = None,
             source: str = "") -> dict:
    """Run ``case`` writing into ``out_dir``; return the summary (also in ``summary.json``).

    ``parts`` replaces the built mesh/material/model (tests, scripts that build their own);
    ``source`` (where the case came from) heads ``case.resolved.toml`` as a comment.

    Raises
    ------
    CaseError, ValueError
        When the case cannot be built (nothing is integrated then).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    handler = _setup_logging(out_dir)
    try:
        header = "# Resolved case: every key with its value (SI units), as run.\n"
        if source:
            header += "".join(f"# {line}\n" for line in source.splitlines())
        (out_dir / "case.resolved.toml").write_text(header + dump_case(case))
        log.info("case %s: %s", case.case.name, case.case.description)
        wall0 = time.perf_counter()
        parts = build(case) if parts is None else parts
        return _simulate(case, parts, out_dir, quiet, wall0)
    except Exception:
        log.exception("run aborted")
        raise
    finally:
        logging.getLogger("drape").removeHandler(handler)
        handler.close()


class _Recorder:
    """The integrator's ``on_step``: history row, VTU when due, progress, settling check."""

    def __init__(self, case: Case, ctx: RunContext, writer: OutputWriter, bar):
        self.case, self.ctx, self.writer, self.bar = case, ctx, writer, bar
        self.schedule = OutputSchedule(case.output.every, case.output.every_dt)
        self.settled = _Settling(case, settling_threshold(case, ctx.mesh, ctx.material))
        self.analysis = ANALYSES[case.case.analysis]
        self.vertex = _probe_point(case, ctx.mesh)
        self.step = 0
        self.last = None
        self.last_written = None
        self.stop_reason = None
        try:
            self._energies_take_t = "t" in inspect.signature(ctx.model.energies).parameters
        except (TypeError, ValueError):
            self._energies_take_t = False

    def energies(self, state) -> dict:
        model = self.ctx.model
        if self._energies_take_t:
            out = model.energies(state.u, state.v, t=state.t)
        else:
            out = model.energies(state.u, state.v)
        return {k: float(v) for k, v in out.items()}

    def __call__(self, state, info=None) -> bool:
        model = self.ctx.model
        fields = flatten_fields(model.fields(state.u, state.v, state.a))
        energies = self.energies(state)
        row = {"step": self.step, "t": float(state.t),
               "dt": float(getattr(info, "dt", 0.0)),
               "iterations": int(getattr(info, "iterations", 0)),
               "cuts": int(getattr(info, "cuts", 0))}
        row.update(energies)
        row.update(_probes(self.case, self.ctx.mesh, fields, self.vertex))
        if self.analysis.probe is not None:
            row.update(self.analysis.probe(self.ctx, fields))
        self.ctx.history.append(row)
        self.writer.append_history(row)
        if info is not None and getattr(info, "cuts", 0):
            log.info("t = %.6g s: step size cut to dt = %.3g s", state.t, info.dt)
        if self.schedule.due(self.step, state.t):
            self.writer.write_step(state.t, fields)
            self.last_written = self.step
        self.last = state
        self.step += 1
        self.bar.update(max(0.0, min(float(state.t), self.bar.total) - self.bar.n))
        if self.settled(state.t, energies.get("kinetic", math.inf)):
            self.stop_reason = (
                f"kinetic energy {energies['kinetic']:.3e} J below "
                f"{self.settled.threshold:.3e} J for {self.settled.needed} steps at t = {state.t:g} s")
            return True
        return False

    def finish(self) -> None:
        """Write the last converged state if the schedule skipped it."""
        if self.last is not None and self.last_written != self.step - 1:
            s = self.last
            self.writer.write_step(s.t, flatten_fields(self.ctx.model.fields(s.u, s.v, s.a)))
            self.last_written = self.step - 1


def _simulate(case: Case, parts: Parts, out_dir: Path, quiet: bool, wall0: float) -> dict:
    from drape import newmark

    ctx = RunContext(case, parts.mesh, parts.material, parts.model, out_dir)
    model, solver = parts.model, case.solver
    status, reason = "completed", f"reached t_end = {solver.t_end:g} s"
    error = None
    with OutputWriter(out_dir, case.case.name, parts.mesh, fields=case.output.fields) as writer:
        bar = _progress(solver.t_end, quiet)
        rec = _Recorder(case, ctx, writer, bar)
        u0, v0 = initial_fields(case, model)
        state0 = newmark.initial_state(model, u0, v0)
        rec(state0)
        newton = dict(rtol=solver.rtol, atol=solver.atol, du_rtol=solver.du_rtol,
                      du_atol=solver.du_atol, max_iter=solver.max_iter)
        try:
            if solver.quasi_static:
                times = np.union1d(_pseudo_times(solver.dt, solver.t_end), hit_times(case))
                newmark.quasi_static(model, np.ones_like(times), times=times, state=state0,
                                     max_cuts=solver.max_cuts, on_step=rec, **newton)
            else:
                state = state0
                for t_stop, dt_max, settling in time_phases(case):
                    # the settling phase starts at dt and lands on no output marks: its step grows
                    state = newmark.integrate(model, t_stop, solver.dt, state=state, dt_max=dt_max,
                                              beta=solver.newmark_beta, gamma=solver.newmark_gamma,
                                              alpha_hht=solver.alpha_hht, max_cuts=solver.max_cuts,
                                              hit_times=() if settling else hit_times(case),
                                              on_step=rec, **newton)
                    if rec.stop_reason is not None:
                        break
            if rec.stop_reason is not None:
                status, reason = "settled", rec.stop_reason
        except newmark.ConvergenceError as exc:
            status, reason = "failed", f"no convergence: {exc}"
            log.error("stopped: %s", exc)
        except KeyboardInterrupt:
            status, reason = "interrupted", "interrupted by the user (Ctrl-C)"
            log.warning("interrupted")
        except Exception as exc:  # keep what was written, say why, then let it propagate
            status, reason = "error", f"{type(exc).__name__}: {exc}"
            error = exc
            log.exception("run stopped by an error")
        finally:
            bar.close()
        rec.finish()
        ctx.state = rec.last
        summary = {
            "case": case.case.name,
            "description": case.case.description,
            "material": getattr(parts.material, "name", None),
            "model": type(model).__name__,
            "status": status,
            "reason": reason,
            "t_final": float(rec.last.t),
            "settling_time": float(rec.last.t) if status == "settled" else None,
            "steps": rec.step - 1,
            "vtu_files": len(writer.datasets),
            "pvd": writer.pvd_path.name,
            "final": {k: v for k, v in ctx.history[-1].items() if k != "step"},
        }
        if status in ("completed", "settled") and case.case.analysis != "none":
            analysis = ANALYSES[case.case.analysis]
            try:
                summary["analysis"] = {"name": analysis.name, **analysis.finish(ctx)}
            except Exception as exc:  # a failing analysis must not lose the run
                log.exception("analysis %s failed", analysis.name)
                summary["analysis"] = {"name": analysis.name,
                                       "error": f"{type(exc).__name__}: {exc}"}
        wall = time.perf_counter() - wall0
        summary["wall_time_s"] = wall
        summary["simulated_per_wall"] = float(rec.last.t) / wall if wall > 0 else None
        writer.write_summary(summary)
    log.info("%s: %s (%d steps, %.1f s wall)", status, reason, summary["steps"], wall)
    if error is not None:
        raise error
    return summary


def time_phases(case: Case) -> list[tuple[float, float, bool]]:
    """``(t_stop, dt_max, settling)`` of each stretch of a dynamic run: ``dt`` while loads
    change, then (when ``settling_dt`` is given, once they are constant) a settling phase whose
    step grows from ``dt`` up to ``settling_dt``.

    >>> from drape.case import parse_case
    >>> c = parse_case({"case": {"name": "x"}, "material": {"name": "f"},
    ...     "mesh": {"kind": "strip", "length": 1.0, "width": 0.1, "nx": 4},
    ...     "load": {"gravity": {"ramp_time": 0.2}},
    ...     "solver": {"dt": 0.01, "t_end": 1.0, "settling_dt": 0.05}})
    >>> time_phases(c)
    [(0.2, 0.01, False), (1.0, 0.05, True)]
    """
    solver = case.solver
    t_change = case.load.end_time()
    if solver.settling_dt is None or t_change >= solver.t_end:
        return [(solver.t_end, solver.dt, False)]
    settle = (solver.t_end, solver.settling_dt, True)
    return [settle] if t_change <= 0.0 else [(t_change, solver.dt, False), settle]


def hit_times(case: Case) -> list[float]:
    """Times the integrator must land on: output marks, load-history corners, KES turning points.

    >>> from drape.case import parse_case
    >>> c = parse_case({"case": {"name": "x"}, "material": {"name": "f"},
    ...     "mesh": {"kind": "strip", "length": 1.0, "width": 0.1, "nx": 4},
    ...     "load": {"gravity": {"history": [[0, 0], [0.35, 1]]}},
    ...     "output": {"every_dt": 0.25}, "solver": {"dt": 0.1, "t_end": 0.6}})
    >>> hit_times(c)
    [0.25, 0.35, 0.5]
    """
    t_end = case.solver.t_end
    times: set[float] = set()
    if case.output.every_dt is not None:
        n = int(math.floor(t_end / case.output.every_dt + 1e-9))
        times.update(k * case.output.every_dt for k in range(1, n + 1))
    load = case.load
    for part in (load.gravity, load.pressure, load.end_moment):
        if part is None:
            continue
        if part.history is not None:
            times.update(row[0] for row in part.history)
        elif part.ramp_time > 0:
            times.add(part.ramp_time)
    if load.kes is not None:
        from constitutive.kes import kes_profile

        times.update(kes_profile(**load.kes.profile_kwargs()).phase_times.tolist())
    return sorted(t for t in times if 0.0 < t < t_end)


def _pseudo_times(dt: float, t_end: float) -> np.ndarray:
    n = max(1, int(math.ceil(t_end / dt - 1e-9)))
    return np.linspace(t_end / n, t_end, n)


def _progress(total: float, quiet: bool):
    from tqdm import tqdm

    return tqdm(total=total, disable=quiet, unit="s", unit_scale=False, desc="simulated time",
                mininterval=0.5,
                bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} s [{elapsed}<{remaining}]",
                file=sys.stderr, leave=False)


# --------------------------------------------------------------------------- CLI
def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="python -m drape.run",
        description="Run a fabric bending / drape case file (TOML) and write VTU/PVD, "
                    "history.csv and summary.json.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="example:\n"
               "  python -m drape.run cases/cantilever.toml --out out/cantilever \\\n"
               "      --set solver.t_end=0.5 --set mesh.nx=10 --set \"mesh.length=3 cm\"\n"
               "  python -m drape.inspect out/cantilever      (pictures of the result)\n\n"
               "outputs in DIR: <name>_NNNN.vtu + <name>.pvd (ParaView, pyvista), history.csv,\n"
               "summary.json, case.resolved.toml, run.log\n\n"
               "exit codes: 0 completed or settled, 1 bad input, 2 no convergence (every converged\n"
               "step stays on disk; summary.json says why), 130 interrupted",
    )
    p.add_argument("case", nargs="?", help="case file (TOML)")
    p.add_argument("--out", metavar="DIR",
                   help="output directory (default: out/<case name>)")
    p.add_argument("--set", metavar="KEY=VALUE", action="append", default=[], dest="overrides",
                   help="override any case key by its dotted name; the value is read as TOML "
                        "(numbers, true/false, arrays, \"strings\"), a bare word as a string: "
                        "--set solver.dt=1e-3 --set model.kinematics=small; "
                        "repeatable, applied before validation")
    p.add_argument("--quiet", action="store_true", help="no progress bar, no final message")
    p.add_argument("--check", action="store_true",
                   help="validate the case and build mesh, material and model, then stop "
                        "(prints what would run; writes nothing)")
    p.add_argument("--help-case", action="store_true",
                   help="print every case-file table and key with its meaning, and exit")
    return p


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point; returns the exit code."""
    parser = _parser()
    args = parser.parse_args(argv)
    if args.help_case:
        print(describe_schema())
        return 0
    if args.case is None:
        parser.error("the case file is required (or --help-case)")
    try:
        case = load_case(args.case, args.overrides)
        if args.check:
            parts = build(case)
            print(f"{case.case.name}: OK — {type(parts.model).__name__}, {parts.model.ndofs} dofs "
                  f"({len(parts.model.fixed_dofs)} fixed), {parts.mesh.t.shape[1]} triangles, "
                  f"material {getattr(parts.material, 'name', '?')}, "
                  f"t_end = {case.solver.t_end:g} s, dt = {case.solver.dt:g} s, "
                  f"analysis {case.case.analysis}")
            return 0
        out = Path(args.out) if args.out else Path("out") / case.case.name
        source = f"from {args.case}" + "".join(f" --set {o}" for o in args.overrides)
        summary = run_case(case, out, quiet=args.quiet, source=source)
    except (CaseError, RunInputError) as exc:
        print(f"error in {args.case}:\n  " + str(exc).replace("\n", "\n  "), file=sys.stderr)
        return 1
    except ValueError as exc:  # bad input caught by a lower layer (material, mesh, model)
        print(f"error in {args.case}: {exc}", file=sys.stderr)
        return 1
    if summary["status"] == "failed":
        print(f"{case.case.name}: FAILED at t = {summary['t_final']:g} s: {summary['reason']}\n"
              f"  every converged step is kept in {out} ({summary['vtu_files']} VTU files, "
              f"{summary['pvd']})", file=sys.stderr)
        return 2
    if summary["status"] == "interrupted":
        print(f"{case.case.name}: interrupted at t = {summary['t_final']:g} s; output kept in {out}",
              file=sys.stderr)
        return 130
    if not args.quiet:
        print(f"{case.case.name}: {summary['status']} ({summary['reason']}); "
              f"{summary['steps']} steps in {summary['wall_time_s']:.1f} s; output in {out}")
        if "analysis" in summary:
            for key, value in summary["analysis"].items():
                if isinstance(value, (int, float, str)):
                    print(f"  {key}: {value}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
