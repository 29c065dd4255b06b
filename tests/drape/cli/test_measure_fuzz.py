"""Generated scans and options for ``drape measure``: never a traceback, never exit 1, each
problem one line; a whole synthetic drape, in whatever unit and file format, measured to its
hem's drape coefficient within :data:`DC_TOLERANCE` points.

The drapes are the parametric skirts of tests/drape/conftest.py (hem ``r0 + A cos(n phi)``, at
least 24 sectors a fold), whole or corrupted: turned, shuffled, cut in half or by a sector,
holed, upside down, with a stray vertex, collapsed to a line, cut to one triangle, with a
NaN vertex.
"""
from __future__ import annotations

import contextlib
import io
import json
import math
import tempfile
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from drape.cli.measure import main

#: A whole synthetic drape's DC against its hem's (points): the hem polygon's chords, at 24
#: sectors a fold or more, cut at most 0.11 points off the smooth hem's area.
DC_TOLERANCE = 0.2
RD = 0.09
CORRUPTIONS = ["none", "shuffle", "half", "sector", "hole", "flip", "stray", "collapse", "one",
               "nan"]
UNITS = {"m": 1.0, "cm": 100.0, "mm": 1000.0}
#: Option values: plausible ones (the standard set-up), and slips, junk and absurd numbers.
SPECIMEN = ["30cm", "0.3", "300 mm", "30", "-1", "nan", "3 kg", "", "1e400", "24cm", "0.3 m"]
DISC = ["18cm", "0.18", "180mm", "1cm", "12cm", "18", "0", "inf", "x"]
TOP_BAND = ["0.3mm", "1mm", "0.3", "-1mm", "3e-4"]


@st.composite
def drapes(draw):
    n = draw(st.integers(3, 12))
    r0 = draw(st.floats(0.10, 0.142))
    # the crests stop 3 mm short of the 15 cm hem: a crest reaching it does not hang at all, and
    # its sector, flat out to the hem, is part of the flat top (refused as a disc too large)
    amplitude = draw(st.floats(0.0, 1.0)) * min(r0 - RD - 0.005, 0.147 - r0)
    return dict(n_folds=n, amplitude=amplitude, r0=r0, phase=draw(st.floats(0.0, 2 * math.pi)),
                centre=(draw(st.floats(-0.01, 0.01)), draw(st.floats(-0.01, 0.01))),
                n_sectors=24 * n + draw(st.integers(0, 48)), n_rings=draw(st.integers(3, 6)),
                with_top=draw(st.booleans()))


def corrupt(drape, kind: str, rng: np.random.Generator) -> None:
    """Corrupt ``drape`` (a SyntheticDrape) in place."""
    p, t = drape.points, drape.triangles
    xy = p[:, :2] - drape.centre
    r, angle = np.hypot(*xy.T), np.mod(np.arctan2(xy[:, 1], xy[:, 0]), 2 * np.pi)
    start = rng.uniform(0, 2 * np.pi)
    within = np.mod(angle - start, 2 * np.pi)
    if kind == "shuffle":
        order = rng.permutation(len(p))
        drape.points, drape.triangles = p[order], np.argsort(order)[t][rng.permutation(len(t))]
    elif kind in ("half", "sector", "hole"):
        gone = {"half": within < np.pi,
                "sector": (within < np.radians(rng.uniform(2, 60))) & (r > RD + 1e-3),
                "hole": (within < rng.uniform(0.05, 0.8)) & (r > RD + 0.002) & (r < RD + 0.012)}
        drape.triangles = t[~gone[kind][t].any(axis=1)]
    elif kind == "flip":
        p[:, 2] *= -1.0
    elif kind == "stray":
        p[rng.integers(len(p))] = [10.0 ** rng.integers(1, 30), -(10.0 ** rng.integers(1, 30)), 0.0]
    elif kind == "collapse":
        p[:, 1:] = 0.0
    elif kind == "one":
        drape.triangles = t[:1]
    elif kind == "nan":
        p[rng.integers(len(p)), rng.integers(3)] = np.nan


#: What a whole drape measured with the standard options ends with, by corruption: refused
#: (2), measured without a word (0), or measured with a warning ("warning").
EXPECTED = {"none": 0, "shuffle": 0, "half": 2, "flip": "warning", "stray": 2, "collapse": 2,
            "one": 2, "nan": 2}


