"""The platform Peirce case against a separately computed strip: an inextensible elastica with the
same bending law, clamped or pushed over a perfect clamp (:mod:`constitutive.elastica`), which
shares nothing with the shell, its contact or its time stepping."""
import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from constitutive import elastica
from constitutive.material import load_material
from constitutive.units import G0
from drape.analyses.bending_length import bending_length
from drape.cli.run import main as run

CASES = Path(__file__).resolve().parents[3] / "cases"
ELASTIC = ["--set", "material.friction=false", "--set", "material.d=0"]


@pytest.fixture(scope="module")
def fabric1():
    material = load_material("fabric1")
    return material.warp, material.areal_mass * G0


@pytest.mark.slow
def test_elastic_elastica_pushed_meets_the_line_where_clamped_it_does(fabric1):
    """Without memory the pushed strip is at every overhang what the clamped one is: clamped at
    the overhang where the pushed one met 41.5°, it hangs at 41.5° (to the interpolation
    between segments). With the law's friction the pushed strip is bent more, so it meets the
    line earlier."""
    law, weight = fabric1
    elastic = dataclasses.replace(law, friction=None)
    overhang = elastica.pushed_overhang(elastic, weight, 0.0145, 0.0175, 1e-4)
    assert elastica.clamped_chord(elastic, weight, overhang, 1e-4) == pytest.approx(41.5, abs=0.02)
    hysteretic = elastica.pushed_overhang(law, weight, 0.0145, 0.0175, 1e-4)
    assert elastica.clamped_chord(law, weight, hysteretic, 1e-4) < 41.5 - 0.5     # measured 40.73°


@pytest.mark.slow
def test_a_stiffer_grip_reads_closer_to_the_perfect_clamp(fabric1):
    """The elastic strip pushed through a grip of foundation stiffness K meets the line short of
    the perfect clamp, by a rotation at the edge that shrinks like K^(-1/4) (a beam on an elastic
    foundation): measured 2.8 % short at K = 10⁹ N/m³, 0.9 % at 10¹¹."""
    law, weight = fabric1
    elastic = dataclasses.replace(law, friction=None)
    clamp = elastica.pushed_overhang(elastic, weight, 0.0145, 0.0175, 5e-5)
    soft, stiff = (elastica.gripped_overhang(elastic, weight, 0.022, 0.0145, 0.0175, 5e-5, k) / clamp
                   for k in (1e9, 1e11))
    assert soft < stiff < 1.0
    assert 1.0 - stiff == pytest.approx((1.0 - soft) * 100 ** -0.25, rel=0.25)
    # the same grip at points 0.25 mm apart (contact points) gives more than spread evenly
    points = elastica.gripped_overhang(elastic, weight, 0.022, 0.0145, 0.0175, 5e-5, 1e11, every=5) / clamp
    assert points < stiff


@pytest.mark.slow
def test_elastica_hangs_at_the_clamped_shell_cantilevers_chord_angle(tmp_path, fabric1):
    """cases/cantilever.toml (the shell, the law with its friction, dynamic settling) and the
    elastica clamped at the same overhang under a growing weight: chord angles within 0.05°."""
    law, weight = fabric1
    assert run([str(CASES / "cantilever.toml"), "--out", str(tmp_path), "--quiet"]) == 0
    shell = json.loads((tmp_path / "summary.json").read_text())["analysis"]
    reference = elastica.clamped_chord(law, weight, shell["overhang_m"], 1e-4)
    assert shell["chord_angle_deg"] == pytest.approx(reference, abs=0.05)


@pytest.mark.slow
def test_platform_meets_the_line_within_1_percent_of_a_perfect_clamp(tmp_path, fabric1):
    """cases/peirce_platform.toml with an elastic strip (the grip compared alone): the overhang at
    which its tip meets 41.5°, so its bending length, within 1 % of the elastica's over a perfect
    clamp (measured: 0.6 % short, from the grip's give)."""
    law, weight = fabric1
    assert run([str(CASES / "peirce_platform.toml"), "--out", str(tmp_path), "--quiet", *ELASTIC]) == 0
    platform = json.loads((tmp_path / "summary.json").read_text())["analysis"]
    reference = elastica.pushed_overhang(dataclasses.replace(law, friction=None), weight, 0.0145, 0.0175, 1e-4)
    assert platform["reached"]
    assert platform["overhang_m"] == pytest.approx(reference, rel=0.01)
    assert platform["overhang_m"] < reference      # a grip gives: the strip turns at the edge
    assert np.isfinite(platform["bending_length_peirce_m"])


