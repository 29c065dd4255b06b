"""Global fit of the bending law to KES-FB loops (constitutive.fit)."""

import json

import numpy as np
import pytest

from constitutive.datasets import DATASET_NAMES, KESLoop, load_dataset
from constitutive.fit import DEFAULT_ACCEL_TIME, evaluate, fit, fit_loop, thesis_law
from constitutive.fit.global_fit import _Projector
from constitutive.fit.variants import _variant, from_kes, to_kes
from constitutive.friction import FrictionParams
from constitutive.kes import kes_profile, run_kes
from constitutive.law import BendingLaw
from drape.cli.fit import main

T = DEFAULT_ACCEL_TIME


@pytest.fixture(scope="module")
def full_fits():
    return {n: fit(n, "full", T) for n in DATASET_NAMES}


@pytest.mark.parametrize("name", DATASET_NAMES)
def test_fit_beats_thesis_parameters(full_fits, name):
    # same harness (profile, T, 1 ms samples, state-form friction): the global fit's residual
    # 4.17 is below that of the thesis's published full-model parameters (Tables 4.4/4.7/4.10/
    # 4.13). At T = 0.5 s the fits give 0.188 / 0.0267 / 0.0688 / 0.0173 against 0.431 / 0.0572 /
    # 0.237 / 0.0501; at least a 1.5x improvement is required.
    r = full_fits[name]
    own = evaluate(thesis_law(name), load_dataset(name).sample(T))
    assert r.residual < own / 1.5


def test_thesis_harness_matches_run_kes():
    # the residual of given parameters, computed by fit.evaluate, equals the one computed from
    # constitutive.kes.run_kes (independent code path) on the same profile
    data = load_dataset("fabric2-warp")
    loop = data.sample(T)
    law = thesis_law("fabric2-warp")
    prof = kes_profile(1e-3, rate=data.rate, accel_time=T, k_max=data.k_plus, k_min=data.k_minus)
    sim = run_kes(law, prof)
    ref = np.sum(((sim.moment - loop.moment) / 9.80665e-3) ** 2)
    assert evaluate(law, loop) == pytest.approx(ref, rel=1e-12)


# Tables 4.4, 4.7, 4.10, 4.13 as printed (an independent transcription of the material library)
PRINTED = {
    "fabric1-warp": dict(f1=6.184e-1, f2=6.164e-1, eta=9.998e-1, eps_f=7.302e-1, d=5.793e-3,
                         k1=6.380e-3, k3=8.656e-4),
    "fabric1-weft": dict(f1=2.173e-1, f2=2.161e-1, eta=9.876e-1, eps_f=7.316e-1, d=2.141e-3,
                         k1=4.548e-3, k3=1.619e-4),
    "fabric2-warp": dict(f1=7.836e-1, f2=7.810e-1, eta=9.949e-1, eps_f=7.207e-1, d=1.474e-2,
                         k1=1.154e-2, k3=1.092e-3),
    "fabric2-weft": dict(f1=1.600e-1, f2=1.600e-1, eta=9.932e-1, eps_f=7.646e-4, d=5.637e-3,
                         k1=3.722e-3, k3=5.436e-4),
}


@pytest.mark.parametrize("name", DATASET_NAMES)
def test_thesis_parameters_as_printed(name):
    # the harness's "thesis own" law carries the printed values (to 1e-4 relative: the
    # f1 = f2 tie of Table 4.13 is resolved with f_k = 2.12e-6); m was not a thesis parameter
    law = thesis_law(name)
    fr = law.friction
    got = to_kes(dict(k1=law.k1, k3=law.k3, d=law.d, f1=fr.f1, f2=fr.f2, eps_f=fr.eps_f,
                      eta=fr.eta))
    for k, v in PRINTED[name].items():
        assert got[k] == pytest.approx(v, rel=1e-4), k
    assert law.m == 0.0 and fr.f1 > fr.f2


@pytest.mark.parametrize("true", [
    dict(k1=5e-3, k3=2e-4, d=2e-3, f1=4e-3, f2=2.5e-3, eps_f=0.3, eta=0.5),
    dict(k1=8e-3, k3=1e-4, d=0.0, f1=3e-3, f2=1e-3, eps_f=1.0, eta=0.05),
])
def test_fit_recovers_known_parameters(true):
    # a loop simulated by run_kes (exact friction path, no noise), fitted without any guess:
    # every parameter within 0.5 % (d within 1e-6 gf·cm²·s/cm when it is 0)
    p = from_kes(true)
    law = BendingLaw(k1=p["k1"], k3=p["k3"], d=p["d"],
                     friction=FrictionParams(p["f1"], p["f2"], p["eps_f"], p["eta"]))
    prof = kes_profile(1e-3, accel_time=T)
    sim = run_kes(law, prof)
    loop = KESLoop("synthetic", prof.t, prof.kappa, prof.kappa_dot, prof.kappa_ddot, sim.moment,
                   prof.phase - 1, T, prof.rate, True)
    got = to_kes(fit_loop(loop).params())
    for k, v in true.items():
        if v == 0.0:
            assert abs(got[k]) < 1e-6
        else:
            assert got[k] == pytest.approx(v, rel=5e-3), k


