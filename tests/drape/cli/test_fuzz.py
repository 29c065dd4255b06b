"""Generated values for every case key and for a sweep's run table: the runner answers each
with one line and a documented exit code within seconds, never a traceback or a hang.

The runner is called in-process with ``--check`` (validate and build, no time stepping). The
keys are enumerated from the case schema, so a new key is fuzzed as soon as it exists. Run
tables are drawn mostly valid, so that most of them reach the rows' checks and must build
there, with a fixed share broken on purpose in every way a table can be, each of which must
be refused in one line.
"""
from __future__ import annotations

import contextlib
import csv
import io
import time
from collections import Counter
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

ROOT = Path(__file__).resolve().parents[3]
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


# --------------------------------------------------------------------------- run tables
def _number(low: float, high: float, unit: str = ""):
    return st.floats(low, high).map(lambda x: f"{x:.6g}{unit}")


#: Columns a run table of the cantilever base may have, each with cells its rules accept
#: (``measured.*`` columns take any number).
VALID_COLUMNS = {
    "material.bending_scale": _number(0.25, 4.0),
    "material.friction": st.sampled_from(["true", "false"]),
    "mesh.nx": st.integers(2, 4).map(str),
    "mesh.ny": st.integers(1, 2).map(str),
    "mesh.length": _number(1.0, 5.0, " cm"),
    "solver.dt": _number(0.002, 0.02),
    "solver.t_end": _number(0.5, 8.0),
    "model.damping.alpha": _number(0.0, 60.0),
    "load.gravity.ramp_time": _number(0.05, 1.0),
    "measured.DC": _number(0.0, 100.0),
    "measured.nodes": st.integers(0, 12).map(str),
}
#: Cells that break the rule of their column.
BAD_CELLS = {
    "material.bending_scale": ["-1", "0", "nan", "inf", "stiff"],
    "material.friction": ["maybe", "2"],
    "mesh.nx": ["0", "-2", "1.5", "many"],
    "mesh.ny": ["0", "-1"],
    "mesh.length": ["-1 cm", "0 cm", "5 kg", "5 __import__"],
    "solver.dt": ["-0.01", "0", "nan"],
    "solver.t_end": ["-1", "0"],
}
#: Column names a run table refuses (not dotted) or a row's case refuses (no such key).
UNDOTTED = ["bending_scale", "nx", "friction", "measured"]
MISSPELT = ["material.bending_scal", "mesh.nxx", "solver.dtt", "mesh..nx", ".x", "mesh."]
#: Run names that cannot name a run's folder, whitespace aside.
BAD_NAMES = ["..", "a/b", "../x", "-a", ".hidden", "a b", "é"]
#: How a table is broken on purpose.
BREAKS = ("undotted column", "misspelt key", "repeated column", "bad run name",
          "repeated run name", "ragged row", "bad cell", "no runs")
#: Valid tables per table broken on purpose, each example having one broken each way: a share
#: of 1/(VALID_PER_BROKEN + 1) broken, and every way tried, whatever way Hypothesis leans in
#: its draws. The valid ones must all be read and built; the floor on the share that is holds
#: the mix to mostly valid tables.
VALID_PER_BROKEN = 4
ACCEPTED_FLOOR = 0.75
#: Examples of a few dozen tables each.
TABLE_FUZZ = settings(FUZZ, max_examples=4,
                      deadline=timedelta(seconds=(VALID_PER_BROKEN + 1) * len(BREAKS) * SECONDS))


@st.composite
def valid_tables(draw) -> tuple[list[str], list[list[str]]]:
    """A header and rows that a sweep of the cantilever reads and builds: known columns, cells
    within their rules or blank (the base case's value), unique run names or none."""
    columns = draw(st.lists(st.sampled_from(sorted(VALID_COLUMNS)), min_size=1, max_size=4,
                            unique=True))
    n = draw(st.integers(1, 3))
    cells = [[draw(st.one_of(st.just(""), VALID_COLUMNS[c])) for c in columns] for _ in range(n)]
    for row in cells:
        if not any(row):                   # a blank line is no run
            row[0] = draw(VALID_COLUMNS[columns[0]])
    if draw(st.booleans()):
        names = draw(st.lists(st.from_regex(r"[A-Za-z0-9][A-Za-z0-9._-]{0,8}", fullmatch=True),
                              min_size=n, max_size=n, unique=True))
        return ["name", *columns], [[name, *row] for name, row in zip(names, cells)]
    return columns, cells


