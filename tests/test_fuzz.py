"""Generated values for every case key and for a sweep's run table: the runner answers each
with one line and a documented exit code within seconds, never a traceback or a hang.

The runner is called in-process with ``--check`` (validate and build, no time stepping). The
keys are enumerated from the case schema, so a new key is fuzzed as soon as it exists.
"""
from __future__ import annotations

import contextlib
import io
import time
from datetime import timedelta
from pathlib import Path

import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from drape.cli import common as cli
from drape.cli import run as run_cli
from drape.batch import rows as sweep_rows
from drape.case.case import Case

ROOT = Path(__file__).resolve().parents[1]
#: Base cases, made small so that a value that builds builds in milliseconds; the generated
#: override comes last and wins.
BASES = [
    (ROOT / "cases" / "cantilever.toml", ["mesh.nx=2", "mesh.ny=1"]),
    (ROOT / "cases" / "cusick_kes.toml", ["mesh.n_radial=1", "mesh.n_circumferential=8"]),
    (ROOT / "cases" / "kes_strip.toml", ["mesh.nx=2", "mesh.ny=1"]),
]
#: The exit codes a --check may end with: it builds (0) or the input is bad (2).
CHECKED = (cli.EXIT_OK, cli.EXIT_BAD_INPUT)
#: A generous bound on one answer (they take milliseconds; a hang would take forever).
SECONDS = 5.0


def case_keys() -> list[str]:
    """Every dotted key of the case schema, tables included (a table can be set whole)."""
    schema = Case.model_json_schema()
    defs = schema.get("$defs", {})
    keys: set[str] = set()

    def walk(node, prefix):
        if "$ref" in node:
            node = defs[node["$ref"].split("/")[-1]]
        if "properties" in node:
            keys.add(prefix)
            for name, sub in node["properties"].items():
                walk(sub, f"{prefix}.{name}" if prefix else name)
            return
        options = node.get("anyOf") or node.get("oneOf") or []
        tables = [o for o in options if "$ref" in o or "properties" in o]
        for option in tables:
            walk(option, prefix)
        keys.add(prefix)

    walk(schema, "")
    keys.discard("")
    return sorted(keys)


KEYS = case_keys()

unit_strings = st.sampled_from([
    "9**9**9 cm", "2**1000000 cm", "1e999 cm", "1e-999 cm", "-0 cm", "5 cm", "5 kg", "3 1/cm/s",
    "nan cm", "inf m", "5 __import__", "5 cm**99", "5 (cm", "()", "1/0 cm", "0x10 cm", "5 gf*cm",
    "12 mg/cm^2", "5 %", "5 degC", "",
])
path_tricks = st.sampled_from([
    "..", ".", "/", "../../etc/passwd", "/etc/passwd", "/dev/zero", "/proc/self/mem", "a/b",
    "~", "\x00", "nul", "con", "fabric1", "fabric1/../fabric1", " ", "x" * 300,
    str(ROOT / "cases"), str(ROOT / "cases" / "cantilever.toml"),
])
numbers = st.one_of(
    st.sampled_from([0, -1, 1, 2, 7, 2**31, 2**63 - 1, -(2**63), 10**30, 0.0, -0.0, 1e-300,
                     5e-324, 1e300, 1.7976931348623157e308, float("inf"), float("-inf"),
                     float("nan"), 0.5, 1e-9]),
    st.integers(min_value=-10, max_value=300),
    st.floats(allow_nan=True, allow_infinity=True),
)
scalars = st.one_of(numbers, st.booleans(), unit_strings, path_tricks, st.text(max_size=12))
values = st.one_of(scalars, st.lists(scalars, max_size=4),
                   st.dictionaries(st.sampled_from(["kind", "name", "path", "value", "x"]), scalars,
                                   max_size=3))


def as_set_value(value) -> str:
    """``value`` as the text after ``--set KEY=``: TOML where TOML can hold it."""
    if isinstance(value, str) and value.isidentifier():
        return value                                   # a bare word, read as a string
    try:
        return tomli_w.dumps({"v": value})[len("v = "):].strip()
    except (TypeError, ValueError):
        return str(value)


def check(case: Path, overrides: list[str]) -> tuple[int, str, str, float]:
    """``python -m drape.run CASE --check --set ...`` in-process: code, stdout, stderr, seconds."""
    out, err = io.StringIO(), io.StringIO()
    start = time.perf_counter()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = run_cli.main([str(case), "--check", *sum((["--set", o] for o in overrides), [])])
        except SystemExit as stop:                     # the option parser's own errors
            code = stop.code
    return code, out.getvalue(), err.getvalue(), time.perf_counter() - start


def assert_answered(code: int, out: str, err: str, seconds: float, what: str) -> None:
    assert seconds < SECONDS, f"{what}: {seconds:.1f} s"
    assert code in CHECKED, f"{what}: exit {code}: {err}"
    assert "Traceback" not in err + out, f"{what}: {err}"
    if code == cli.EXIT_OK:
        assert "OK —" in out, f"{what}: {out}"
    else:
        lines = err.splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: "), f"{what}: {err!r}"


@pytest.fixture(scope="module", autouse=True)
def warm():
    """Build each base once, so that no example pays for the first imports."""
    for case, small in BASES:
        assert check(case, small)[0] == cli.EXIT_OK


FUZZ = settings(max_examples=100, deadline=timedelta(seconds=SECONDS), derandomize=True,
                database=None, suppress_health_check=[HealthCheck.too_slow])


def test_every_case_key_is_enumerated():
    assert {"mesh.length", "case.name", "material.kes.B_warp", "load.perturbation.seed",
            "solver.dt", "model.damping.alpha"} <= set(KEYS)
    assert len(KEYS) > 100


@FUZZ
@given(base=st.sampled_from(BASES), key=st.sampled_from(KEYS), value=values)
def test_any_value_of_any_case_key_is_answered_in_one_line(base, key, value):
    case, small = base
    item = f"{key}={as_set_value(value)}"
    assert_answered(*check(case, small + [item]), what=f"{case.name} --set {item!r}")


@FUZZ
@given(key=st.sampled_from(KEYS + ["measured.DC", "name", "bending_scale", "mesh..nx", ".x"]),
       cells=st.lists(st.one_of(st.just(""), scalars.map(as_set_value)), min_size=1, max_size=3),
       name=st.one_of(path_tricks, st.sampled_from(["", "a", "run-1"])))
def test_any_run_table_is_read_or_refused_in_one_line(tmp_path_factory, key, cells, name):
    """A run table's columns and cells: read_table refuses it, or each row's case is checked."""
    import csv

    table = tmp_path_factory.mktemp("table") / "runs.csv"
    with open(table, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["name", key])
        writer.writerows([[f"{name}{i}" if name else "", cell] for i, cell in enumerate(cells)])
    try:
        rows = sweep_rows.read_table(table)
    except sweep_rows.SweepError as exc:
        assert "\n" not in str(exc)
        return
    case, small = BASES[0]
    for row in rows:
        assert_answered(*check(case, small + row.overrides()), what=f"row {row}")
