"""The TOML case file: the whole case with its cross-table rules, loading, dotted overrides.

A case file describes one simulation: the specimen mesh, the fabric, the structural model,
the loads, the time integration, what to write and when to stop. The tables are defined in
:mod:`drape.case.schema` and :mod:`drape.case.loads`; errors are worded by
:func:`constitutive.schema_errors.format_errors`, the ``--help-case`` text by
:mod:`drape.case.help`. Every table rejects unknown keys. Numbers are SI (m, kg, s, N); any
dimensional number may instead be written as a string with units, e.g. ``length = "5 cm"``
or ``rate = "0.5 1/cm/s"``, converted with pint.

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
    out_of_balance = 1e-3         # of the weight (drape.run.settling)

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

import tomllib
from pathlib import Path

from pydantic import ValidationError, model_validator

from constitutive.bundled import cases_dir
from constitutive.schema_errors import format_errors
from drape.case.contact_tables import BODY_SHAPES, ContactSpec
from drape.case.help import describe
from drape.case.loads import (  # noqa: F401
    Agitation,
    Amplitude,
    EndMoment,
    Gravity,
    KesDrive,
    LoadSpec,
    Perturbation,
    Pressure,
)
from drape.case.material_tables import CaseMaterial, LawOverride  # noqa: F401
from drape.case.mesh_tables import (CircleMesh, CusickMesh, FileMesh, MeshSpec,  # noqa: F401
                                    RectangleMesh, StripMesh)
from drape.case.quantities import _Section, _rule
from drape.case.setup import SETUP_KEY, SETUPS, merge_setup
from drape.case.schema import (  # noqa: F401  (the tables, importable with the case)
    CaseInfo,
    Damping,
    MeasuredSpec,
    Membrane,
    ModelSpec,
    OutputSpec,
    SolverSpec,
    StopSpec,
)

__all__ = [
    "Case",
    "CaseError",
    "load_case",
    "parse_case",
    "read_case_data",
    "apply_overrides",
    "check_boundaries",
    "dump_case",
    "describe_schema",
]


class CaseError(ValueError):
    """A case file breaks the schema; the message names each offending dotted key and rule."""


class Case(_Section):
    """A whole case file."""

    case: CaseInfo
    """[case]: name, description and analysis."""
    mesh: MeshSpec
    """[mesh]: geometry, selected by ``kind`` = strip | rectangle | cusick | file."""
    material: CaseMaterial
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
    measured: MeasuredSpec | None = None
    """[measured]: the real test's results, for comparison (not used by the run)."""
    contact: ContactSpec | None = None
    """[contact]: rigid bodies the fabric touches (``[[contact.body]]``), self-contact."""

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
        if self.solver.quasi_static and self.stop.active and "out_of_balance" in self.stop.model_fields_set:
            raise _rule(
                "stop.out_of_balance needs a dynamic run: solver.quasi_static = true is in "
                "balance at every step (set stop.out_of_balance = 0 or leave it out)"
            )
        self._agitation_is_resolved()
        if self.load.perturbation is not None and self.mesh.kind not in PERTURBABLE_MESHES:
            raise _rule(f"load.perturbation needs mesh.kind in {PERTURBABLE_MESHES} "
                        f"(got '{self.mesh.kind}')")
        if self.case.analysis == "kes" and self.load.kes is None:
            raise _rule("case.analysis = 'kes' needs a [load.kes] drive")
        if self.case.analysis == "cycle" and (self.load.gravity is None
                                               or self.load.gravity.history is None):
            raise _rule("case.analysis = 'cycle' needs a load.gravity.history")
        if self.case.analysis == "cusick" and self.mesh.kind != "cusick":
            raise _rule(f"case.analysis = 'cusick' needs mesh.kind = 'cusick' (got '{self.mesh.kind}')")
        return self

    def _agitation_is_resolved(self):
        """Shaking needs inertia, and steps short enough to follow it (Newmark's period error
        is (ω Δt)²/12: 3 % at 10 steps a cycle)."""
        shake = self.load.agitation
        if shake is None:
            return
        if self.solver.quasi_static:
            raise _rule("load.agitation needs a dynamic run (solver.quasi_static = false)")
        if self.model.damping.drag_coefficient:
            raise _rule("load.agitation cannot be combined with model.damping.drag_coefficient: "
                        "the quadratic drag of the shaken frame's velocity is not modelled "
                        "(use the linear model.damping.air_drag)")
        longest = 1.0 / (STEPS_PER_SHAKE * shake.frequency)
        if self.solver.dt > longest * (1 + 1e-9):
            raise _rule(f"solver.dt = {self.solver.dt:g} s is too long for load.agitation.frequency"
                        f" = {shake.frequency:g} Hz: at least {STEPS_PER_SHAKE} steps a cycle "
                        f"need solver.dt <= {longest:.3g} s")

    def _model_can_do_it(self):
        """Loads and supports each kinematics offers (plate: drape.models.plate, shell: drape.models.shell)."""
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
            if self.contact is not None:
                raise _rule("[contact] needs model.kinematics = 'large' (the small-deflection plate "
                            "cannot follow a fabric over a body)")
            if load.end_moment is not None:
                raise _rule("load.end_moment needs model.kinematics = 'large' (a follower moment)")
            if load.perturbation is not None:
                raise _rule("load.perturbation needs model.kinematics = 'large'")
            if model.damping.drag_coefficient:
                raise _rule("model.damping.drag_coefficient needs model.kinematics = 'large' "
                            "(the drag acts along the deformed normal)")

    def boundary_names(self) -> dict[str, str]:
        """Every boundary name the case refers to, keyed by the dotted key that names it."""
        names = {f"model.supports.{b}": b for b in self.model.supports}
        if self.load.end_moment is not None:
            names["load.end_moment.boundary"] = self.load.end_moment.boundary
        if self.load.kes is not None:
            for i, end in enumerate(self.load.kes.ends):
                names[f"load.kes.ends[{i}]"] = end
        return names


