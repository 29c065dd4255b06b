"""Plate and shell write the same curvature and twisting moment for the same small twist."""
import numpy as np
import pytest

from drape.case.build import build
from drape.case.case import parse_case

C = 1e-3          # twist w = C x y [1/m]: κ12 = w_,xy = C, small enough for the linear regime
L = 0.01


def _square(kinematics):
    case = parse_case({
        "case": {"name": "twist"}, "material": {"name": "fabric1"},
        "mesh": {"kind": "rectangle", "length": L, "width": L, "nx": 2, "ny": 2},
        "model": {"kinematics": kinematics}, "solver": {"dt": 0.01, "t_end": 0.1}})
    return build(case)


def _twist_dofs(parts, kinematics):
    model = parts.model
    if kinematics == "small":
        return model.basis.project(lambda x: C * x[0] * x[1])
    zero = lambda x: np.zeros(x.shape[1:])      # noqa: E731
    value = lambda x: np.stack([zero(x), zero(x), C * x[0] * x[1]])          # noqa: E731
    grad = lambda x: np.stack([np.stack([zero(x), zero(x)])] * 2              # noqa: E731
                              + [np.stack([C * x[1], C * x[0]])])
    hess = lambda x: np.stack([np.zeros((2, 2) + x.shape[1:])] * 2           # noqa: E731
                              + [np.array([[zero(x), zero(x) + C], [zero(x) + C, zero(x)]])])
    return model.interpolate(value, grad, hess)


def test_plate_and_shell_write_the_same_twist_curvature_and_moment():
    cells = {}
    for kinematics in ("small", "large"):
        parts = _square(kinematics)
        u = _twist_dofs(parts, kinematics)
        zero = np.zeros_like(u)
        cells[kinematics] = parts.model.fields(u, zero, zero)["cell_data"]
        d_t = parts.material.twist_rigidity
    for fields in cells.values():
        # independent reference: κ12 = w_,xy = C and the tensor twisting moment M12 = D_t κ12
        np.testing.assert_allclose(fields["curvature_xy"], C, rtol=1e-5)
        # the elastic part: the shell's friction acts on the curvature tensor, twist included
        elastic = fields["moment_xy"] - fields.get("friction_moment_xy", 0.0)
        np.testing.assert_allclose(elastic, d_t * C, rtol=1e-5)
    assert np.abs(cells["large"]["friction_moment_xy"]).max() > 0
    np.testing.assert_allclose(cells["small"]["moment_xy"],
                               cells["large"]["moment_xy"] - cells["large"]["friction_moment_xy"],
                               rtol=1e-5)
