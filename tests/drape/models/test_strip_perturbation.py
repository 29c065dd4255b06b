"""The seeded imperfection along a strip (a strip laid down is never quite straight): the field
against finite differences, its clamp-like start at the left end, its bound, its seeds, its
interpolation on the shell's basis, and the case rule that places it."""
from pathlib import Path

import numpy as np
import pytest

from drape.models.perturbation import PerturbationError, StripPerturbation, perturbation_dofs

L = 0.3
CASES = Path(__file__).resolve().parents[3] / "cases"


def line(n=3001, y=0.01):
    return np.array([np.linspace(0.0, L, n), np.full(n, y)])


def test_zero_with_its_slope_at_the_left_end_and_bounded_by_the_amplitude():
    p = StripPerturbation(L, kind="random", amplitude=2e-3, seed=4)
    x = line()
    assert p.value(x)[0] == 0.0 and p.grad(x)[0, 0] == 0.0
    w = p.value(x)
    assert 0.2 * 2e-3 < np.abs(w).max() <= 2e-3
    # uniform across the width
    np.testing.assert_array_equal(p.value(line(y=0.0)), p.value(line(y=0.04)))


def test_lobed_field_has_n_half_waves_on_the_way():
    """``kind = "lobed"``: ``w = A ξ² cos(n π ξ + φ)`` changes sign n times along the strip,
    give or take the one at the left end where ξ² is zero."""
    for n in (3, 6, 9):
        p = StripPerturbation(L, kind="lobed", n_lobes=n, amplitude=1e-3, seed=1)
        w = p.value(line())[1:]
        assert abs(np.count_nonzero(np.diff(np.sign(w))) - n) <= 1


def test_same_seed_same_field_other_seed_other_field():
    x = line()
    a, b = StripPerturbation(L, seed=3).value(x), StripPerturbation(L, seed=3).value(x)
    assert np.array_equal(a, b)
    assert np.abs(a - StripPerturbation(L, seed=5).value(x)).max() > 1e-4


@pytest.mark.parametrize("kind", ["lobed", "random"])
def test_gradient_and_hessian_match_finite_differences(kind):
    p = StripPerturbation(L, kind=kind, n_lobes=7, amplitude=1e-3, seed=2)
    x = np.random.default_rng(0).uniform([[0.005], [0.0]], [[L - 0.005], [0.04]], (2, 60))
    h = 1e-6
    e = np.eye(2)[:, :, None] * h
    grad_fd = np.array([(p.value(x + e[i]) - p.value(x - e[i])) / (2 * h) for i in range(2)])
    hess_fd = np.array([(p.grad(x + e[i]) - p.grad(x - e[i])) / (2 * h) for i in range(2)])
    scale = 1e-3 / L
    np.testing.assert_allclose(p.grad(x), grad_fd, atol=1e-6 * scale)
    np.testing.assert_allclose(p.hess(x), hess_fd, atol=1e-4 * scale * 12 / L)


def test_dofs_reproduce_the_field_on_the_strip():
    from skfem import Basis

    import meshes
    from drape.fem.argyris import ElementTriArgyrisLocal

    mesh = meshes.rectangle(L, 0.04, 16, 1)
    basis = Basis(mesh, ElementTriArgyrisLocal())
    p = StripPerturbation(L, kind="random", amplitude=1e-3, seed=0)
    x0 = perturbation_dofs(basis, p)
    assert np.abs(x0[0::3]).max() == 0 and np.abs(x0[1::3]).max() == 0
    w_h = np.asarray(basis.interpolate(x0[2::3]))
    w = p.value(np.asarray(basis.global_coordinates()))
    # quintic interpolation of up to 12 half-waves on 16 cells: within 2 % of the amplitude
    assert np.abs(w_h - w).max() < 2e-2 * 1e-3


def test_bad_parameters_name_the_key():
    with pytest.raises(PerturbationError, match="perturbation.kind"):
        StripPerturbation(L, kind="wavy")
    with pytest.raises(PerturbationError, match="length"):
        StripPerturbation(0.0)


def test_case_places_it_on_strips_and_rectangles_and_names_the_rule_elsewhere(tmp_path):
    from drape.case.build import fold_perturbation
    from drape.case.case import CaseError, load_case

    case = load_case(CASES / "drop_fold.toml")
    field = fold_perturbation(case)
    assert isinstance(field, StripPerturbation) and field.length == pytest.approx(0.3)
    with pytest.raises(CaseError, match="load.perturbation needs mesh.kind"):
        load_case(CASES / "sphere_drape.toml", ["load.perturbation.kind=random"])
