"""A specimen's rigidity varying from place to place (drape.models.rigidity, the shell's
``rigidity_factor``, ``[model.rigidity_variation]``)."""
import dataclasses

import numpy as np
import pytest

from constitutive.material import load_material
from drape.case.case import CaseError, load_case
from drape.models.rigidity import RigidityVariation
from drape.models.shell import KirchhoffLoveShell, ShellInputError
from meshes import strip

ELL = 0.02


def test_the_field_has_mean_one_its_cv_and_the_gaussian_correlation():
    """Over many seeds: g has unit variance and correlation exp(−r²/2ℓ²) at r = ℓ and 2ℓ
    (random Fourier features are exact in expectation); the factor has mean 1 and the cv."""
    rng = np.random.default_rng(1)
    x = rng.uniform(0, 0.3, (2, 400))
    direction = rng.normal(size=(2, 400))
    direction /= np.linalg.norm(direction, axis=0)
    products = {0.0: [], 1.0: [], 2.0: []}
    factors = []
    for seed in range(200):
        field = RigidityVariation(cv=0.2, correlation_length=ELL, seed=seed)
        g0 = field.gaussian(x)
        for lag in products:
            products[lag].append(g0 * field.gaussian(x + lag * ELL * direction))
        factors.append(field(x))
    for lag, p in products.items():
        assert np.mean(p) == pytest.approx(np.exp(-0.5 * lag ** 2), abs=0.03)
    s = np.concatenate(factors)
    assert s.mean() == pytest.approx(1.0, abs=0.01)
    assert s.std() / s.mean() == pytest.approx(0.2, abs=0.01)
    assert np.array_equal(RigidityVariation(0.2, ELL, seed=7)(x), RigidityVariation(0.2, ELL, seed=7)(x))


@pytest.mark.parametrize("kwargs", [dict(cv=-0.1, correlation_length=ELL),
                                    dict(cv=0.1, correlation_length=0.0),
                                    dict(cv=0.1, correlation_length=ELL, modes=0)])
def test_bad_fields_are_refused(kwargs):
    with pytest.raises(ValueError, match="breaks"):
        RigidityVariation(**kwargs)


def _scaled(material, c):
    """Fabric 1 with every moment-valued parameter of its laws times ``c`` (k1, k3, f1, f2)."""
    def law(x):
        friction = dataclasses.replace(x.friction, f1=c * x.friction.f1, f2=c * x.friction.f2)
        return dataclasses.replace(x, k1=c * x.k1, k3=c * x.k3, friction=friction)
    return material.replace(warp=law(material.warp), weft=law(material.weft))


def test_a_uniform_factor_is_the_laws_moments_scaled():
    """A factor 2.5 everywhere gives the internal force, tangent and bending energy of the
    shell whose laws' moments (elastic and friction) are 2.5 times larger, at a bent state
    after a committed step (the friction state carried), to round-off."""
    mat = load_material("fabric1")
    mesh = strip(0.0163, 0.025, 3, 1)
    varied = KirchhoffLoveShell(mesh, mat, load_boundary="free_end",
                                rigidity_factor=lambda x: np.full(x.shape[1:], 2.5))
    stiffer = KirchhoffLoveShell(mesh, _scaled(mat, 2.5), load_boundary="free_end")
    rng = np.random.default_rng(0)
    u1 = 1e-3 * rng.normal(size=varied.ndofs)
    u1[varied.fixed_dofs] = 0.0
    u2 = 1.7 * u1
    for shell in (varied, stiffer):
        shell.commit(u1)
    (f_v, J_v), (f_s, J_s) = (shell.internal_forces(u2, weights=(1.0, 0.0, 0.0))
                              for shell in (varied, stiffer))
    assert np.abs(f_v).max() > 0
    np.testing.assert_allclose(f_v, f_s, rtol=0, atol=1e-12 * np.abs(f_s).max())
    np.testing.assert_allclose(J_v, J_s, rtol=0, atol=1e-12 * np.abs(J_s).max())
    e_v, e_s = varied.energies(u2, 0 * u2), stiffer.energies(u2, 0 * u2)
    assert e_v["bending"] == pytest.approx(e_s["bending"], rel=1e-12)
    assert e_v["friction_work"] == pytest.approx(e_s["friction_work"], rel=1e-12)


def test_a_bad_factor_is_refused_by_the_shell():
    with pytest.raises(ShellInputError, match="rigidity_factor"):
        KirchhoffLoveShell(strip(0.0163, 0.025, 3, 1), load_material("fabric1"),
                           load_boundary="free_end", rigidity_factor=lambda x: -np.ones(x.shape[1:]))


def test_a_case_varies_the_rigidity_with_the_cv_it_asks_for():
    """``[model.rigidity_variation]`` on the Cusick mesh: the shell's factors at its
    quadrature points have, area-weighted, mean 1 and about the cv (one specimen: 18 cm on
    a 2 cm correlation length holds some 60 independent patches)."""
    from drape.case.build import build_material, build_mesh, build_model

    case = load_case("cases/cusick_kes.toml", ["model.rigidity_variation.cv=0.15",
                                               "model.rigidity_variation.correlation_length=2 cm",
                                               "model.rigidity_variation.seed=3"])
    shell = build_model(case, build_mesh(case), build_material(case))
    w = shell.w / shell.w.sum()
    mean = float(np.sum(w * shell.rigidity))
    cv = float(np.sqrt(np.sum(w * (shell.rigidity - mean) ** 2))) / mean
    assert mean == pytest.approx(1.0, abs=0.05) and cv == pytest.approx(0.15, abs=0.05)
    with pytest.raises(CaseError, match="rigidity_variation.correlation_length"):
        load_case("cases/cantilever.toml", ["model.rigidity_variation.cv=0.15"])


def test_one_seed_is_one_specimen():
    """Without its own seed the field takes the perturbation's: seeds 0 and 1 of an ensemble
    are two specimens; a seed given is kept."""
    from drape.case.build import rigidity_variation

    keys = ["model.rigidity_variation.cv=0.1", "model.rigidity_variation.correlation_length=3cm"]
    fields = [rigidity_variation(load_case("cases/cusick_kes.toml", keys + [f"load.perturbation.seed={s}"]))
              for s in (0, 1)]
    assert [f.seed for f in fields] == [0, 1]
    given = load_case("cases/cusick_kes.toml", keys + ["load.perturbation.seed=1",
                                                       "model.rigidity_variation.seed=5"])
    assert rigidity_variation(given).seed == 5