def _break(draw, how: str, header: list[str], rows: list[list[str]]):
    """``header`` and ``rows`` broken the way ``how`` says (every way is refused)."""
    keys = [i for i, c in enumerate(header) if c != "name"]
    if how == "undotted column":
        header[draw(st.sampled_from(keys))] = draw(st.sampled_from(UNDOTTED))
    elif how == "misspelt key":
        i = draw(st.sampled_from(keys))
        header[i] = draw(st.sampled_from(MISSPELT))
        rows[0][i] = "1"                  # a blank cell would keep the base: nothing to refuse
    elif how == "repeated column":
        i = draw(st.sampled_from(keys))
        header.append(header[i])
        for row in rows:
            row.append(row[i])
    elif how in ("bad run name", "repeated run name"):
        if header[0] != "name":
            header.insert(0, "name")
            rows[:] = [[f"r{k}", *row] for k, row in enumerate(rows)]
        if how == "bad run name":
            rows[draw(st.integers(0, len(rows) - 1))][0] = draw(st.sampled_from(BAD_NAMES))
        else:
            rows.append(list(rows[0]))
    elif how == "ragged row":
        rows[draw(st.integers(0, len(rows) - 1))].append("1")
    elif how == "bad cell":
        column = draw(st.sampled_from(sorted(BAD_CELLS)))
        if column not in header:
            header.append(column)
            for row in rows:
                row.append("")
        rows[draw(st.integers(0, len(rows) - 1))][header.index(column)] = \
            draw(st.sampled_from(BAD_CELLS[column]))
    else:                                  # "no runs": the header alone
        rows.clear()
    return header, rows


@st.composite
def run_table_batches(draw) -> list[tuple[list[str], list[list[str]], str | None]]:
    """Tables ``(header, rows, broken)``: for each way in :data:`BREAKS`, one broken that way
    (``broken`` says how) and :data:`VALID_PER_BROKEN` valid ones (``broken`` None)."""
    tables = []
    for how in BREAKS:
        tables += [(*draw(valid_tables()), None) for _ in range(VALID_PER_BROKEN)]
        header, rows = draw(valid_tables())
        tables.append((*_break(draw, how, header, rows), how))
    return tables


def _read_and_check(path: Path, broken: str | None) -> str:
    """Read the table at ``path`` and check each row's case: "accepted" or "refused", after
    asserting each answer is one line and the verdict the one ``broken`` calls for."""
    try:
        rows = sweep_rows.read_table(path)
    except sweep_rows.SweepError as exc:
        assert "\n" not in str(exc)
        assert broken, f"a valid table refused: {exc}"
        return "refused"
    case, small = BASES[0]
    answers = [check(case, small + row.overrides()) for row in rows]
    for row, answer in zip(rows, answers):
        assert_answered(*answer, what=f"row {row}")
    refused = [row for row, answer in zip(rows, answers) if answer[0] != cli.EXIT_OK]
    assert bool(refused) == bool(broken), f"{broken or 'valid'} table, rows refused: {refused}"
    return "refused" if refused else "accepted"


@pytest.mark.slow
def test_run_tables_are_mostly_read_and_built_and_the_broken_ones_refused(tmp_path_factory):
    """Mostly valid run tables: each is read and every row builds. A share is broken on
    purpose, every way of :data:`BREAKS`, and refused in one line, by the table reader or by a
    row's check. The share read and built is printed (``-s`` or ``-rA``) and held above a floor."""
    verdicts: Counter = Counter()
    breaks: Counter = Counter()

    @TABLE_FUZZ
    @given(tables=run_table_batches())
    def one(tables):
        for header, rows, broken in tables:
            path = tmp_path_factory.mktemp("table") / "runs.csv"
            with open(path, "w", newline="") as fh:
                csv.writer(fh).writerows([header, *rows])
            verdicts[_read_and_check(path, broken)] += 1
            breaks[broken] += 1

    one()
    total = sum(verdicts.values())
    accepted = verdicts["accepted"] / total
    print(f"run tables: {verdicts['accepted']} of {total} read and built ({accepted:.0%}, floor "
          f"{ACCEPTED_FLOOR:.0%}); {total - breaks[None]} broken on purpose, all refused: "
          + ", ".join(f"{how} {breaks[how]}" for how in BREAKS))
    assert accepted >= ACCEPTED_FLOOR
    assert breaks[None] < total