def test_fit_is_global_against_a_finer_brute_force_grid(full_fits):
    # an independent brute-force search on a grid 2x finer in each direction (and offset)
    # finds no residual lower than the fit's (tolerance 1e-6 relative)
    r = full_fits["fabric1-weft"]
    proj = _Projector(r.loop, _variant("full"), False)
    u = np.linspace(-3.5 + 0.0625, 1.5, 40)
    w = np.linspace(-3.0 + 0.06, -1e-6, 25)
    U, W = np.meshgrid(u, w, indexing="ij")
    best = min(res for s in range(0, U.size, 100)
               for res, _ in proj.solve_batch(proj.friction_columns(U.flat[s:s + 100],
                                                                    W.flat[s:s + 100])))
    assert r.residual <= best * (1 + 1e-6)


def test_nested_variants_are_ordered():
    # a global fit of nested models gives ordered residuals:
    # asymmetric <= full <= no-cubic, no-friction <= linear
    res = {v: fit("fabric2-weft", v, T).residual
           for v in ("asymmetric", "full", "no-cubic", "no-friction", "linear")}
    tol = 1 + 1e-9
    assert res["asymmetric"] <= res["full"] * tol
    assert res["full"] <= res["no-cubic"] * tol
    assert res["full"] <= res["no-friction"] * tol
    assert res["no-cubic"] <= res["linear"] * tol
    assert res["no-friction"] <= res["linear"] * tol


def test_variant_structure():
    r = fit("fabric1-weft", "linear", T)
    assert r.law.friction is None and r.law.k3 == 0.0
    r = fit("fabric1-weft", "no-friction", T)
    assert r.law.friction is None and r.law.k3 > 0
    with pytest.raises(ValueError, match="variant 'bogus'"):
        fit("fabric1-weft", "bogus")


def test_fit_mass_is_nonnegative_and_helps_at_most_a_little():
    without = fit("fabric1-weft", "no-friction", T)
    with_m = fit("fabric1-weft", "no-friction", T, fit_mass=True)
    assert with_m.law.m >= 0.0
    assert with_m.residual <= without.residual * (1 + 1e-9)


JSON_KEYS = {"dataset", "variant", "accel_time", "residual", "params", "derived", "B", "2HB"}


def test_cli_json_has_documented_keys(tmp_path, capsys):
    out = tmp_path / "fit.json"
    assert main(["fabric2-weft", "--variant", "full", "--accel-time", "0.5",
                 "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "residual 4.17" in text and "f_s" in text and "gf·cm/cm" in text
    rec = json.loads(out.read_text())
    assert JSON_KEYS <= set(rec)
    assert set(rec["params"]) == {"m", "d", "k1", "k3", "f1", "f2", "eps_f", "eta"}
    assert set(rec["derived"]) == {"f_k", "f_s", "s_e", "s_p"}
    assert rec["dataset"] == "fabric2-weft" and rec["variant"] == "full"
    assert rec["accel_time"] == 0.5
    # KES units: f_k = f1 - f2 in gf·cm/cm, residual equals the printed one
    p = rec["params"]
    assert rec["derived"]["f_k"] == pytest.approx(p["f1"] - p["f2"], rel=1e-6, abs=1e-12)
    assert f"{rec['residual']:.4e}" in text


def test_cli_csv_and_plot(tmp_path):
    png = tmp_path / "loop.png"
    from pathlib import Path

    csv = Path(__file__).resolve().parents[3] / "tests" / "data" / "kes_small.csv"
    assert main([str(csv), "--variant", "linear", "--plot", str(png)]) == 0
    assert png.stat().st_size > 10_000


def test_cli_reports_bad_csv_rows_by_line(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("curvature,moment\n0,0\n1,abc\n")
    with pytest.raises(SystemExit) as exc:
        main([str(bad)])
    assert exc.value.code == 2
    assert "bad.csv: line 3: moment 'abc' is not a number" in capsys.readouterr().err


def test_cli_refuses_accel_times_that_are_no_numbers_in_one_line(capsys):
    for bad in ("abc", "0.5,-1", "nan"):
        with pytest.raises(SystemExit) as exc:
            main(["fabric1-warp", "--sweep-accel", bad])
        assert exc.value.code == 2
        err = capsys.readouterr().err
        assert err.startswith(f"error: --sweep-accel '{bad}'") and len(err.splitlines()) == 1


def test_cli_refuses_an_output_in_a_missing_folder_before_fitting(tmp_path, capsys):
    target = tmp_path / "missing" / "fit.json"
    assert main(["fabric1-warp", "--json", str(target)]) == 4
    err = capsys.readouterr().err
    assert err == f"error: cannot write {target}: its folder {target.parent} does not exist\n"
