"""Generated option values for ``drape identify``: each command is either accepted, and its
definition saved as given, or refused in one line with exit 2 (bad input) or 4 (a folder that
cannot be written), with nothing written.

No forward run starts: the cluster is a stand-in and the search is interrupted as Ctrl-C
interrupts it, once the definition is saved (exit 130), as in test_identify_options.py.
"""
from __future__ import annotations

import contextlib
import io
import json
import math
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from drape.cli.identify import main
from drape.identification.definition import DEFINITION
from drape.identification.parameters import PARAMETERS

ROOT = Path(__file__).resolve().parents[3]
CASE = ROOT / "cases" / "cusick_kes.toml"
KEYS = list(PARAMETERS)

numbers = st.one_of(st.integers(-5, 2_000_000_000).map(str),
                    st.floats(allow_nan=True, allow_infinity=True).map(repr),
                    st.sampled_from(["x", "", "1e400", "-0"]))
boxes = st.lists(st.tuples(st.sampled_from(KEYS + ["frobnicate"]),
                           st.floats(-1.0, 50.0) | st.sampled_from([math.inf, math.nan]),
                           st.floats(-1.0, 50.0)), max_size=2).map(
    lambda items: [f"{k}={lo:g},{hi:g}" for k, lo, hi in items])


#: Values in each option's range (the base case may still refuse a box's corner).
GOOD = {"--seeds": st.integers(1, 100).map(str),
        "--evaluations": st.integers(1, 10_000).map(str),
        "--design": st.integers(0, 100).map(str),
        "--converged-within": st.floats(0.0, 0.99).map(repr),
        "--weight": st.floats(1.0, 100.0).map(repr) | st.sampled_from(["124 g/m^2", "12 mg/cm^2"]),
        "--scale": st.just("1"),
        "--workers": st.integers(1, 256).map(str)}
#: Any value: out of range, of another type, junk.
ANY = {"--seeds": st.integers(-3, 150).map(str) | numbers,
       "--evaluations": st.integers(-3, 12_000).map(str) | numbers,
       "--design": st.integers(-3, 150).map(str) | numbers,
       "--converged-within": st.floats(-0.5, 1.5).map(repr) | numbers,
       "--weight": st.floats(-10.0, 300.0).map(repr) | st.sampled_from(
           ["124 g/m^2", "3 kg", "nan", "0.0124 g/cm^2"]),
       "--scale": st.sampled_from(["1", "1.0", "0", "-1", "0.001", "1000", "nan"]),
       "--workers": st.integers(-2, 300).map(str)}


@st.composite
def good_boxes(draw, free):
    items = []
    for key in draw(st.lists(st.sampled_from(free), unique=True, max_size=2)):
        low, high = PARAMETERS[key].limits
        lo, hi = sorted(draw(st.lists(st.floats(low, high), min_size=2, max_size=2, unique=True)))
        items.append(f"{key}={lo!r},{hi!r}")
    return items


@settings(max_examples=25, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(good=st.booleans(), data=st.data())
def test_an_option_is_saved_as_checked_or_refused_in_one_line(scan, no_runs, good, data):
    if good:
        values = data.draw(st.fixed_dictionaries({}, optional=GOOD))
        free = data.draw(st.none() | st.lists(st.sampled_from(KEYS), max_size=2).map(
            lambda keys: ["bending_length", *keys]))
        box = data.draw(good_boxes(free or ["bending_length", "hysteresis"]))
        library, out = data.draw(st.sampled_from([None, "new"])), "new"
    else:
        values = data.draw(st.fixed_dictionaries({}, optional=ANY))
        free = data.draw(st.none() | st.lists(st.sampled_from(KEYS), min_size=1, max_size=3))
        box = data.draw(boxes)
        library = data.draw(st.sampled_from([None, "new", "file", "out"]))
        out = data.draw(st.sampled_from(["new", "file"]))
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "file").write_text("x")
        folder = tmp / ("id" if out == "new" else "file")
        argv = [str(scan), "--base", str(CASE), "--out", str(folder)]
        argv += [f"{k}={v}" for k, v in values.items()]
        argv += [f"--box={item}" for item in box]
        argv += ["--free", *free] if free else []
        argv += {None: [], "new": ["--library", str(tmp / "lib")],
                 "file": ["--library", str(tmp / "file")], "out": ["--library", str(folder)]}[library]
        code, err = _run(argv)
        lines = err.splitlines()
        if code == 130:
            saved = json.loads((folder / DEFINITION).read_text())
            _assert_saved_as_given(saved, values, free)
            return
        assert code in (2, 4), (argv, err)
        assert len(lines) == 1 and lines[0].startswith("error: "), (argv, err)
        assert not (tmp / "id").exists() and not (tmp / "lib").exists()
        if good:    # in range, only a corner of the box may be no valid fabric
            assert "not a valid fabric" in lines[0], (argv, err)


def _assert_saved_as_given(saved: dict, values: dict, free) -> None:
    """The saved definition holds the values the options gave (within their ranges)."""
    for option, key in (("--seeds", "seeds"), ("--evaluations", "evaluations"),
                        ("--design", "design")):
        if option in values:
            assert saved[key] == int(values[option])
    for option, key in (("--converged-within", "converged_within"), ("--scale", "scale")):
        if option in values:
            assert saved[key] == float(values[option])
    assert 1 <= saved["seeds"] <= 100 and 0 <= saved["converged_within"] < 1
    if free:
        assert saved["free"] == list(dict.fromkeys(free))
    assert set(saved["box"]) == set(saved["free"])
    assert all(PARAMETERS[k].limits[0] <= lo < hi <= PARAMETERS[k].limits[1]
               for k, (lo, hi) in saved["box"].items())
    assert saved["weight"] is None or 1 <= saved["weight"] <= 100


def _run(argv) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(argv)
        except SystemExit as exc:
            code = exc.code
    return code, err.getvalue()
