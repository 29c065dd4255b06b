"""An identification's definition: what ``DIR/identify.json`` holds, every value checked.

The keys are the options of ``drape identify`` (:data:`OPTIONS`): the scans and their scale,
the base case and its ``--set`` items, the free parameters and their box, the seeds, the
budget, the initial design, the weight and the libraries. :func:`check_definition` checks each
against its stated range (:data:`COUNTS`, the parameters' limits, the KES sheet's weights) and
returns the definition as it is stored; a problem is one line naming the option. A stored
definition is read back by :func:`read_definition`, which says what is wrong with one that
cannot be used, so that ``--resume`` with the corrected options can replace it.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

from constitutive.bundled import cases_dir
from constitutive.material.kes_sheet import read_sheet_value
from drape.identification.parameters import DEFAULT_FREE, PARAMETERS, check_box
from drape.identification.search import CONVERGED_WITHIN
from drape.run.atomic import atomic_write_text

__all__ = ["DEFINITION", "OPTIONS", "COUNTS", "DEFAULT_BASE", "DEFAULTS", "BUDGET", "check_definition",
           "read_definition", "write_definition"]

#: The identification's definition in its folder, read back by ``--resume``.
DEFINITION = "identify.json"

#: The option each key comes from.
OPTIONS = {"scans": "SCAN", "scale": "--scale", "base": "--base", "set": "--set",
           "free": "--free", "box": "--box", "seeds": "--seeds", "evaluations": "--evaluations",
           "converged_within": "--converged-within", "design": "--design", "weight": "--weight",
           "library": "--library", "bundled_library": "--no-bundled-library"}

#: The stated ranges (inclusive) of the counts: seeds a point, points run in a folder, points
#: of the initial design (beyond a hundred, more than any budget spends).
COUNTS = {"seeds": (1, 100), "evaluations": (1, 10_000), "design": (0, 100)}

#: The base case when none is given: the one Cusick set-up (``cases/setups/cusick.toml``) with a
#: starting fabric, the case the bundled library of forward runs was run on.
DEFAULT_BASE = cases_dir("cusick_lowered.toml")

#: What a key not given is (a definition stored before a key existed has it so too).
DEFAULTS = {"base": str(DEFAULT_BASE), "scale": 1.0, "set": [], "free": list(DEFAULT_FREE), "seeds": 2, "evaluations": 14,
            "converged_within": CONVERGED_WITHIN, "design": None, "weight": None,
            "library": None, "bundled_library": False}

#: The keys a resumed identification may change: its budget.
BUDGET = ("evaluations", "converged_within")


def _file(path, option: str) -> str:
    """``path`` resolved, if it is an existing file."""
    if not isinstance(path, str) or not path:
        raise ValueError(f"{option}: {path!r} is no file name")
    p = Path(path)
    if p.is_dir():
        raise ValueError(f"{option} {path}: is a folder, not a file")
    if not p.is_file():
        raise ValueError(f"{option} {path}: no such file")
    return str(p.resolve())


def _count(key: str, value) -> int:
    low, high = COUNTS[key]
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise ValueError(f"{OPTIONS[key]} = {value!r}: must be a whole number from {low} to {high}")
    return value


def _number(key: str, value, ok, rule: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not ok(float(value)):
        raise ValueError(f"{OPTIONS[key]} = {value!r}: {rule}")
    return float(value)


def _weight(value) -> float | None:
    if value is None:
        return None
    try:
        return read_sheet_value("weight", value)
    except ValueError as exc:
        raise ValueError(f"--weight {value}: {exc}") from None


def _free(value) -> list[str]:
    if not isinstance(value, list) or not value or not all(k in PARAMETERS for k in value):
        raise ValueError(f"--free {value!r}: choose from {', '.join(PARAMETERS)}")
    free = list(dict.fromkeys(value))
    if "bending_length" not in free:
        raise ValueError("--free must include bending_length (the drape's first parameter)")
    return free


def _strings(key: str, value) -> list[str]:
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise ValueError(f"{OPTIONS[key]}: {value!r} is no list of items")
    return list(value)


def check_definition(definition: dict) -> dict:
    """``definition`` checked, with the defaults of the keys it lacks; as it is stored.

    Raises
    ------
    ValueError
        One line naming the option whose value breaks its rule: a key unknown or missing, a
        scan or base case that is no file, a count out of :data:`COUNTS`, a box beyond the
        parameters' limits, a weight outside the KES sheet's range, a scale that is no
        positive number.
    """
    unknown = sorted(set(definition) - set(OPTIONS))
    if unknown:
        raise ValueError(f"{DEFINITION}: unknown keys {', '.join(unknown)}")
    d = {**DEFAULTS, **definition}
    if "scans" not in d or not isinstance(d["scans"], list) or not d["scans"]:
        raise ValueError("give the scans to identify from (SCAN ...)")
    free = _free(d["free"])
    checked = {
        "scans": [_file(s, "SCAN") for s in d["scans"]],
        "scale": _number("scale", d["scale"], lambda x: math.isfinite(x) and x > 0,
                         "must be a positive number (0.001 for scans in millimetres)"),
        "base": _file(d["base"], "--base"), "set": _strings("set", d["set"]), "free": free,
        "box": {k: list(v) for k, v in check_box(d.get("box", _default_box(free)), free).items()},
        "seeds": _count("seeds", d["seeds"]), "evaluations": _count("evaluations", d["evaluations"]),
        "converged_within": _number("converged_within", d["converged_within"],
                                    lambda x: 0 <= x < 1, "must lie in [0, 1)"),
        "design": None if d["design"] is None else _count("design", d["design"]),
        "weight": _weight(d["weight"]), "library": _library(d["library"]),
        "bundled_library": d["bundled_library"],
    }
    if not isinstance(checked["bundled_library"], bool):
        raise ValueError(f"{DEFINITION}: bundled_library = {d['bundled_library']!r}: true or false")
    return checked


def _default_box(free) -> dict:
    return {k: [PARAMETERS[k].low, PARAMETERS[k].high] for k in free}


def _library(value) -> str | None:
    if value is None:
        return None
    if not isinstance(value, str) or not value:
        raise ValueError(f"--library: {value!r} is no folder name")
    return str(Path(value).resolve())


def read_definition(folder) -> tuple[dict | None, str | None]:
    """The definition stored in ``folder``: ``(definition, None)`` when it can be used,
    ``(what it holds or None, what is wrong)`` when not, ``(None, None)`` when there is none."""
    path = Path(folder) / DEFINITION
    if not path.exists():
        return None, None
    try:
        stored = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        return None, f"cannot be read ({exc})"
    if not isinstance(stored, dict):
        return None, "holds no definition"
    try:
        return check_definition(stored), None
    except ValueError as exc:
        return stored, str(exc)


def write_definition(folder, definition: dict) -> None:
    """Store ``definition`` in ``folder`` (whole, or not at all)."""
    atomic_write_text(Path(folder) / DEFINITION, json.dumps(definition, indent=1))