@pytest.mark.slow
def test_platform_with_the_law_gives_the_clamped_cantilevers_bending_length_within_2_percent(
        tmp_path, fabric1):
    """The tester as shipped (the law with its friction): Peirce's bending length read on the
    platform within 2 % of the clamped cantilever's (the elastica clamped at cases/cantilever.toml's
    1.63 cm, which the shell cantilever meets within 0.05°, test above). Measured 1.9 % short:
    1.2 % is the test's own physics (a perfect clamp pushed reads that short, since every section
    is bent hardest at the edge and its friction keeps it bent), the rest the grip's give.
    Pushed over a perfect clamp the elastica meets the line within 1 % of where the shell does."""
    law, weight = fabric1
    assert run([str(CASES / "peirce_platform.toml"), "--out", str(tmp_path), "--quiet"]) == 0
    platform = json.loads((tmp_path / "summary.json").read_text())["analysis"]
    clamped_at = 0.0163
    clamped_c = bending_length(clamped_at, np.radians(elastica.clamped_chord(law, weight, clamped_at, 1e-4)))
    assert platform["reached"]
    assert platform["bending_length_peirce_m"] == pytest.approx(clamped_c, rel=0.02)
    assert platform["bending_length_peirce_m"] < clamped_c
    pushed = elastica.pushed_overhang(law, weight, 0.0145, 0.0175, 1e-4)
    assert platform["overhang_m"] == pytest.approx(pushed, rel=0.01)


@pytest.mark.slow
def test_the_grip_converges_with_the_exact_tangent_and_not_with_the_projected_one(tmp_path):
    """Held between platform and ruler, the strip's first load step converges with the exact
    barrier Hessian; projected on the positive semi-definite cone pair by pair (IPC's), the
    tangent overstates the grip's stiffness and the residual falls only by a constant factor per
    iteration (a half with IPC's own pairs, under 5 % with one pair per point), so the step fails
    at every bisection (docs/theory.md §7). The strip is taken 0.5 mm wide, five times the
    case's width: its contact forces, five times larger, keep the linear rate above round-off."""
    case = str(CASES / "peirce_platform.toml")
    short = ["--quiet", "--set", "solver.t_end=0.04", "--set", "mesh.width=0.05cm"]
    assert run([case, "--out", str(tmp_path / "exact"), *short]) == 0
    assert run([case, "--out", str(tmp_path / "projected"), *short, "--set", "contact.hessian=projected"]) == 3
    summary = json.loads((tmp_path / "projected" / "summary.json").read_text())
    norms = [float(v) for v in summary["reason"].split("residual norms [")[1].split("]")[0].split(", ")]
    assert all(0.4 < b / a < 1.0 for a, b in zip(norms, norms[1:]))     # linear, not quadratic


@pytest.mark.slow
def test_one_pair_per_point_pushes_the_strip_past_the_edge_where_ipcs_pairs_stall(tmp_path):
    """The case's strip with its fine zone from 4.5 mm: with IPC's own pairs the push stalls as a
    contact point passes the platform's edge (t ≈ 0.70 s, where the edge has moved 0.2 mm; 0.99 s
    on a strip 0.5 mm wide); with one pair per point, continuous there, it goes on
    (docs/theory.md §7)."""
    case = str(CASES / "peirce_platform.toml")
    past = ["--quiet", *ELASTIC, "--set", "mesh.fine_zone.start=4.5mm", "--set", "mesh.fine_zone.nx=50",
            "--set", "solver.t_end=1.04", "--set", "output.every_dt=0.52"]
    assert run([case, "--out", str(tmp_path / "per_point"), *past]) == 0
    assert run([case, "--out", str(tmp_path / "ipc"), *past, "--set", "contact.pairs=ipc"]) == 3
    stalled = json.loads((tmp_path / "ipc" / "summary.json").read_text())
    assert 0.6 < stalled["t_final"] < 1.0      # while the push is on (it starts at 0.6 s)
