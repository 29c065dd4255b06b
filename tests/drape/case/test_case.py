"""Case files: schema validation gives one clear error per mistake; --set overrides; round trip."""
from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import pytest

from drape.case.case import (
    Case,
    CaseError,
    apply_overrides,
    check_boundaries,
    describe_schema,
    dump_case,
    load_case,
    parse_case,
)

CASES = Path(__file__).resolve().parents[3] / "cases"

GOOD = {
    "case": {"name": "t"},
    "mesh": {"kind": "strip", "length": 0.05, "width": 0.025, "nx": 4, "ny": 1},
    "material": {"name": "fabric1"},
    "model": {"supports": {"clamped": "clamped"}},
    "load": {"gravity": {"ramp_time": 0.1}},
    "solver": {"dt": 0.01, "t_end": 0.2},
}


def error_of(overrides, base=GOOD) -> str:
    data = copy.deepcopy(base)
    apply_overrides(data, overrides)
    with pytest.raises(CaseError) as info:
        parse_case(data)
    return str(info.value)


def test_good_case_validates_with_defaults():
    case = parse_case(copy.deepcopy(GOOD))
    assert case.solver.newmark_beta == 0.25 and case.solver.newmark_gamma == 0.5
    assert case.model.kinematics == "small"
    assert case.load.gravity.amplitude(0.05) == pytest.approx(0.5)


@pytest.mark.parametrize(
    "overrides, expected",
    [
        (["model.dampin.alpha=1.0"], "unknown key 'model.dampin' (did you mean 'damping'?)"),
        (["mesh.lenght=0.1"], "unknown key 'mesh.lenght' (did you mean 'length'?)"),
        (["mesh.nx='ten'"], "mesh.nx = 'ten': must be an integer"),
        (["mesh.nx=2.5"], "mesh.nx = 2.5: must be an integer"),
        (["material.thickness=-1"], "material.thickness = -1: must be > 0"),
        (["mesh.width=-0.01"], "mesh.width = -0.01: must be > 0"),
        (["material.f1=0.5", "material.f2=0.6"],
         "material.f1 = 0.5 must exceed material.f2 = 0.6 (dissipativity, 3.18)"),
        (["material.warp.f1=0.1", "material.warp.f2=0.1"],
         "material.warp.f1 = 0.1 must exceed material.warp.f2 = 0.1 (dissipativity, 3.18)"),
        (["case.analysis='peirse'"],
         "case.analysis = 'peirse': must be one of 'none', 'peirce', 'cusick', 'kes', 'cycle'"),
        (["model.kinematics='huge'"],
         "model.kinematics = 'huge': must be one of 'small' or 'large'"),
        (["mesh.kind='strp'"],
         "mesh.kind = 'strp': must be one of 'strip', 'rectangle', 'cusick', 'circle', 'file'"),
        (["material.path='x.toml'"],
         "material: give exactly one of name, path or [material.kes] (got name, path)"),
        (["model.kinematics='large'", "mesh.element='morley'"],
         "mesh.element = 'morley' cannot carry model.kinematics = 'large' (needs 'argyris')"),
        (["solver.dt=1.0"], "solver.dt = 1.0: must not exceed solver.t_end = 0.2"),
        (["model.kinematics='large'", "model.supports.clamped='simply_supported'"],
         "model.supports.clamped = 'simply_supported': the large-rotation model offers only "
         "'clamped' and 'free'"),
        (["load.end_moment.value=1e-6"],
         "load.end_moment needs model.kinematics = 'large' (a follower moment)"),
        (["mesh.length='5 kg'"], "mesh.length = '5 kg': cannot read '5 kg' as a quantity"),
        (["solver=3"], "solver = 3: must be a table"),
        (["model.membrane_strain_degree=3"],
         "model.membrane_strain_degree is only used with model.kinematics = 'large' (got 'small')"),
        (["material.bending_scale=-2"], "material.bending_scale = -2: must be > 0"),
        (["model.kinematics='large'", "mesh.element='argyris'", "model.membrane_stabilization=0.1"],
         "model.membrane_stabilization needs model.membrane_strain_degree"),
        (["model.membrane_stabilization=2"], "model.membrane_stabilization = 2: must be <= 1"),
        (["model.viscous_tangent='full'"],
         "model.viscous_tangent is only used with model.kinematics = 'large' (got 'small')"),
        (["model.viscous_tangent='exact'"], "model.viscous_tangent = 'exact'"),
        (["model.bending_friction='per_direction'"],
         "model.bending_friction is only used with model.kinematics = 'large' (got 'small')"),
        (["model.bending_friction='isotropic'"], "model.bending_friction = 'isotropic'"),
        (["model.damping.drag_coefficient=1.2"],
         "model.damping.drag_coefficient needs model.kinematics = 'large' (the drag acts along "
         "the deformed normal)"),
        (["model.damping.drag_coefficient=1.2", "model.damping.air_drag=0.3"],
         "model.damping: give air_drag (linear) or drag_coefficient (quadratic), not both"),
        (["model.kinematics='large'", "mesh.element='argyris'", "load.agitation.acceleration=0.3",
          "model.damping.drag_coefficient=1.2"],
         "load.agitation cannot be combined with model.damping.drag_coefficient"),
        (["mesh.fine_zone.start='1 cm'", "mesh.fine_zone.end='6 cm'", "mesh.fine_zone.nx=10"],
         "mesh.fine_zone.end = 0.06 m lies beyond the strip's length 0.05 m"),
        (["mesh.fine_zone.start='3 cm'", "mesh.fine_zone.end='2 cm'", "mesh.fine_zone.nx=10"],
         "mesh.fine_zone.start = 0.03 m must be below mesh.fine_zone.end = 0.02 m"),
        (["load.agitation.acceleration=0.3", "load.agitation.frequency='20 Hz'"],
         "solver.dt = 0.01 s is too long for load.agitation.frequency = 20 Hz: at least 10 steps "
         "a cycle need solver.dt <= 0.005 s"),
    ],
)
def test_each_mistake_gives_exactly_one_clear_error(overrides, expected):
    message = error_of(overrides)
    assert len(message.splitlines()) == 1, message
    assert message.startswith(expected), message


