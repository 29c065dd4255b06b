"""Contact as given: bodies, half-spaces and [contact] tables refused with one line, units
read, and short runs of case files with a body (the contact core itself: test_contact.py)."""
from types import SimpleNamespace

import numpy as np
import pytest

from drape.contact.bodies import ContactInputError, HalfSpace, RigidBody

from contact_sheet import THICKNESS, plane, sheet


# ---------------------------------------------------------------------------- input


def test_fabric_starting_inside_a_body_is_refused():
    with pytest.raises(ContactInputError, match="intersecting body .slab."):
        sheet(bodies=[RigidBody("slab", plane([0.1, 0.1, 0.0], [0.2, 0, 1]))])
    with pytest.raises(ContactInputError, match="closer than half its thickness"):
        sheet(bodies=[RigidBody("slab", plane([0.1, 0.1, -0.2 * THICKNESS], [0, 0, 1]))])


@pytest.mark.parametrize("surface, mu, message", [
    (SimpleNamespace(vertices=[[0, 0, np.nan], [1, 0, 0], [0, 1, 0]], triangles=[[0, 1, 2]]), 0.1, "NaN"),
    (SimpleNamespace(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], triangles=np.zeros((0, 3), int)), 0.1,
     "not a surface"),
    (SimpleNamespace(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], triangles=[[0, 1, 2]]), -0.1, "mu = -0.1"),
])
def test_bad_bodies_are_refused_with_one_line(surface, mu, message):
    with pytest.raises(ContactInputError, match=message) as err:
        RigidBody("b", surface, mu)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("point, normal, path, message", [
    ([0, 0, 0.01], [0, 0, 1], None, "behind it"),
    ([0, 0, -1e-4], [0, 0, 1], None, "closer than half its thickness"),
    ([0, 0, -0.01], [0, 0, 0], None, "normal must not be the zero vector"),
    ([0, 0, np.nan], [0, 0, 1], None, "NaN"),
    ([0, 0, -0.01], [0, 0, 1], ([0.0, 1.0], [[0, 0, 0], [0.01, 0, 0]]), "moves along its normal only"),
])
def test_bad_half_spaces_are_refused_with_one_line(point, normal, path, message):
    from drape.contact.motion import RigidPath

    with pytest.raises(ContactInputError, match=message) as err:
        sheet(bodies=[HalfSpace("floor", point, normal, path=None if path is None else RigidPath(*path))])
    assert len(str(err.value).splitlines()) == 1


# ---------------------------------------------------------------------------- case file


def case_with(contact, kinematics="large"):
    from drape.case.case import parse_case

    return parse_case({
        "case": {"name": "c"}, "material": {"name": "fabric1"},
        "mesh": {"kind": "rectangle", "length": 0.1, "width": 0.1, "nx": 2, "ny": 2,
                 "element": "argyris"},
        "model": {"kinematics": kinematics, "supports": {}},
        "solver": {"dt": 0.01, "t_end": 0.1}, "contact": contact})


@pytest.mark.parametrize("contact, kinematics, message", [
    ({"body": [{"name": "t", "shape": "plane", "point": [0, 0, -0.01], "size": 1.0, "mu": -0.2}]},
     "large", r"contact.body\[0\].mu = -0.2: must be >= 0"),
    ({"body": [{"name": "t", "shape": "plane", "point": [0, 0, -0.01], "size": 1.0}]}, "small",
     r"\[contact\] needs model.kinematics = 'large'"),
    ({"body": [{"name": "t", "shape": "sphere", "centre": [0, 0, -1], "radius": 0.5},
               {"name": "t", "shape": "sphere", "centre": [0, 0, -3], "radius": 0.5}]},
     "large", "names must be unique: t given twice"),
    ({"body": [{"name": "t", "shape": "cone", "centre": [0, 0, -1]}]}, "large", r"contact.body\[0\].shape = .cone.: must be one of"),
    ({"dhat": "-1 mm"}, "large", "contact.dhat"),
    ({"pairs": "nearest"}, "large", "contact.pairs"),
    ({"pairs": "per_point", "body": [{"name": "post", "shape": "cylinder", "centre": [0, 0, -0.1],
                                      "radius": 0.05, "length": 0.2, "mu": 0.3}]},
     "large", "per_point.* friction only on a plane or half-space: body 'post'"),
    ({"pairs": "per_point", "self_contact": True, "mu_self": 0.2}, "large",
     "per_point.* friction only on a plane or half-space: the fabric itself"),
])
def test_bad_contact_tables_are_refused_with_one_line(contact, kinematics, message):
    from drape.case.case import CaseError

    with pytest.raises(CaseError, match=message) as err:
        case_with(contact, kinematics)
    assert len(str(err.value).splitlines()) == 1


