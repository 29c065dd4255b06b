"""The contact cases: each shipped case builds, and a short run of the strip dropped onto a
slope folds onto itself without any two of its triangles crossing, at any written step, as
the independent intersection check (Möller's test, not the solver's distances) reads the VTU
files."""
from pathlib import Path

import numpy as np
import pytest

from drape.analyses.intersections import intersections, self_intersections
from drape.analyses.platform_reading import centre_line
from drape.analyses.scan import read_scan
from drape.case.case import load_case
from drape.case.contact_build import body_surface
from drape.cli.run import main as run
from drape.run.output import read_pvd
from drape.run.pictures import contact_bodies

CASES = Path(__file__).resolve().parents[3] / "cases"
CONTACT_CASES = ["table_drape", "sphere_drape", "drop_fold", "peirce_platform"]


@pytest.mark.parametrize("name", CONTACT_CASES)
def test_contact_case_builds(name):
    out = run([str(CASES / f"{name}.toml"), "--check"])
    assert out == 0


@pytest.mark.slow
def test_short_drop_folds_without_crossing_itself_or_a_body(tmp_path):
    """The case's first half second: the strip slides down the slope, its leading end stops on
    the mat and the rest rides up onto it. Every written step is checked, fabric against itself
    and against each body."""
    path = CASES / "drop_fold.toml"
    code = run([str(path), "--out", str(tmp_path), "--set", "solver.t_end=0.5",
                "--set", "output.every_dt=0.01", "--set", "stop.out_of_balance=0"])
    assert code == 0
    case = load_case(path)
    bodies = [body_surface(b) for b in case.contact.body]      # they stand still in this case
    drawn = contact_bodies(tmp_path)(0.3)                      # what drape inspect draws
    assert [len(b.triangles) for b in drawn] == [len(b.triangles) for b in bodies]
    assert all(np.array_equal(a.vertices, b.vertices) for a, b in zip(drawn, bodies))
    steps = read_pvd(tmp_path / "drop_fold.pvd")
    assert len(steps) >= 40
    for t, vtu in steps:
        points, triangles = read_scan(vtu)
        assert len(self_intersections(points, triangles)) == 0, f"the fabric crosses itself at t = {t}"
        for body in bodies:
            assert len(intersections(points, triangles, body.vertices, body.triangles)) == 0, t
    # it did fold: along the strip its centre line turns back on itself in x
    from meshes import rectangle

    mesh = rectangle(0.3, 0.04, case.mesh.nx, case.mesh.ny)
    reference = np.column_stack([mesh.p.T, np.zeros(mesh.p.shape[1])])
    _, line = centre_line(mesh, points - reference)
    assert (np.diff(line[:, 0]) < 0).any()


def test_cloth_laid_on_a_table_stays_on_it_under_its_full_weight(tmp_path):
    """The table's top is triangulated: a cloth vertex resting on it is in a dozen barrier pairs
    (its triangle, its neighbours', its edges with the edges beneath). With the barrier
    stiffness divided by that count, the cloth laid at mid-layer under its full weight at once
    stays within the barrier layer (1 mm) over the first 0.02 s; with the per-pair stiffness
    (1.1e5 N/m³, given by ``--set contact.barrier_stiffness``) the table throws it 8 mm up."""
    assert highest_lift("table_drape", tmp_path, 0.02, "mesh.nx=6", "mesh.ny=6",
                        "load.gravity.ramp_time=0") < 1e-3


def test_cusick_specimen_laid_on_its_support_starts_at_rest(tmp_path):
    """The lowered Cusick case lays the specimen in the middle of the barrier layer on its
    support, an exact plane (a half-space: one barrier pair per resting vertex, so the stiffness
    is the per-pair one), under its full weight at once: it stays within the layer until the
    support moves."""
    assert highest_lift("cusick_lowered", tmp_path, 0.1, "mesh.n_radial=2",
                        "mesh.n_circumferential=22") < 1e-3


def highest_lift(name, out, t_end, *overrides) -> float:
    """Largest upward displacement [m] over the steps of a short run of a shipped case to ``t_end``."""
    sets = [a for o in (*overrides, f"solver.t_end={t_end}", "stop.out_of_balance=0") for a in ("--set", o)]
    assert run([str(CASES / f"{name}.toml"), "--out", str(out), "--quiet", *sets]) == 0
    history = np.genfromtxt(out / "history.csv", delimiter=",", names=True)
    assert history["t"][-1] == pytest.approx(t_end)
    return float(history["uz_max"].max())