def test_missing_required_key_is_named():
    data = copy.deepcopy(GOOD)
    del data["solver"]["dt"]
    with pytest.raises(CaseError, match=r"^solver\.dt is required$"):
        parse_case(data)


def test_unit_strings_are_converted_to_si():
    case = parse_case({**copy.deepcopy(GOOD),
                       "mesh": {"kind": "strip", "length": "5 cm", "width": "25 mm", "nx": 4}})
    assert case.mesh.length == pytest.approx(0.05, rel=1e-12)
    assert case.mesh.width == pytest.approx(0.025, rel=1e-12)


def test_missing_boundary_names_the_key_and_lists_the_available_ones():
    from skfem import MeshTri

    mesh = MeshTri().with_boundaries({"clamped": lambda x: x[0] < 1e-9,
                                      "free_end": lambda x: x[0] > 1 - 1e-9})
    data = copy.deepcopy(GOOD)
    data["model"]["supports"] = {"clampd": "clamped"}
    case = parse_case(data)
    with pytest.raises(CaseError) as info:
        check_boundaries(case, mesh)
    assert str(info.value) == ("model.supports names boundary 'clampd' which the mesh does not "
                               "have; available: clamped, free_end")


def test_overrides_parse_toml_values_and_create_tables():
    data = copy.deepcopy(GOOD)
    apply_overrides(data, ["solver.dt=2e-3", "case.name=short", "model.damping.alpha=3",
                           "output.fields=['curvature_xx']", "load.gravity.factor=-1.0"])
    case = parse_case(data)
    assert case.solver.dt == 2e-3
    assert case.case.name == "short"            # bare words stay strings
    assert case.model.damping.alpha == 3.0
    assert case.output.fields == ["curvature_xx"]
    assert case.load.gravity.factor == -1.0


def test_override_through_a_value_is_an_error():
    data = copy.deepcopy(GOOD)
    with pytest.raises(CaseError, match="'case.name' is a value, not a table"):
        apply_overrides(data, ["case.name.x=1"])
    with pytest.raises(CaseError, match="expected KEY=VALUE"):
        apply_overrides(data, ["solver.dt"])


def test_load_case_resolves_relative_paths_and_overrides(tmp_path):
    (tmp_path / "c.toml").write_text(
        '[case]\nname = "f"\n[mesh]\nkind = "file"\npath = "m.msh"\n'
        '[material]\npath = "mat.toml"\n[solver]\ndt = 0.1\nt_end = 1.0\n')
    case = load_case(tmp_path / "c.toml", ["solver.t_end=2.0"])
    assert case.mesh.path == str(tmp_path / "m.msh")
    assert case.material.path == str(tmp_path / "mat.toml")
    assert case.solver.t_end == 2.0


def test_unreadable_toml_is_a_case_error(tmp_path):
    (tmp_path / "bad.toml").write_text("[case\nname = 1\n")
    with pytest.raises(CaseError, match="not valid TOML"):
        load_case(tmp_path / "bad.toml")
    with pytest.raises(CaseError, match="does not exist"):
        load_case(tmp_path / "missing.toml")


def test_resolved_case_round_trips():
    data = copy.deepcopy(GOOD)
    apply_overrides(data, ["load.gravity.factor=0.5", "stop.out_of_balance=1e-4"])
    case = parse_case(data)
    again = parse_case(tomllib.loads(dump_case(case)))
    assert again == case


@pytest.mark.parametrize("path", sorted(CASES.glob("*.toml")), ids=lambda p: p.name)
def test_shipped_case_files_validate(path):
    assert isinstance(load_case(path), Case)


def test_schema_help_documents_every_key():
    text = describe_schema()
    from constitutive.schema_errors import model_class
    from drape.case import case as c

    for section in (c.SolverSpec, c.ModelSpec, c.StopSpec, c.OutputSpec, c.Gravity, c.KesDrive):
        for name, field in section.model_fields.items():
            assert field.description, f"{section.__name__}.{name} has no docstring"
            if model_class(field.annotation) is not None:
                assert f"[{section.__name__.lower().replace('spec', '')}.{name}]" in text, name
            else:
                assert f"  {name} : " in text, name


def test_cusick_mesh_grading_below_one_is_named():
    with pytest.raises(CaseError) as info:
        load_case(Path(__file__).parents[3] / "cases" / "cusick_fabric1.toml", ["mesh.radial_grading=0.5"])
    assert str(info.value) == "mesh.radial_grading = 0.5: must be >= 1.0"


def test_friction_tangent_choices_are_the_laws():
    """The case schema lists the law's friction tangents (kept in one place: constitutive.law)."""
    import typing

    from constitutive.law import FRICTION_TANGENTS
    from drape.case.case import ModelSpec

    assert typing.get_args(ModelSpec.model_fields["friction_tangent"].annotation) == FRICTION_TANGENTS


def test_bending_friction_choices_are_the_sheet_laws():
    """The case schema lists the sheet law's friction frames (kept in constitutive.sheet)."""
    import typing

    from constitutive.sheet import FRICTION_FRAMES
    from drape.case.case import ModelSpec

    assert typing.get_args(ModelSpec.model_fields["bending_friction"].annotation) == FRICTION_FRAMES
