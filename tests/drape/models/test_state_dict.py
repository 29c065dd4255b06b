"""Saved and restored states: a model restored from its state_dict continues exactly as the original."""
from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import pytest

from constitutive.friction import FrictionParams, FrictionState
from constitutive.law import BendingLaw
from drape.solvers import time_stepping
from drape.case.build import build
from drape.case.case import load_case

ROOT = Path(__file__).resolve().parents[3]
CANTILEVER = ROOT / "cases" / "cantilever.toml"


def curvature_history(rng, shape, n=12):
    return np.cumsum(rng.normal(scale=0.4, size=(n, *shape)), axis=0)


def test_friction_state_restored_from_its_dict_answers_like_the_original():
    rng = np.random.default_rng(1)
    params = FrictionParams(f1=1.0, f2=0.6, eps_f=2.0, eta=0.4)
    original = FrictionState(params, shape=(3, 4))
    for kappa in curvature_history(rng, (3, 4)):
        original.commit(kappa)
    restored = FrictionState(params, shape=(3, 4))
    restored.load_state_dict(copy.deepcopy(original.state_dict()))
    for kappa in curvature_history(rng, (3, 4)):
        for st in (original, restored):
            st.trial(kappa)
            st.commit(kappa)
        np.testing.assert_array_equal(restored.moment(kappa + 0.1), original.moment(kappa + 0.1))
    for key, value in original.state_dict().items():
        np.testing.assert_array_equal(restored.state_dict()[key], value)


def test_bending_state_dict_checks_shape_and_friction():
    law = BendingLaw(k1=1.0, friction=FrictionParams(1.0, 0.0, 1.0, 0.5))
    state = law.new_state((2,))
    state.commit(np.array([0.5, -0.2]))
    saved = state.state_dict()
    assert sorted(saved) == ["friction.kappa", "friction.y1", "friction.y2", "kappa"]
    with pytest.raises(ValueError, match=r"bending state kappa: saved with shape \(2,\), expected \(3,\)"):
        law.new_state((3,)).load_state_dict(saved)
    with pytest.raises(ValueError, match="saved with friction, but the law has none"):
        BendingLaw(k1=1.0).new_state((2,)).load_state_dict(saved)
    restored = law.new_state((2,))
    restored.load_state_dict(saved)
    np.testing.assert_array_equal(restored.trial(np.array([1.0, 1.0]))[0],
                                  state.trial(np.array([1.0, 1.0]))[0])


@pytest.mark.parametrize("kinematics", ["large", "small"])
def test_model_restored_from_its_state_dict_continues_like_the_original(kinematics):
    overrides = ["mesh.nx=2", "mesh.ny=1", f"model.kinematics={kinematics}", "solver.t_end=0.1"]
    if kinematics == "small":
        overrides.append("mesh.element=morley")
    case = load_case(CANTILEVER, overrides)
    original = build(case).model
    run = dict(alpha_hht=case.solver.alpha_hht, rtol=1e-10, atol=1e-14)
    state = time_stepping.integrate(original, 0.05, 0.01, **run)
    saved = copy.deepcopy(original.state_dict())
    restored = build(case).model
    restored.load_state_dict(saved)
    for key, value in saved.items():
        np.testing.assert_array_equal(restored.state_dict()[key], value, err_msg=key)

    ends = [time_stepping.integrate(model, 0.1, 0.01, state=copy.deepcopy(state), **run)
            for model in (original, restored)]
    np.testing.assert_array_equal(ends[1].u, ends[0].u)
    after = original.state_dict()
    for key, value in restored.state_dict().items():
        np.testing.assert_array_equal(value, after[key], err_msg=key)
    assert any(np.any(after[k] != saved[k]) for k in after)   # the states did move on


def test_a_state_dict_of_another_mesh_is_refused():
    coarse = build(load_case(CANTILEVER, ["mesh.nx=2", "mesh.ny=1"])).model
    fine = build(load_case(CANTILEVER, ["mesh.nx=3", "mesh.ny=1"])).model
    with pytest.raises(ValueError, match="saved with shape"):
        fine.load_state_dict(coarse.state_dict())
