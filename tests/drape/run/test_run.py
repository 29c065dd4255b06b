"""The case runner: wiring, failure handling, settling, CLI, and short end-to-end runs."""
from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from types import SimpleNamespace

import meshio

import numpy as np
import pytest
import pyvista
import scipy.sparse as sp

from drape.models.protocol import Evaluation
from drape import analyses
from drape.cli import run as run_cli
from drape.run import runner
from drape.run.settling import out_of_balance
from drape.case.case import CaseError, apply_overrides, load_case, parse_case
from drape.run.output import read_pvd

ROOT = Path(__file__).resolve().parents[3]
CASES = ROOT / "cases"
G = 9.80665


class VertexOscillators:
    """Private stand-in model: one independent damped oscillator per mesh vertex (w only).

    ``m a + c v + k u = −λ(t) m g``; Newton fails (NaN residual) once ``t > fail_after``.
    """

    def __init__(self, mesh, m=0.2, k=50.0, c=0.0, gravity=lambda t: 1.0, fail_after=np.inf):
        self.mesh = mesh
        self.ndofs = mesh.p.shape[1]
        self.fixed_dofs = np.zeros(0, dtype=int)
        self.load_scale = 1.0
        self.m, self.k, self.c = m, k, c
        self.gravity, self.fail_after = gravity, fail_after
        eye = sp.identity(self.ndofs, format="csr")
        self.M, self.K, self.C = m * eye, k * eye, c * eye
        self.rayleigh = (c / m, 0.0)
        self.commits = 0
        self.seconds = {"law": 0.0, "assembly": 0.0}

    symmetric_tangent = True

    def prescribed(self, t):
        return None

    def lifting(self, t):
        return None

    def force_scale(self, t):
        return self.m * G * math.sqrt(self.ndofs)      # |weight vector|

    def evaluate(self, u, v, a, t, tangent=None, weights=None):
        f = -self.load_scale * self.gravity(t) * self.m * G * np.ones(self.ndofs)
        force = self.C @ v + self.K @ u - f
        if t > self.fail_after:
            force = force * np.nan
        return Evaluation(self.M @ a, force, *((self.K, self.C, self.M) if tangent else ())).weighted(weights)

    def commit(self, u, v, a):
        self.commits += 1

    def state_dict(self):
        return {"commits": np.array(self.commits)}

    def load_state_dict(self, state):
        self.commits = int(state["commits"])

    def energies(self, u, v, t=None):
        return {"kinetic": 0.5 * self.m * float(v @ v), "strain": 0.5 * self.k * float(u @ u)}

    def fields(self, u, v, a):
        disp = np.zeros((self.ndofs, 3))
        disp[:, 2] = u
        n_cells = self.mesh.t.shape[1]
        return {"point_data": {"displacement": disp},
                "cell_data": {"curvature": np.zeros((n_cells, 3)), "moment_xx": np.zeros(n_cells)}}


def small_case(**over):
    data = {
        "case": {"name": "fake"},
        "mesh": {"kind": "strip", "length": 0.05, "width": 0.02, "nx": 3, "ny": 1},
        "material": {"name": "fabric1"},
        "model": {"supports": {"clamped": "clamped"}},
        "solver": {"dt": 0.01, "t_end": 0.1},
    }
    toml = lambda v: str(v).lower() if isinstance(v, bool) else str(v)  # noqa: E731
    apply_overrides(data, [f"{k}={toml(v)}" for k, v in over.items()])
    return parse_case(data)


def fake_parts(case, **kw):
    from skfem import MeshTri

    mesh = MeshTri.init_tensor(np.linspace(0, case.mesh.length, case.mesh.nx + 1),
                               np.linspace(0, case.mesh.width, case.mesh.ny + 1))
    mesh = mesh.with_boundaries({"clamped": lambda x: x[0] < 1e-12})
    return runner.Parts(mesh, SimpleNamespace(areal_mass=0.2), VertexOscillators(mesh, **kw))


def read_history(out):
    with open(out / "history.csv") as fh:
        return [{k: float(v) if v != "" else None for k, v in row.items()} for row in csv.DictReader(fh)]