def test_contact_table_reads_units():
    case = case_with({"thickness": "0.4 mm", "dhat": "2 mm", "eps_v": "1 mm/s",
                      "body": [{"name": "ball", "shape": "sphere", "centre": ["0 cm", "0 cm", "-5 cm"],
                                "radius": "4 cm", "path": {"times": [0, 1], "translations": [[0, 0, 0],
                                                                                            [0, 0, 0.01]]}}]})
    spec = case.contact
    assert (spec.thickness, spec.dhat, spec.eps_v) == pytest.approx((4e-4, 2e-3, 1e-3))
    assert spec.body[0].centre == pytest.approx((0.0, 0.0, -0.05)) and spec.body[0].radius == pytest.approx(0.04)


# ---------------------------------------------------------------------------- a run


CASE = """
[case]
name = "drop"
[mesh]
kind = "rectangle"
length = "10 cm"
width = "10 cm"
nx = 3
ny = 3
[material]
name = "fabric1"
[model]
kinematics = "large"
supports = {}
[model.damping]
alpha = 5.0
[load.gravity]
ramp_time = 0.0
[solver]
dt = 0.01
t_end = 0.06
alpha_hht = -0.3
[contact]
dhat = "1 mm"
"""


def run_case_text(tmp_path, bodies, capsys):
    from drape.cli.run import main as run

    path = tmp_path / "case.toml"
    path.write_text(CASE + bodies)
    code = run([str(path), "--out", str(tmp_path / "out"), "--quiet"])
    return code, capsys.readouterr().err.strip()


def test_a_case_drops_the_fabric_on_a_plane_and_it_stays_above(tmp_path, capsys):
    code, err = run_case_text(tmp_path, """
[[contact.body]]
name = "table"
shape = "plane"
point = ["5 cm", "5 cm", "-5 mm"]
size = "30 cm"
mu = 0.3
""", capsys)
    assert code == 0, err
    history = np.genfromtxt(tmp_path / "out" / "history.csv", delimiter=",", names=True)
    half = 0.5 * 0.254e-3                                     # half of Fabric 1's thickness
    assert history["uz_min"].min() < -0.004                  # it fell onto the table ...
    assert history["uz_min"].min() > -0.005 + half           # ... and not through it
    assert np.isfinite(history["contact_potential"]).all()


@pytest.mark.parametrize("body, message", [
    ('shape = "mesh"\nfile = "nowhere.stl"', "contact.body 'b': "),
    ('shape = "sphere"\ncentre = [0.05, 0.05, 0.0]\nradius = "2 cm"', "starts intersecting body 'b'"),
    # a slip of a digit is refused before any array is made (it would fill the memory)
    ('shape = "sphere"\ncentre = [0.05, 0.05, -1.0]\nradius = "2 cm"\nresolution = 2147483648',
     "triangles asked for, more than 100,000; check its resolution"),
    ('shape = "half_space"\npoint = [0, 0, "-5 mm"]\npath = { times = [0, 1], translations = [[0, 0, 0], [0.01, 0, 0]] }',
     "contact.body 'b': a half-space moves along its normal only"),
    ('shape = "half_space"\npoint = [0, 0, "1 mm"]', "from the plane of body 'b', behind it"),
])
def test_a_case_with_an_unusable_body_exits_2_with_one_line(tmp_path, capsys, body, message):
    code, err = run_case_text(tmp_path, f'[[contact.body]]\nname = "b"\n{body}\n', capsys)
    assert code == 2
    assert message in err and len(err.splitlines()) == 1


def test_a_case_lays_the_fabric_on_a_half_space_and_draws_it(tmp_path, capsys):
    from drape.run.pictures import contact_bodies

    code, err = run_case_text(tmp_path, """
[[contact.body]]
name = "floor"
shape = "half_space"
point = [0, 0, "-5 mm"]
rotation_deg = [0, 0, 30]
mu = 0.3
""", capsys)
    assert code == 0, err
    history = np.genfromtxt(tmp_path / "out" / "history.csv", delimiter=",", names=True)
    half = 0.5 * 0.254e-3                                     # half of Fabric 1's thickness
    assert -0.005 + half < history["uz_min"].min() < -0.004  # on the floor, not through it
    drawn = contact_bodies(tmp_path / "out")(0.0, extent=0.1)
    assert len(drawn) == 1 and np.allclose(drawn[0].vertices[:, 2], -0.005)
    assert np.ptp(drawn[0].vertices[:, 0]) > 0.1             # wider than the fabric