STEPS_PER_SHAKE = 10
"""Fewest time steps a cycle of ``[load.agitation]`` may take."""
#: Meshes a [load.perturbation] field is defined on: round the Cusick disc, or along x.
PERTURBABLE_MESHES = ("cusick", "strip", "rectangle")

_MESH_VARIANTS = {"strip": StripMesh, "rectangle": RectangleMesh, "cusick": CusickMesh,
                  "circle": CircleMesh, "file": FileMesh}


def parse_case(data: dict, base_dir: Path | str | None = None) -> Case:
    """Validate a case dictionary (as read from TOML); raise :class:`CaseError` on any problem.

    Relative ``mesh.path`` / ``material.path`` are resolved against ``base_dir``.
    """
    try:
        case = Case.model_validate(data)
    except ValidationError as exc:
        raise CaseError(format_errors(exc, Case, {"mesh": _MESH_VARIANTS, "contact.body[]": BODY_SHAPES})) from None
    if base_dir is not None:
        base = Path(base_dir)
        if case.mesh.kind == "file" and not Path(case.mesh.path).is_absolute():
            case.mesh.path = str((base / case.mesh.path).resolve())
        if case.material.path is not None and not Path(case.material.path).is_absolute():
            case.material.path = str((base / case.material.path).resolve())
        for body in (case.contact.body if case.contact is not None else ()):
            if body.shape == "mesh" and not Path(body.file).is_absolute():
                body.file = str((base / body.file).resolve())
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


def _read_toml(path: Path, what: str) -> dict:
    if path.is_dir():
        raise CaseError(f"{path} is a folder, not a {what} (give a .toml file in it)")
    try:
        return tomllib.loads(path.read_bytes().decode("utf-8"))
    except FileNotFoundError:
        raise CaseError(f"{what} {str(path)!r} does not exist") from None
    except UnicodeDecodeError as exc:
        raise CaseError(f"{path}: not a text file (a TOML {what} is UTF-8 text; byte "
                        f"{exc.start} is not)") from None
    except tomllib.TOMLDecodeError as exc:
        raise CaseError(f"{path}: not valid TOML ({exc})") from None


def read_case_data(path) -> dict:
    """The case file at ``path`` as a dictionary, on its set-up if it names one
    (:mod:`drape.case.setup`).

    ``setup`` is the name of a bundled set-up (``"cusick"``: ``cases/setups/cusick.toml``, so a
    copied case file keeps its set-up), or a ``.toml`` path relative to the case file's
    folder. A set-up cannot name a set-up of
    its own (what a case is worked on is read in one place). Relative paths inside the set-up
    (a mesh file, a body's surface) are the case's: keep them out of set-ups.

    Raises
    ------
    CaseError
        The case or its set-up cannot be read, or ``setup`` is not a string.
    """
    path = Path(path)
    data = _read_toml(path, "case file")
    name = data.pop(SETUP_KEY, None)
    if name is None:
        return data
    if not isinstance(name, str) or not name.strip():
        raise CaseError(f"{SETUP_KEY} = {name!r}: must be a bundled set-up's name (\"cusick\") "
                        "or the path of a set-up file (a string)")
    bundled = "/" not in name and "\\" not in name and not name.endswith(".toml")
    setup = _read_toml(cases_dir(SETUPS, f"{name}.toml") if bundled else path.parent / name,
                       "set-up file")
    if SETUP_KEY in setup:
        raise CaseError(f"{SETUP_KEY} = {name!r}: the set-up file names a set-up of its own "
                        f"({setup[SETUP_KEY]!r}); a set-up is one file")
    return merge_setup(setup, data)


def load_case(path, overrides: list[str] | None = None) -> Case:
    """Read a TOML case file (on its set-up, :func:`drape.case.setup.read_case_data`), apply
    ``--set`` overrides, validate.

    Raises
    ------
    CaseError
        Unreadable TOML or any schema violation (message names the key and the rule).
    """
    path = Path(path)
    data = read_case_data(path)
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
    drape.case.case.CaseError: model.supports names boundary 'lft' which the mesh does not have; available: left
    """
    available = sorted((getattr(mesh, "boundaries", None) or {}).keys())
    for key, name in case.boundary_names().items():
        if name not in available:
            where = "model.supports" if key.startswith("model.supports.") else key
            raise CaseError(
                f"{where} names boundary '{name}' which the mesh does not have; "
                f"available: {', '.join(available) or '(none)'}"
            )


def describe_schema() -> str:
    """Every table and key of a case file with its type, default and meaning (``--help-case``).

    >>> "[solver]" in describe_schema()
    True
    """
    return describe(Case)