def test_failed_run_keeps_every_converged_step_with_a_readable_pvd(tmp_path):
    case = small_case(**{"solver.max_cuts": 0})
    parts = fake_parts(case, fail_after=0.025)        # steps at 0.01, 0.02 converge; 0.03 cannot
    summary = runner.run_case(case, tmp_path, quiet=True, parts=parts)

    assert summary["status"] == "failed"
    assert "no convergence" in summary["reason"] and "t = 0.02" in summary["reason"]
    on_disk = json.loads((tmp_path / "summary.json").read_text())
    assert on_disk["status"] == "failed" and on_disk["reason"] == summary["reason"]
    assert on_disk["t_final"] == pytest.approx(0.02, rel=1e-12)

    history = read_history(tmp_path)
    assert [row["step"] for row in history] == [0, 1, 2]
    assert parts.model.commits == 2                   # nothing committed after the failure

    listed = read_pvd(tmp_path / "fake.pvd")
    assert [t for t, _ in listed] == pytest.approx([0.0, 0.01, 0.02], rel=1e-12)
    reader = pyvista.get_reader(str(tmp_path / "fake.pvd"))
    assert reader.number_time_points == 3
    for (t, path), row in zip(listed, history):
        m = meshio.read(path)
        assert m.point_data["displacement"][:, 2] == pytest.approx(row["uz_min"], rel=1e-12, abs=0)
        assert set(m.cell_data) >= {"curvature_xx", "curvature_yy", "curvature_xy", "moment_xx"}
    log = (tmp_path / "run.log").read_text()
    assert "stopped: " in log and "Newton did not converge" in log
    assert (tmp_path / "case.resolved.toml").exists()


def test_inspect_draws_the_stopped_run_and_its_history(tmp_path, capsys):
    from PIL import Image

    from drape.cli import inspect

    case = small_case(**{"solver.max_cuts": 0})
    runner.run_case(case, tmp_path, quiet=True, parts=fake_parts(case, fail_after=0.025))
    assert inspect.main([str(tmp_path), "--field", "displacement", "--step", "1"]) == 0
    printed = capsys.readouterr().out.split()
    assert [Path(p).name for p in printed] == ["fake_displacement_0001.png", "history.png"]
    for p in printed:
        with Image.open(p) as im:
            assert im.size[0] > 300 and im.size[1] > 300
            assert np.unique(np.asarray(im.convert("L"))).size > 10   # a picture, not a blank
    assert inspect.main([str(tmp_path), "--field", "nope"]) == 2
    assert "available: curvature_xx" in capsys.readouterr().err


def test_cli_failure_prints_reason_and_exits_3(tmp_path, monkeypatch, capsys):
    case_file = tmp_path / "c.toml"
    case_file.write_text('[case]\nname = "fake"\n[mesh]\nkind = "strip"\nlength = 0.05\n'
                         'width = 0.02\nnx = 3\n[material]\nname = "fabric1"\n'
                         '[solver]\ndt = 0.01\nt_end = 0.1\n')
    monkeypatch.setattr(runner, "build", lambda case: fake_parts(case, fail_after=0.015))
    code = run_cli.main([str(case_file), "--out", str(tmp_path / "o"), "--quiet",
                        "--set", "solver.max_cuts=1"])
    err = capsys.readouterr().err
    assert code == 3 and len(err.splitlines()) == 1
    # 0.01 converges, 0.02 fails, the cut step to 0.015 converges, its successor fails at dt/2
    assert "FAILED at t = 0.015 s" in err and "Newton did not converge" in err
    assert "3 VTU files" in err


