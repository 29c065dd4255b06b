"""Both structural models offer the whole interface the runner and the analyses use."""
import numpy as np
import pytest

from drape.case.build import build
from drape.case.case import parse_case
from drape.models.protocol import StructuralModel


def _strip(kinematics):
    return parse_case({
        "case": {"name": "strip"}, "material": {"name": "fabric1"},
        "mesh": {"kind": "strip", "length": 0.05, "width": 0.02, "nx": 3, "ny": 1},
        "model": {"kinematics": kinematics, "supports": {"clamped": "clamped"}},
        "load": {"gravity": {"ramp_time": 0.0}},
        "solver": {"dt": 0.01, "t_end": 0.1}})


@pytest.mark.parametrize("kinematics", ["small", "large"])
def test_plate_and_shell_satisfy_the_structural_model_protocol(kinematics):
    model = build(_strip(kinematics)).model
    assert isinstance(model, StructuralModel)
    members = [m for m in dir(StructuralModel) if not m.startswith("_")]
    missing = [m for m in members if not hasattr(model, m)]
    assert not missing


@pytest.mark.parametrize("kinematics", ["small", "large"])
def test_nodal_displacement_energies_and_load_time_agree_with_fields(kinematics):
    model = build(_strip(kinematics)).model
    rng = np.random.default_rng(0)
    u = 1e-4 * rng.standard_normal(model.ndofs)
    v = np.zeros(model.ndofs)
    model.residual(u, v, v, 0.0)
    assert model.load_time == 0.0
    disp = model.nodal_displacement(u)
    assert disp.shape == (model.mesh.p.shape[1], 3)
    np.testing.assert_array_equal(disp, model.fields(u, v, v)["point_data"]["displacement"])
    # the load potential is read at the given time, default the last evaluation's
    assert model.energies(u, v) == model.energies(u, v, t=model.load_time)