@st.composite
def options(draw, scale: float, centre: tuple, folder: Path) -> tuple[bool, list[str]]:
    """Whether the options are the standard set-up's (in any spelling, the true centre or
    none, a folder that can be written or none), and the options."""
    standard = draw(st.booleans())
    pick = (lambda values, good: draw(st.sampled_from(good))) if standard else (
        lambda values, good: draw(st.none() | st.sampled_from(values)))
    argv = []
    if not standard or scale != 1.0 or draw(st.booleans()):
        argv += ["--scale", f"{1 / scale:g}"] if standard or draw(st.booleans()) else []
    for name, values, good in (("specimen", SPECIMEN, [None, "30cm", "0.3", "300 mm"]),
                               ("disc", DISC, [None, "18cm", "0.18", "180mm"]),
                               ("top-band", TOP_BAND, [None, "0.3mm", "3e-4"])):
        value = pick(values, good)
        argv += [f"--{name}={value}"] * (value is not None)
    true = f"--centre={1e3 * centre[0]:.6f}mm,{1e3 * centre[1]:.6f}mm"
    argv += pick([], [[], [true]]) if standard else draw(st.sampled_from(
        [[], [true], ["--centre=0,0"], ["--centre=2,-1"]]))
    argv += pick([], [[], ["--out", str(folder / "out")]]) if standard else draw(st.sampled_from(
        [[], ["--out", str(folder / "out")], ["--out", str(folder / "file")]]))
    return standard, argv


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(shape=drapes(), kind=st.sampled_from(CORRUPTIONS), unit=st.sampled_from(list(UNITS)),
       fmt=st.sampled_from(["ply", "obj", "stl", "vtu"]), data=st.data(),
       seed=st.integers(0, 2**16))
def test_measure_answers_every_scan_and_option_in_one_line(
        drape_surface, shape, kind, unit, fmt, data, seed):
    drape = drape_surface(**shape)
    corrupt(drape, kind, np.random.default_rng(seed))
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        path = drape.write(tmp / f"scan.{fmt}", UNITS[unit])
        (tmp / "file").write_text("x")
        standard, argv = data.draw(options(UNITS[unit], drape.centre, tmp))
        code, stdout, stderr = _run([str(path), "--json", *argv])
    assert code in (0, 2, 4), (argv, stderr)
    assert "Traceback" not in stderr
    lines = stderr.splitlines()
    assert all(line.startswith(("error: ", "warning: ")) for line in lines), stderr
    assert sum(line.startswith("error: ") for line in lines) <= 1, stderr     # one scan
    if code == 4:
        assert str(tmp / "file") in argv and stdout == ""
    expected = EXPECTED.get(kind)
    if not standard or expected is None or (kind == "flip" and any("--centre" in a for a in argv)):
        return
    if expected == "warning":
        assert code == 0 and len(lines) == 1 and lines[0].startswith("warning: "), stderr
    else:
        assert code == expected and (lines == []) == (code == 0), (argv, stderr)
    if code == 0:
        (measured,) = json.loads(stdout)["scans"]
        assert abs(measured["drape_coefficient_percent"] - drape.dc_percent) <= DC_TOLERANCE


@settings(max_examples=12, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(shape=drapes(), unit=st.sampled_from(list(UNITS)),
       fmt=st.sampled_from(["ply", "obj", "stl", "vtu"]),
       specimen=st.sampled_from(["30cm", "0.3", "300 mm", "0.3 m"]),
       disc=st.sampled_from(["18cm", "0.18", "180mm"]), shuffle=st.booleans(),
       seed=st.integers(0, 2**16))
def test_a_whole_drape_in_any_unit_and_format_gives_its_hems_dc(
        drape_surface, shape, unit, fmt, specimen, disc, shuffle, seed):
    drape = drape_surface(**shape)
    if shuffle:
        corrupt(drape, "shuffle", np.random.default_rng(seed))
    with tempfile.TemporaryDirectory() as tmp:
        path = drape.write(Path(tmp) / f"scan.{fmt}", UNITS[unit])
        code, stdout, stderr = _run([str(path), "--json", "--scale", f"{1 / UNITS[unit]:g}",
                                     f"--specimen={specimen}", f"--disc={disc}"])
    assert (code, stderr) == (0, "")
    (measured,) = json.loads(stdout)["scans"]
    assert abs(measured["drape_coefficient_percent"] - drape.dc_percent) <= DC_TOLERANCE
    if shape["amplitude"] > 0.002:      # folds 4 mm deep or more: the node detection sees them
        assert measured["n_nodes"] == shape["n_folds"]


def _run(argv) -> tuple[int, str, str]:
    """Exit code, stdout and stderr of ``drape measure ARGV`` run in this process."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(argv)
        except SystemExit as exc:       # an option error exits from the parser
            code = exc.code
    return code, out.getvalue(), err.getvalue()