def test_cli_bad_case_exits_2_with_one_line_naming_the_key(tmp_path, capsys):
    case_file = tmp_path / "c.toml"
    case_file.write_text('[case]\nname = "x"\n[mesh]\nkind = "strip"\nlength = 0.05\n'
                         'width = 0.02\nnx = 3\n[material]\nname = "fabric1"\n'
                         '[model]\ndampin = {alpha = 1.0}\n[solver]\ndt = 0.01\nt_end = 0.1\n')
    assert run_cli.main([str(case_file), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"error: in {case_file}: unknown key 'model.dampin' (did you mean 'damping'?)"]


def test_check_builds_without_running(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert run_cli.main([str(CASES / "kes_strip.toml"), "--check"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("kes_strip: OK — KirchhoffPlate, ") and "analysis kes" in out
    assert "membrane taken at" not in out               # a plate has no membrane
    assert not any(tmp_path.iterdir())                 # nothing written
    assert run_cli.main([str(CASES / "validation" / "wool_tropical.toml"), "--check"]) == 0
    from constitutive.tensile import DEFAULT_TENSILE
    from drape.analyses.drape_coefficient import skirt_tension

    tension = skirt_tension(0.1629 * 9.80665, 0.127, 0.0635)    # the wool's W, its 25.4/12.7 cm
    E = DEFAULT_TENSILE.tangent(tension)
    lines = capsys.readouterr().out.splitlines()
    assert lines[1] == (f"  membrane taken at T = {tension:.3g} N/m: E11 = {E:.4g} N/m, E22 = {E:.4g} N/m, "
                        "G12 = 25.28 N/m")            # the set-up's G = 0.45 gf/(cm·deg)
    assert lines[2] == f"  damping C = {0.3 / 0.1629:.3g} 1/s M + 0 s K0"    # the air drag over ρ_A


def test_cli_missing_boundary_exits_2_listing_the_mesh_boundaries(tmp_path, capsys):
    code = run_cli.main([str(CASES / "cantilever.toml"), "--out", str(tmp_path / "o"), "--quiet",
                        "--set", "model.supports={clampd='clamped'}"])
    assert code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"error: in {CASES / 'cantilever.toml'}: model.supports names boundary 'clampd' "
                   "which the mesh does not have; available: bottom, clamped, free_end, left, "
                   "right, top"]


def test_settling_stops_the_run_once_the_static_out_of_balance_is_small(tmp_path):
    # critically damped oscillators: settle well before t_end
    case = small_case(**{"solver.t_end": 2.0, "solver.dt": 0.01, "load.gravity.ramp_time": 0.1,
                         "stop.out_of_balance": 1e-4, "stop.steps": 3, "output.every_dt": 0.5,
                         "solver.atol": 1e-12})   # force round-off floor near rest ~1e-13 N
    parts = fake_parts(case, c=2 * np.sqrt(50.0 * 0.2), gravity=lambda t: case.load.gravity.amplitude(t))
    summary = runner.run_case(case, tmp_path, quiet=True, parts=parts)
    assert summary["status"] == "settled", summary["reason"]
    assert summary["reason"].startswith("static out-of-balance") and "for 3 steps" in summary["reason"]
    history = read_history(tmp_path)
    assert summary["t_final"] < 2.0 and history[-1]["t"] == summary["t_final"]
    # independent: every oscillator is out of balance by |k u + m g| against a weight m g each
    ratio = [abs(50.0 * row["tip_uz"] + 0.2 * G) / (0.2 * G) for row in history]
    assert [row["out_of_balance"] for row in history if row["t"] >= 0.1] == pytest.approx(
        [r for r, row in zip(ratio, history) if row["t"] >= 0.1], rel=1e-6, abs=1e-12)
    assert all(row["out_of_balance"] is None for row in history if row["t"] < 0.1 - 1e-9)
    assert all(r < 1e-4 for r in ratio[-3:]) and ratio[-4] >= 1e-4
    # static deflection of each oscillator: u = −m g / k (independent of the runner)
    assert history[-1]["tip_uz"] == pytest.approx(-0.2 * G / 50.0, rel=1e-4)
    # every_dt output: t = 0, first steps past 0.5, 1.0, ... and the final step
    times = [t for t, _ in read_pvd(tmp_path / "fake.pvd")]
    assert times[0] == 0.0 and times[-1] == pytest.approx(summary["t_final"])
    assert all(abs(t / 0.5 - round(t / 0.5)) < 1e-9 for t in times[:-1])


def test_out_of_balance_leaves_out_inertia_damping_and_supported_dofs():
    mesh = fake_parts(small_case()).mesh
    model = VertexOscillators(mesh, c=3.0)
    model.fixed_dofs = np.array([0, 2])
    rng = np.random.default_rng(0)
    u, v, a = rng.normal(size=(3, model.ndofs))
    free = np.setdiff1d(np.arange(model.ndofs), [0, 2])
    want = np.linalg.norm(50.0 * u[free] + 0.2 * G)          # k u − f_ext, no m a, no c v
    assert out_of_balance(model, u, 0.0) == pytest.approx(want, rel=1e-12)
    assert model.evaluate(u, v, a, 0.0).residual[free] != pytest.approx(50.0 * u[free] + 0.2 * G)
    model.prescribed = lambda t: (np.array([1, 3]), np.zeros(2))   # imposed dofs carry reactions
    rest = np.setdiff1d(free, [1, 3])
    assert out_of_balance(model, u, 0.0) == pytest.approx(np.linalg.norm(50.0 * u[rest] + 0.2 * G))


def test_the_kinetic_energy_keys_are_rejected_naming_the_new_key():
    for key in ("kinetic_fraction", "kinetic_energy"):
        with pytest.raises(CaseError, match=rf"stop\.{key} is no longer read.*stop\.out_of_balance"):
            small_case(**{f"stop.{key}": 1e-6})


def test_a_quasi_static_run_takes_no_explicit_settling_rule():
    from drape.run.settling import Settling

    assert not Settling(small_case(**{"solver.quasi_static": True})).active     # in balance anyway
    with pytest.raises(CaseError, match=r"stop\.out_of_balance needs a dynamic run"):
        small_case(**{"solver.quasi_static": True, "stop.out_of_balance": 1e-3})


def test_settling_dt_lengthens_the_step_only_once_the_loads_are_constant(tmp_path):
    case = small_case(**{"solver.t_end": 2.0, "solver.dt": 0.01, "solver.settling_dt": 0.05,
                         "load.gravity.ramp_time": 0.1, "stop.out_of_balance": 1e-4,
                         "stop.steps": 3, "output.every_dt": 0.5, "solver.atol": 1e-12})
    parts = fake_parts(case, c=2 * np.sqrt(50.0 * 0.2), gravity=lambda t: case.load.gravity.amplitude(t))
    summary = runner.run_case(case, tmp_path, quiet=True, parts=parts)
    assert summary["status"] == "settled", summary["reason"]
    rows = read_history(tmp_path)[1:]
    ramp = [r["dt"] for r in rows if r["t"] <= 0.1 + 1e-12]
    after = [r["dt"] for r in rows if r["t"] > 0.1 + 1e-12]
    assert ramp == pytest.approx([0.01] * 10)
    # then the step starts again at dt, never shrinks (no output mark is landed on) and grows
    # up to settling_dt but not beyond; how fast it grows is the integrator's policy
    assert after[0] == pytest.approx(0.01)
    assert all(b >= a * (1 - 1e-12) for a, b in zip(after, after[1:]))
    assert max(after) == pytest.approx(0.05) and all(d <= 0.05 * (1 + 1e-12) for d in after)
    assert all(r["cuts"] == 0 for r in rows)
    # the same static deflection as the fine-stepped run (u = −m g / k)
    assert rows[-1]["tip_uz"] == pytest.approx(-0.2 * G / 50.0, rel=1e-4)


def test_settling_dt_shorter_than_dt_is_rejected_naming_the_key():
    with pytest.raises(Exception, match=r"solver\.settling_dt.*must not be shorter than solver\.dt"):
        small_case(**{"solver.settling_dt": 0.001})


def test_quasi_static_path_follows_the_load_history_and_cycle_reports_each_level(tmp_path):
    hist = "[[0.0, 0.0], [1.0, 1.0], [2.0, -0.5], [3.0, 0.0]]"
    case = small_case(**{"solver.quasi_static": True, "solver.dt": 0.25, "solver.t_end": 3.0,
                         "load.gravity.history": hist, "load.gravity.smooth": False,
                         "case.analysis": "cycle"})
    parts = fake_parts(case, gravity=lambda t: case.load.gravity.amplitude(t))
    summary = runner.run_case(case, tmp_path, quiet=True, parts=parts)
    assert summary["status"] == "completed"
    history = read_history(tmp_path)
    t = np.array([row["t"] for row in history])
    np.testing.assert_allclose(t, np.arange(0, 3.01, 0.25), atol=1e-12)
    static = -0.2 * G / 50.0                          # u = −m g / k of each oscillator
    expected = static * np.interp(t, [0, 1, 2, 3], [0, 1, -0.5, 0])
    np.testing.assert_allclose([row["tip_uz"] for row in history], expected, rtol=1e-9, atol=1e-15)
    levels = summary["analysis"]["levels"]
    assert [lv["gravity_factor"] for lv in levels] == [0.0, 1.0, -0.5, 0.0]
    np.testing.assert_allclose([lv["tip_uz"] for lv in levels], static * np.array([0, 1, -0.5, 0]),
                               rtol=1e-9, atol=1e-15)
    (residual,) = summary["analysis"]["residual_after_unloading"]   # elastic: nothing left
    assert residual["t"] == 3.0 and abs(residual["tip_uz"]) < 1e-15


def test_analysis_registry_probe_and_finish_reach_history_and_summary(tmp_path):
    calls = []

    def probe(ctx, fields):
        return {"mean_uz": float(np.mean(fields["displacement"][:, 2]))}

    @analyses.register("tiny", probe=probe)
    def finish(ctx):
        calls.append(len(ctx.history))
        return {"last_mean_uz": ctx.history[-1]["mean_uz"]}

    try:
        case = small_case(**{"case.analysis": "tiny"})    # registered names become valid case values
        summary = runner.run_case(case, tmp_path, quiet=True, parts=fake_parts(case))
    finally:
        analyses.unregister("tiny")
    with pytest.raises(CaseError, match="case.analysis = 'tiny': must be one of 'none', "):
        small_case(**{"case.analysis": "tiny"})
    assert calls == [11]
    assert summary["analysis"]["name"] == "tiny"
    assert summary["analysis"]["last_mean_uz"] == pytest.approx(read_history(tmp_path)[-1]["mean_uz"])


def test_help_and_help_case(capsys):
    with pytest.raises(SystemExit) as info:
        run_cli.main(["--help"])
    assert info.value.code == 0
    assert "--set KEY=VALUE" in capsys.readouterr().out
    assert run_cli.main(["--help-case"]) == 0
    out = capsys.readouterr().out
    assert "[solver]" in out and "out_of_balance" in out


# ----------------------------------------------------------------- end to end (real parts)
def test_kes_strip_end_to_end_reports_B_close_to_the_material_driver(tmp_path):
    from constitutive.kes import kes_profile, kes_values, run_kes

    out = tmp_path / "kes"
    code = run_cli.main([str(CASES / "kes_strip.toml"), "--out", str(out), "--quiet",
                        "--set", "solver.dt=0.1"])
    assert code == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed"
    case = load_case(out / "case.resolved.toml")
    material = runner.build_material(case)
    # independent reference: the constitutive driver on the same law and profile samples
    p = kes_profile(dt=case.solver.dt, **case.load.kes.profile_kwargs())
    history = read_history(out)
    np.testing.assert_allclose([row["t"] for row in history], p.t, atol=1e-9)
    loop = run_kes(material.warp, p)
    B_ref, HB2_ref = kes_values(loop.kappa, loop.moment)
    # the plate lifts the imposed rotation with the profile's exact rates: FE = law to round-off
    assert summary["analysis"]["B"] == pytest.approx(B_ref, rel=1e-9)
    assert summary["analysis"]["HB2"] == pytest.approx(HB2_ref, rel=1e-9)
    moment = np.array([row["moment"] for row in history])
    assert np.max(np.abs(moment - loop.moment)) <= 1e-9 * np.max(np.abs(loop.moment))
    assert summary["analysis"]["max_moment_difference_rel"] <= 1e-9


def test_real_plate_that_cannot_converge_stops_cleanly(tmp_path, capsys):
    # friction makes the loaded plate nonlinear: one Newton iteration cannot also pass the
    # increment test, so the first step fails and nothing after step 0 may be on disk
    out = tmp_path / "fail"
    code = run_cli.main([str(CASES / "cantilever.toml"), "--out", str(out), "--quiet",
                        "--set", "model.kinematics=small", "--set", "solver.max_iter=1",
                        "--set", "solver.max_cuts=0"])
    assert code == 3
    assert "FAILED at t = 0 s" in capsys.readouterr().err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "failed" and "max_iter=1" in summary["reason"]
    assert "analysis" not in summary                    # no post-processing of a failed run
    ((t, vtu),) = read_pvd(out / "cantilever.pvd")
    assert t == 0.0 and meshio.read(vtu).point_data["displacement"].shape[1] == 3
    assert pyvista.get_reader(str(out / "cantilever.pvd")).number_time_points == 1


def test_cantilever_runs_short_from_the_command_line(tmp_path):
    out = tmp_path / "cant"
    code = run_cli.main([str(CASES / "cantilever.toml"), "--out", str(out), "--quiet",
                        "--set", "solver.t_end=0.02", "--set", "solver.dt=0.01",
                        "--set", "stop.after=10.0", "--set", "case.analysis='none'"])
    assert code == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed" and summary["t_final"] == pytest.approx(0.02)
    assert len(read_pvd(out / f"{summary['case']}.pvd")) >= 2
    resolved = load_case(out / "case.resolved.toml")
    assert resolved.solver.t_end == 0.02


def test_kes_summary_material_uses_the_material_library_units():
    """[material.kes] takes the units a KES sheet prints (docs/theory.md §1): W 12.5 mg/cm² is 0.125 kg/m²,
    0.30 mm is 3e-4 m; B in gf·cm²/cm (× 9.80665e-5 N·m) comes back from the built law's simulated loop."""
    case = load_case(Path(__file__).parents[3] / "cases" / "cusick_kes.toml")
    material = runner.build_material(case)
    assert material.areal_mass == pytest.approx(0.125, rel=1e-12)
    assert material.thickness == pytest.approx(3.0e-4, rel=1e-12)
    assert material.simulated_kes()["warp"].B == pytest.approx(case.material.kes.B_warp * 9.80665e-5, rel=0.02)


def test_bending_scale_makes_the_same_fabric_stiffer():
    """[material] bending_scale = 8 multiplies every moment of both laws (so the simulated KES
    B and 2HB, and the default twist rigidity) by 8, keeps the friction lengths and the weight:
    the bending length doubles."""
    base = load_case(Path(__file__).parents[3] / "cases" / "cusick_fabric1.toml")
    stiff = load_case(Path(__file__).parents[3] / "cases" / "cusick_fabric1.toml",
                      ["material.bending_scale=8"])
    a, b = runner.build_material(base), runner.build_material(stiff)
    assert b.areal_mass == a.areal_mass
    assert b.twist_rigidity == pytest.approx(8 * a.twist_rigidity, rel=1e-12)
    for d in ("warp", "weft"):
        la, lb = getattr(a, d), getattr(b, d)
        assert lb.friction.eps_f == la.friction.eps_f and lb.friction.eta == la.friction.eta
        ka, kb = a.simulated_kes()[d], b.simulated_kes()[d]
        assert kb.B == pytest.approx(8 * ka.B, rel=1e-9)
        assert kb.HB2 == pytest.approx(8 * ka.HB2, rel=1e-9)
        c = lambda law, m: (law.k1 / (m.areal_mass * 9.80665)) ** (1 / 3)  # noqa: E731
        assert c(lb, b) == pytest.approx(2 * c(la, a), rel=1e-12)
    with pytest.raises(Exception, match="bending_scale"):
        load_case(Path(__file__).parents[3] / "cases" / "cusick_fabric1.toml", ["material.bending_scale=0"])


def test_nonnegative_friction_tangent_changes_newton_only_not_the_solution(tmp_path):
    """Fabric 2 (softening weft friction) on the cantilever: the floored tangent reaches the
    same states as the consistent one (same residual; only Newton's matrix differs)."""
    tips = {}
    for ft in ("consistent", "nonnegative"):
        case = load_case(Path(__file__).parents[3] / "cases" / "cantilever.toml",
                         ["material.name=fabric2", f"model.friction_tangent={ft}", "solver.t_end=0.5",
                          "solver.settling_dt=0.01"])
        runner.run_case(case, tmp_path / ft, quiet=True)
        tips[ft] = np.array([row["tip_uz"] for row in read_history(tmp_path / ft)])
    assert len(tips["consistent"]) == len(tips["nonnegative"]) > 40
    np.testing.assert_allclose(tips["nonnegative"], tips["consistent"], rtol=1e-7, atol=1e-12)
    with pytest.raises(Exception, match="friction_tangent"):
        load_case(Path(__file__).parents[3] / "cases" / "cantilever.toml", ["model.friction_tangent=secant"])
